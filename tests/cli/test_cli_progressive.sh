#!/usr/bin/env bash
# test_cli_progressive.sh: rl render's defaults for a user. Progressive
# renderers (pt) loop frames under --time and --spp and say so in the
# summary, write previews to --out while they run, save what accumulated on
# Ctrl-C (exit 130); --tonemap and --exposure change PNG output only, and
# their defaults leave it byte for byte as it was.
# Run as: bash test_cli_progressive.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# png_stat white|mean FILE.png: how many pixels are clipped to pure white,
# or the mean of the RGB bytes.
png_stat() {
    python3 - "$@" <<'PY'
import sys, zlib, struct
def read_png(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n'
    pos, idat = 8, b''
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    assert depth == 8
    bpp = {2: 3, 6: 4, 0: 1, 4: 2}[ctype]
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line); prev = line
    return w, h, bpp, rows
w, h, bpp, rows = read_png(sys.argv[2])
if sys.argv[1] == 'white':
    print(sum(1 for r in rows for x in range(w) if all(r[x * bpp + k] == 255 for k in range(3))))
else:
    print(int(sum(r[x * bpp + k] for r in rows for x in range(w) for k in range(3)) / (3 * w * h)))
PY
}
# json_get FILE KEY: one top-level value of a JSON file.
json_get() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }

# --- tone mapping -----------------------------------------------------------
# The default (none = clamp) is today's PNG, byte for byte.
run_ok "$RL" render cornell --algo whitted --size 96x72 --out "$TMP/w.png"
run_ok "$RL" render cornell --algo whitted --size 96x72 --tonemap none --exposure 0 --out "$TMP/w-none.png"
cmp -s "$TMP/w.png" "$TMP/w-none.png" || fail "--tonemap none --exposure 0 changed the PNG"
# Whitted's bright surfaces clip to white under the clamp, not under the operators.
clipped=$(png_stat white "$TMP/w.png")
[ "$clipped" -gt 0 ] || fail "whitted cornell should clip some pixels without tone mapping"
for op in reinhard aces; do
    run_ok "$RL" render cornell --algo whitted --size 96x72 --tonemap $op --out "$TMP/w-$op.png"
    n=$(png_stat white "$TMP/w-$op.png")
    [ "$n" -lt "$clipped" ] || fail "--tonemap $op clips $n pixels, the clamp $clipped"
done
# One stop more brightens; the stats file records the mapping.
run_ok "$RL" render cornell --algo whitted --size 96x72 --exposure 1 --out "$TMP/w-ev.png" \
    --stats-json "$TMP/w-ev.json"
[ "$(png_stat mean "$TMP/w-ev.png")" -gt "$(png_stat mean "$TMP/w.png")" ] || fail "--exposure 1 did not brighten"
[ "$(json_get "$TMP/w-ev.json" tonemap)" = none ] || fail "stats lack the tone mapping"
# EXR stays linear: the flags are refused there, before any work.
expect_error 2 "EXR stays linear" "$RL" render cornell --tonemap aces --out "$TMP/x.exr"
[ ! -e "$TMP/x.exr" ] || fail "a refused render wrote x.exr"
expect_error 2 "--tonemap" "$RL" render cornell --tonemap filmic --out "$TMP/x.png"
expect_error 2 "--exposure" "$RL" render cornell --exposure bright --out "$TMP/x.png"

