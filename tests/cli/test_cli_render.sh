#!/usr/bin/env bash
# test_cli_render.sh: rl render writes what it promises (PNG/EXR at the
# requested size, depth and ID layers, a stats file), accepts renderer
# options, and rl info reports the Cornell box's 36 triangles.
# Run as: bash test_cli_render.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# png_size FILE: "WIDTHxHEIGHT" from the IHDR chunk (big-endian at bytes 16..23).
png_size() {
    local magic w h
    magic=$(od -An -tx1 -N8 "$1" | tr -d ' \n')
    [ "$magic" = "89504e470d0a1a0a" ] || { echo "not-a-png"; return; }
    w=$(od -An -tu1 -j16 -N4 "$1" | awk '{print $1*16777216+$2*65536+$3*256+$4}')
    h=$(od -An -tu1 -j20 -N4 "$1" | awk '{print $1*16777216+$2*65536+$3*256+$4}')
    echo "${w}x${h}"
}
expect_png() {
    [ -s "$1" ] || fail "$1 was not written"
    [ "$(png_size "$1")" = "$2" ] || fail "$1 is $(png_size "$1"), expected $2"
}

# PNG at the requested size, with the one-line summary on stdout.
run_ok "$RL" render cornell --algo raster --size 64x48 --out "$TMP/c.png"
expect_png "$TMP/c.png" 64x48
[ "$(wc -l <"$TMP/out")" -eq 1 ] || fail "summary should be one line: $(cat "$TMP/out")"
expect_in "$TMP/out" "raster"
expect_in "$TMP/out" "64x48"
expect_in "$TMP/out" " ms"
expect_in "$TMP/out" "triangles rasterized"

# The default algorithm is raster; = syntax works too.
run_ok "$RL" render cornell --size=32x24 --out="$TMP/eq.png"
expect_png "$TMP/eq.png" 32x24
expect_in "$TMP/out" "^raster"

# EXR: magic number 76 2f 31 01.
run_ok "$RL" render cornell --size 64x48 --out "$TMP/c.exr"
[ "$(od -An -tx1 -N4 "$TMP/c.exr" | tr -d ' \n')" = "762f3101" ] || fail "c.exr is not OpenEXR"

# Renderer options, with and without the renderer's prefix.
run_ok "$RL" render cornell --size 64x48 --set raster.shading=flat --out "$TMP/flat.png"
expect_png "$TMP/flat.png" 64x48
run_ok "$RL" render cornell --size 64x48 --set shading=flat --out "$TMP/flat2.png"
cmp -s "$TMP/flat.png" "$TMP/flat2.png" || fail "raster.shading=flat and shading=flat differ"

# Camera overrides and global flags after the subcommand.
run_ok "$RL" render cornell --size 40x30 --eye 0,1,4 --target 0,1,0 --up 0,1,0 --fov 50 --out "$TMP/cam.png" -q
expect_png "$TMP/cam.png" 40x30
cmp -s "$TMP/cam.png" "$TMP/c.png" && fail "camera overrides had no effect"

# Stats file, depth and ID layers.
run_ok "$RL" render cornell --size 64x48 --out "$TMP/s.png" --stats-json "$TMP/stats.json" \
    --depth-out "$TMP/depth.exr" --id-out "$TMP/ids.png"
expect_in "$TMP/stats.json" '"time_ms"'
expect_in "$TMP/stats.json" '"pixels_written"'
[ "$(od -An -tx1 -N4 "$TMP/depth.exr" | tr -d ' \n')" = "762f3101" ] || fail "depth.exr is not OpenEXR"
expect_png "$TMP/ids.png" 64x48
run_ok "$RL" render cornell --size 64x48 --out "$TMP/s2.png" --depth-out "$TMP/depth.png"
expect_png "$TMP/depth.png" 64x48
python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["time_ms"] >= 0' <"$TMP/stats.json" ||
    fail "stats.json is not valid JSON with time_ms"

# A built-in with parameters.
run_ok "$RL" render cornell-teapot:triangles=2000 --size 32x24 --out "$TMP/teapot.png"
expect_png "$TMP/teapot.png" 32x24

# Size comes from the scene's camera, else 1280x720; --camera picks by name.
cat >"$TMP/box.json" <<'JSON'
{
  "lights": [ { "type": "point", "position": [0, 3, 3], "intensity": 10 } ],
  "cameras": [
    { "name": "front", "eye": [0, 0, 4], "target": [0, 0, 0], "size": [48, 32] },
    { "name": "side", "eye": [4, 1, 0], "target": [0, 0, 0], "size": [30, 20] }
  ],
  "objects": [ { "generator": "box" } ]
}
JSON
run_ok "$RL" render "$TMP/box.json" --out "$TMP/box.png"
expect_png "$TMP/box.png" 48x32
run_ok "$RL" render "$TMP/box.json" --camera side --out "$TMP/side.png"
expect_png "$TMP/side.png" 30x20
run_ok "$RL" render "$TMP/box.json" --camera side --size 20x10 --out "$TMP/side2.png"
expect_png "$TMP/side2.png" 20x10
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$TMP/tri.obj"
run_ok "$RL" render "$TMP/tri.obj" --out "$TMP/tri.png"
expect_png "$TMP/tri.png" 1280x720

