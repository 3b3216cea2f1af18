# ssim.py A.png B.png: the mean SSIM of two 8-bit PNGs' luma (8x8 windows,
# stride 4), printed; python3 only, no imaging library. For the viewer's
# tests, which compare its screenshots with rl render.
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path + ": not a PNG"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and interlace == 0 and ctype in (2, 6), path + ": unsupported PNG"
            channels = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([0.299 * line[x * channels] + 0.587 * line[x * channels + 1] + 0.114 * line[x * channels + 2]
                     for x in range(width)])
        prev = line
    return width, height, rows


def ssim(a, b):
    (w, h, x), (w2, h2, y) = a, b
    assert (w, h) == (w2, h2), "sizes differ: %dx%d and %dx%d" % (w, h, w2, h2)
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    total, count = 0.0, 0
    for y0 in range(0, max(h - 8, 0) + 1, 4):
        for x0 in range(0, max(w - 8, 0) + 1, 4):
            p = [x[j][i] for j in range(y0, min(y0 + 8, h)) for i in range(x0, min(x0 + 8, w))]
            q = [y[j][i] for j in range(y0, min(y0 + 8, h)) for i in range(x0, min(x0 + 8, w))]
            n = len(p)
            mp, mq = sum(p) / n, sum(q) / n
            vp = sum((v - mp) ** 2 for v in p) / n
            vq = sum((v - mq) ** 2 for v in q) / n
            cov = sum((p[k] - mp) * (q[k] - mq) for k in range(n)) / n
            total += (2 * mp * mq + c1) * (2 * cov + c2) / ((mp * mp + mq * mq + c1) * (vp + vq + c2))
            count += 1
    return total / count


if __name__ == "__main__":
    a, b = read_png(sys.argv[1]), read_png(sys.argv[2])
    if len(sys.argv) > 3 and sys.argv[3] == "--mean":
        print("%.4f %.4f" % (sum(map(sum, a[2])) / (a[0] * a[1]), sum(map(sum, b[2])) / (b[0] * b[1])))
    else:
        print("%.4f" % ssim(a, b))