# --- budgets ------------------------------------------------------------------
# A time budget on a tiny image gives many frames, and the summary counts them.
run_ok "$RL" render cornell --algo pt --size 16x12 --time 1s --out "$TMP/t.png" --stats-json "$TMP/t.json"
expect_in "$TMP/out" "frames"
expect_in "$TMP/out" "time budget 1 s"
frames=$(json_get "$TMP/t.json" frames)
[ "$frames" -gt 1 ] || fail "--time 1s rendered $frames frame(s)"
[ "$(json_get "$TMP/t.json" stopped)" = time ] || fail "the budget did not stop the render"
# --spp N stops at N samples per pixel: pt's 2 per frame make 3 frames for 5.
run_ok "$RL" render cornell --algo pt --size 16x12 --spp 5 --set spp=2 --out "$TMP/s.png" --stats-json "$TMP/s.json"
[ "$(json_get "$TMP/s.json" frames)" = 3 ] || fail "--spp 5 with 2 per frame: $(cat "$TMP/out")"
[ "$(json_get "$TMP/s.json" spp)" = 6 ] || fail "--spp 5 with 2 per frame should accumulate 6 spp"
expect_in "$TMP/out" "3 frames, 6 spp"
# The same sample count is the same image (a budget in samples is reproducible).
run_ok "$RL" render cornell --algo pt --size 16x12 --spp 6 --set spp=2 --out "$TMP/s2.png"
cmp -s "$TMP/s.png" "$TMP/s2.png" || fail "two renders to 6 spp differ"
# --set spp keeps one frame of that many samples, as before budgets existed.
run_ok "$RL" render cornell --algo pt --size 16x12 --set pt.spp=3 --out "$TMP/one.png"
expect_in "$TMP/out" "frame "
grep -q "frames" "$TMP/out" && fail "--set spp should render one frame: $(cat "$TMP/out")"
# Budgets need a progressive renderer; a malformed duration is a usage error.
expect_error 2 "progressive" "$RL" render cornell --algo raster --time 1s --out "$TMP/x.png"
expect_error 2 "--time" "$RL" render cornell --algo pt --time 10parsecs --out "$TMP/x.png"
expect_error 2 "--time" "$RL" render cornell --algo pt --time 0s --out "$TMP/x.png"
expect_error 2 "--spp" "$RL" render cornell --algo pt --spp 0 --out "$TMP/x.png"
expect_error 2 "camera-path" "$RL" render cluster --camera-path --time 1s --out "$TMP/f%03d.png"

# --- previews and Ctrl-C --------------------------------------------------------
# A long budget in the background. The preview appears while rl still
# runs; SIGINT then stops it, it saves what accumulated and exits 130.
# A shell starts background jobs with SIGINT ignored (and so does whatever
# ran this script in the background), and rl keeps an ignored SIGINT
# ignored, as it should; python resets it to the default before it execs
# rl, so the test does not depend on how it was started. The budget bounds
# the wait should the signal be lost after all.
python3 -c 'import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])' \
    "$RL" render cornell --algo pt --size 24x18 --time 2m --preview 50ms --out "$TMP/p.png" \
    --stats-json "$TMP/p.json" >"$TMP/p.out" 2>"$TMP/p.err" &
pid=$!
for _ in $(seq 1 600); do
    [ -s "$TMP/p.png" ] && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
done
[ -s "$TMP/p.png" ] || { kill -KILL "$pid" 2>/dev/null; fail "no preview within 60 s: $(cat "$TMP/p.err")"; }
kill -0 "$pid" 2>/dev/null || fail "rl ended before the interrupt: $(cat "$TMP/p.out" "$TMP/p.err")"
kill -INT "$pid"
wait "$pid"
code=$?
[ "$code" -eq 130 ] || fail "rl render after SIGINT exited $code, expected 130: $(cat "$TMP/p.err")"
expect_in "$TMP/p.out" "interrupted by Ctrl-C"
expect_in "$TMP/p.err" "interrupted: saving"
[ "$(json_get "$TMP/p.json" stopped)" = interrupt ] || fail "stats should say the render was interrupted"
[ "$(json_get "$TMP/p.json" frames)" -ge 1 ] || fail "no frame was saved"
[ "$(python3 -c 'import sys; print(open(sys.argv[1], "rb").read(8).hex())' "$TMP/p.png")" = 89504e470d0a1a0a ] ||
    fail "p.png is not a PNG"
ls -a "$TMP" | grep -q '\.tmp\.png$' && fail "a temporary preview file was left behind: $(ls -a "$TMP")"
exit 0