# Camera paths: the scene's camera_path as frames, named by the --out
# pattern, any renderer, one stats entry per frame; the path's keys are the
# first and last frame's cameras.
cat >"$TMP/walk.json" <<'JSON'
{ "name": "walk", "base": "cornell",
  "camera_path": { "keys": [
    { "time_s": 0, "eye": [0.28, 0.27, -0.8], "target": [0.28, 0.27, 0] },
    { "time_s": 1, "eye": [0.6, 0.4, -0.6], "target": [0.28, 0.2, 0.28], "fov_deg": 50 } ] } }
JSON
mkdir -p "$TMP/frames"
run_ok "$RL" render "$TMP/walk.json" --camera-path --frames 4 --size 40x30 --algo whitted \
    --out "$TMP/frames/f%03d.png" --depth-out "$TMP/frames/d%03d.exr" --stats-json "$TMP/walk.json.stats"
for i in 000 001 002 003; do expect_png "$TMP/frames/f$i.png" 40x30; [ -s "$TMP/frames/d$i.exr" ] || fail "d$i.exr missing"; done
[ ! -e "$TMP/frames/f004.png" ] || fail "--frames 4 wrote a fifth frame"
expect_in "$TMP/out" "4 frames"
python3 - "$TMP/walk.json.stats" "$TMP/frames" <<'PY' || fail "the camera path's stats are wrong"
import json, sys
r = json.load(open(sys.argv[1]))
f = r["frames"]
assert r["algorithm"] == "whitted" and len(f) == 4 and r["duration_s"] == 1, r
assert [x["frame"] for x in f] == [0, 1, 2, 3] and abs(f[3]["time_s"] - 1) < 1e-9, f
assert max(abs(a - b) for a, b in zip(f[0]["eye"], [0.28, 0.27, -0.8])) < 1e-6, f[0]
assert max(abs(a - b) for a, b in zip(f[3]["eye"], [0.6, 0.4, -0.6])) < 1e-6, f[3]
assert abs(f[3]["fov_deg"] - 50) < 1e-4 and f[1]["eye"] != f[2]["eye"], f
assert all(x["time_ms"] >= 0 and x["file"].endswith("f%03d.png" % x["frame"]) for x in f), f
PY
# Frames differ along the path; --fps counts frames from the duration.
cmp -s "$TMP/frames/f000.png" "$TMP/frames/f003.png" && fail "the first and last frame are the same"
run_ok "$RL" render "$TMP/walk.json" --camera-path --fps 4 --size 16x12 --out "$TMP/frames/g%d.png"
for i in 0 1 2 3 4; do expect_png "$TMP/frames/g$i.png" 16x12; done
[ ! -e "$TMP/frames/g5.png" ] || fail "--fps 4 over 1 s wrote more than 5 frames"
expect_error 2 "no camera_path" "$RL" render cornell --camera-path --out "$TMP/frames/x%d.png"
expect_error 2 "integer conversion" "$RL" render "$TMP/walk.json" --camera-path --out "$TMP/frames/x.png"
expect_error 2 "integer conversion" "$RL" render "$TMP/walk.json" --camera-path --out "$TMP/frames/x%s%d.png"
expect_error 2 "go with --camera-path" "$RL" render "$TMP/walk.json" --frames 3 --out "$TMP/x.png"
expect_error 2 "one of them" "$RL" render "$TMP/walk.json" --camera-path --frames 3 --fps 2 --out "$TMP/frames/x%d.png"
expect_error 2 "the path sets the camera" "$RL" render "$TMP/walk.json" --camera-path --eye 0,0,0 \
    --out "$TMP/frames/x%d.png"

# rl info: text and JSON.
run_ok "$RL" info cornell
grep -Eq '^triangles +36$' "$TMP/out" || fail "rl info cornell should show 36 triangles: $(cat "$TMP/out")"
expect_in "$TMP/out" "cameras"
run_ok "$RL" info cornell --json
expect_in "$TMP/out" '"triangles":[[:space:]]*36,'
python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["triangles"] == 36' <"$TMP/out" ||
    fail "rl info cornell --json is not valid JSON with 36 triangles"
echo "ok"
