#!/usr/bin/env python3
"""make_sky_hdr.py: writes the lat-long sky of scenes/materials/ as a
Radiance RGBE (.hdr) file, flat (not run-length encoded) scanlines, so that
it needs no imaging library: a blue gradient sky, a small warm sun 35
degrees above the horizon and a dim ground. 128 x 64 texels, 32 KB.

    python3 scripts/make_sky_hdr.py scenes/materials/sky.hdr

Row 0 looks straight up (+y), columns sweep the azimuth from +x towards -z
(docs/scene-format.md, "Environment")."""
import math
import sys

W, H = 128, 64
SUN_ELEV_DEG, SUN_AZIM_DEG, SUN_RADIUS_DEG = 35.0, 140.0, 4.0


def rgbe(r, g, b):
    """One texel as RGBE: a shared exponent, mantissas of 8 bits."""
    m = max(r, g, b)
    if m < 1e-32:
        return bytes((0, 0, 0, 0))
    e = math.frexp(m)[1]
    scale = 256.0 / (2.0 ** e)
    return bytes((min(255, int(r * scale)), min(255, int(g * scale)), min(255, int(b * scale)), e + 128))


def texel(x, y):
    theta = math.pi * (y + 0.5) / H          # from +y
    phi = 2.0 * math.pi * (x + 0.5) / W
    d = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
    se, sa = math.radians(SUN_ELEV_DEG), math.radians(SUN_AZIM_DEG)
    sun = (math.cos(se) * math.cos(sa), math.sin(se), -math.cos(se) * math.sin(sa))
    cos_sun = sum(a * b for a, b in zip(d, sun))
    if cos_sun > math.cos(math.radians(SUN_RADIUS_DEG)):
        return (120.0, 100.0, 70.0)
    up = d[1]
    if up < 0.0:                               # ground: warm grey, darker straight down
        k = 0.25 + 0.1 * (1.0 + up)
        return (0.9 * k, 0.8 * k, 0.65 * k)
    t = 1.0 - up                               # towards the horizon: paler and brighter
    return (0.25 + 0.75 * t, 0.45 + 0.55 * t, 1.0 + 0.2 * t)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "sky.hdr"
    with open(out, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(("-Y %d +X %d\n" % (H, W)).encode("ascii"))
        for y in range(H):
            f.write(b"".join(rgbe(*texel(x, y)) for x in range(W)))


if __name__ == "__main__":
    main()
