#!/usr/bin/env bash
# make_corpus.sh RL FUZZ_LINESPACE_CACHE: writes the seed corpora of the
# harnesses added for issue 34 (approx, linespace, texture, options) into
# tests/fuzz/corpus/<kind>, replacing what is there. RL is a built `rl`,
# FUZZ_LINESPACE_CACHE the built harness (it writes its own seeds, which
# must belong to its grid). Every seed is small: the runs cut inputs at
# 4096 bytes, those of the Line Space harness at 16384. The committed seeds came from this script; rerun it when
# a format changes.
set -euo pipefail
rl=${1:?usage: make_corpus.sh RL FUZZ_LINESPACE_CACHE}
ls_harness=${2:?usage: make_corpus.sh RL FUZZ_LINESPACE_CACHE}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# approx.json of `rl eval`: adaptive and grid sampling, a 2-D slice.
mkdir -p "$here/corpus/approx"
rm -f "$here/corpus/approx"/*
"$rl" -q eval cornell --property visibility --set resolution=8 --samples 8 --out "$tmp/a" >/dev/null
cp "$tmp/a/approx.json" "$here/corpus/approx/adaptive.json"
"$rl" -q eval cornell --property visibility --set resolution=8 --method grid --samples 8 --out "$tmp/g" >/dev/null
cp "$tmp/g/approx.json" "$here/corpus/approx/grid.json"

# Line Space caches of the harness's grid, one per payload and list kind.
mkdir -p "$here/corpus/linespace"
rm -f "$here/corpus/linespace"/*
RL_FUZZ_WRITE_SEEDS="$here/corpus/linespace" ASAN_OPTIONS=detect_leaks=0 "$ls_harness" -runs=0 "$tmp" >/dev/null 2>&1

# Images: EXR from rl; PNG of every colour type and depth, interlaced, with
# tRNS and palette; BMP and TGA for stb_image.
mkdir -p "$here/corpus/texture"
rm -f "$here/corpus/texture"/*
"$rl" -q render cornell --size 6x4 --out "$here/corpus/texture/cornell.exr" >/dev/null
"$rl" -q render cornell --size 6x4 --out "$here/corpus/texture/cornell.png" >/dev/null
python3 - "$here/corpus/texture" <<'PY'
import struct, sys, zlib
out = sys.argv[1]

def chunk(kind, body):
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xffffffff)

def png(name, w, h, depth, ctype, row_bytes, extra=b"", interlace=0):
    raw = b""
    # Adam7's seven passes, each a small picture of its own; one pass of
    # the whole picture otherwise. row_bytes / w: bytes per pixel (depth >= 8).
    passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
    for x0, y0, dx, dy in passes if interlace else [(0, 0, 1, 1)]:
        pw, ph = (w - x0 + dx - 1) // dx, (h - y0 + dy - 1) // dy
        n = row_bytes * pw // w
        for y in range(ph if pw > 0 else 0):
            raw += b"\x00" + bytes((x * 37 + y * 11) & 0xff for x in range(n))
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, ctype, 0, 0, interlace))
    data += extra + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    open(f"{out}/{name}", "wb").write(data)

png("gray1.png", 5, 3, 1, 0, 1)
png("gray8.png", 4, 4, 8, 0, 4)
png("gray16.png", 3, 2, 16, 0, 6)
png("graya8.png", 3, 3, 8, 4, 6)
png("rgb8-trns.png", 3, 2, 8, 2, 9, chunk(b"tRNS", b"\x00\x01\x00\x02\x00\x03"))
png("rgba16.png", 2, 2, 16, 6, 16)
png("palette4.png", 4, 2, 4, 3, 2, chunk(b"PLTE", bytes(range(48))) + chunk(b"tRNS", b"\x80\x40"))
png("interlaced.png", 9, 9, 8, 2, 27, interlace=1)

w, h = 3, 2
pixels = bytes((i * 29) & 0xff for i in range(w * h * 3))
rows = b"".join(pixels[y * 9:(y + 1) * 9] + b"\x00" * 3 for y in range(h))
bmp = b"BM" + struct.pack("<IHHI", 54 + len(rows), 0, 0, 54)
bmp += struct.pack("<IiiHHIIiiII", 40, w, h, 1, 24, 0, len(rows), 2835, 2835, 0, 0)
open(f"{out}/rgb.bmp", "wb").write(bmp + rows)
tga = struct.pack("<BBBHHBHHHHBB", 0, 0, 2, 0, 0, 0, 0, 0, w, h, 32, 8)
open(f"{out}/rgba.tga", "wb").write(tga + bytes((i * 13) & 0xff for i in range(w * h * 4)))
PY

# Command lines of `rl render`, one argument per line.
mkdir -p "$here/corpus/options"
rm -f "$here/corpus/options"/*
printf '%s\n' cornell --out x.png > "$here/corpus/options/minimal.txt"
printf '%s\n' cornell --algo pt --set spp=4 --set shadow=ls-pnmt --set ls_n=2 --time 2s --preview 500ms \
    --out x.png --tonemap aces --exposure -1.5 > "$here/corpus/options/pt.txt"
printf '%s\n' cornell --size 320x240 --eye 0.2,0.3,-1 --target 0,0.2,0 --up 0,1,0 --fov 40 --out x.exr \
    --depth-out d.exr --id-out i.png --stats-json s.json > "$here/corpus/options/camera.txt"
printf '%s\n' cornell --camera-path --frames 12 --out 'f/%04d.png' --set raster.shading=flat > "$here/corpus/options/path.txt"
printf '%s\n' model.obj --headlight --orbit --algo whitted --set max_depth=3 --set background=0.1,0.2,0.3 \
    --out x.png > "$here/corpus/options/model.txt"
ls -l "$here/corpus/approx" "$here/corpus/texture" "$here/corpus/options" |
    awk '$5 > 4096 { print "make_corpus.sh: over 4096 bytes: " $9; bad = 1 } END { exit bad }'
ls -l "$here/corpus/linespace" | awk '$5 > 16384 { print "make_corpus.sh: over 16384 bytes: " $9; bad = 1 } END { exit bad }'
