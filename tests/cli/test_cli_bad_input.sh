#!/usr/bin/env bash
# test_cli_bad_input.sh: broken scene files and outputs fail with exit 1 and
# exactly one "rl: error:" line that says what went wrong; non-finite
# vertices are dropped with a warning instead.
# Run as: bash test_cli_bad_input.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

OUT="$TMP/x.png"

# Missing file: the error names it.
expect_error 1 "no-such-scene.obj" "$RL" render "$TMP/no-such-scene.obj" --size 32x24 --out "$OUT"
expect_error 1 "no-such-scene.json" "$RL" info "$TMP/no-such-scene.json"
expect_error 1 "" "$RL" render no-such-builtin --size 32x24 --out "$OUT"

# Truncated OBJ: stops in the middle of the vertex list, no faces left.
printf 'v 0 0 0\nv 1 0 0\nv 0 1' >"$TMP/truncated.obj"
expect_error 1 "" "$RL" render "$TMP/truncated.obj" --size 32x24 --out "$OUT"

# PLY whose header promises more vertices than the body has.
cat >"$TMP/short.ply" <<'PLY'
ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
3 0 1 2
3 0 2 3
PLY
expect_error 1 "" "$RL" render "$TMP/short.ply" --size 32x24 --out "$OUT"

# glTF cut off in the middle.
printf '{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0' >"$TMP/corrupt.gltf"
expect_error 1 "" "$RL" render "$TMP/corrupt.gltf" --size 32x24 --out "$OUT"

# JSON scene with a syntax error on line 3: file:line in the message.
printf '{\n  "name": "broken",\n  "lights": [ , ]\n}\n' >"$TMP/syntax.json"
expect_error 1 "syntax.json:3" "$RL" render "$TMP/syntax.json" --size 32x24 --out "$OUT"

# JSON scene with an unknown key: named, with its position.
printf '{\n  "name": "typo",\n  "no_such_key_xyz": 1\n}\n' >"$TMP/unknown.json"
expect_error 1 "no_such_key_xyz" "$RL" render "$TMP/unknown.json" --size 32x24 --out "$OUT"
grep -q 'unknown.json:3' "$TMP/err" || fail "unknown key error lacks file:line: $(cat "$TMP/err")"

# Empty JSON scene: nothing to render.
printf '{}\n' >"$TMP/empty.json"
expect_error 1 "" "$RL" render "$TMP/empty.json" --size 32x24 --out "$OUT"
expect_error 1 "" "$RL" info "$TMP/empty.json"
[ ! -e "$OUT" ] || fail "a failed render still wrote $OUT"

# OBJ with a NaN vertex: that triangle is dropped with a warning, the other renders.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\nf 1 2 4\n' >"$TMP/nan.obj"
expect_exit 0 "$RL" render "$TMP/nan.obj" --size 32x24 --out "$TMP/nan.png"
[ -s "$TMP/nan.png" ] || fail "nan.obj did not render"
grep -q '^rl: warning: ' "$TMP/err" || fail "no warning about the dropped triangle: $(cat "$TMP/err")"
expect_exit 0 "$RL" info "$TMP/nan.obj" --json
grep -q '"dropped_nonfinite":[[:space:]]*1,' "$TMP/out" || fail "info does not count the dropped triangle: $(cat "$TMP/out")"

# Outputs: unwritable folder (exit 1, before rendering), unknown format (exit 2).
expect_error 1 "/nonexistent/x.png" "$RL" render cornell --size 32x24 --out /nonexistent/x.png
expect_error 1 "/nonexistent/d.exr" "$RL" render cornell --size 32x24 --out "$OUT" --depth-out /nonexistent/d.exr
expect_error 2 "x.bmp" "$RL" render cornell --size 32x24 --out "$TMP/x.bmp"
[ ! -e "$TMP/x.bmp" ] || fail "x.bmp was written"

# Unknown camera.
expect_error 1 "no-such-camera" "$RL" render cornell --size 32x24 --camera no-such-camera --out "$OUT"

# Issue 34: two outputs in one file (also spelt two ways), a zero up vector,
# an eye far away (rendered, not misreported as "up is parallel").
expect_error 2 "name the same file" "$RL" render cornell --size 32x24 --out "$OUT" --depth-out "$OUT"
run_ok "$RL" render cornell --size 32x24 --out "$TMP/one.png"
expect_error 2 "--out and --stats-json name the same file" "$RL" render cornell --size 32x24 \
    --out "$TMP/one.png" --stats-json "$TMP/./one.png"
expect_error 2 "zero vector" "$RL" render cornell --size 32x24 --up 0,0,0 --out "$OUT"
run_ok "$RL" render cornell --size 32x24 --eye 1e30,1e30,1e30 --out "$OUT"
# Issue 34, no lost output: a write that fails partway (the file size limit:
# rl ignores SIGXFSZ, so it is EFBIG) keeps the previous file, leaves no
# temporary and prints one error line; with --out and --depth-out, a failed
# depth image keeps the previous --out too (the outputs commit together).
# At 1024x768 the Cornell box is ~40 KB as PNG, its depth ~85 KB as EXR.
mkdir -p "$TMP/keep"
run_ok "$RL" render cornell --size 32x24 --out "$TMP/keep/a.png" --stats-json "$TMP/keep/s.json"
cp "$TMP/keep/a.png" "$TMP/a.good"
cp "$TMP/keep/s.json" "$TMP/s.good"
no_temporaries() {
    ! ls -A "$TMP/keep" | grep -q '^\.' || fail "temporary files left: $(ls -A "$TMP/keep")"
}
expect_error 1 "a.png" bash -c 'ulimit -f 4; exec "$@"' - "$RL" render cornell --size 1024x768 --out "$TMP/keep/a.png"
cmp -s "$TMP/keep/a.png" "$TMP/a.good" || fail "a failed write replaced a.png"
no_temporaries
expect_error 1 "d.exr" bash -c 'ulimit -f 60; exec "$@"' - "$RL" render cornell --size 1024x768 \
    --out "$TMP/keep/a.png" --depth-out "$TMP/keep/d.exr" --stats-json "$TMP/keep/s.json"
cmp -s "$TMP/keep/a.png" "$TMP/a.good" || fail "a failed --depth-out replaced --out"
cmp -s "$TMP/keep/s.json" "$TMP/s.good" || fail "a failed --depth-out replaced --stats-json"
[ ! -e "$TMP/keep/d.exr" ] || fail "a failed --depth-out left d.exr"
no_temporaries
run_ok "$RL" render cornell --size 64x48 --out "$TMP/keep/a.png" --depth-out "$TMP/keep/d.exr"
cmp -s "$TMP/keep/a.png" "$TMP/a.good" && fail "a good run did not replace a.png"
[ -s "$TMP/keep/d.exr" ] || fail "a good run did not write d.exr"
no_temporaries

# A damaged Line Space cache (cut short, as a killed save used to leave it)
# is stale: a warning, rebuilt, overwritten with a valid one that the next
# run loads silently. A file that is no cache at all is refused, untouched.
LS=(--algo pt --set shadow=ls-pnmt --set ls_n=1 --set spp=1 --size 32x24 --out "$OUT")
run_ok "$RL" render cornell "${LS[@]}" --set ls_file="$TMP/keep/c.rlls"
cp "$TMP/keep/c.rlls" "$TMP/c.good"
head -c 3000 "$TMP/c.good" >"$TMP/keep/c.rlls"
run_ok "$RL" render cornell "${LS[@]}" --set ls_file="$TMP/keep/c.rlls"
grep -q '^rl: warning: .*c.rlls.*rebuilding' "$TMP/err" || fail "no warning about the damaged cache: $(cat "$TMP/err")"
cmp -s "$TMP/keep/c.rlls" "$TMP/c.good" || fail "the damaged cache was not rewritten as before"
run_ok "$RL" render cornell "${LS[@]}" --set ls_file="$TMP/keep/c.rlls"
! grep -q 'warning' "$TMP/err" || fail "the rewritten cache still warns: $(cat "$TMP/err")"
no_temporaries
echo "not a cache" >"$TMP/keep/other.rlls"
expect_error 1 "other.rlls" "$RL" render cornell "${LS[@]}" --set ls_file="$TMP/keep/other.rlls"
[ "$(cat "$TMP/keep/other.rlls")" = "not a cache" ] || fail "a file that is no cache was overwritten"

# The scene and object Line Spaces' options (Sec. 13.1, 13.2): out of
# range or unknown, a usage error naming the option.
expect_error 2 "ls_scene_segments=65 is outside" "$RL" render cornell --algo pt --set ls_scene_segments=65 --out "$OUT"
expect_error 2 "ls_object_res=0 is outside" "$RL" render cornell --algo pt --set ls_object_res=0 --out "$OUT"
expect_error 2 "ls_scene_inner=\"grid\" is not one of" "$RL" render cornell --algo pt --set ls_scene_inner=grid --out "$OUT"

# Issue 34: a model whose coordinates reach the float limit: the error
# names the file, alone (no lights to fit) and in a JSON scene (no camera
# to frame it with). Exit 1: the file is at fault, not the command line.
printf 'v -3e38 -3e38 -3e38\nv 3e38 0 0\nv 0 3e38 3e38\nf 1 2 3\n' >"$TMP/huge.obj"
printf '{ "objects": [ { "file": "huge.obj" } ], "lights": [ { "type": "directional", "direction": [0, -1, 0] } ] }\n' \
    >"$TMP/huge.json"
expect_bounded_error 1 "huge.obj" "$RL" render "$TMP/huge.obj" --size 32x24 --out "$OUT"
expect_bounded_error 1 "huge.json" "$RL" render "$TMP/huge.json" --size 32x24 --out "$OUT"

# Issue 34: an importer's error quotes at most 40 characters of the file
# the user named, escaped, and nothing of a file it references (an mtllib
# that is really a password file).
mkdir -p "$TMP/etc" "$TMP/a/b"
printf 'root:x:0:0:root:/root:/bin/bash\nnewmtl x\nd secret-hash-in-etc\n' >"$TMP/etc/passwd"
printf 'mtllib ../../etc/passwd\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl root\nf 1 2 3\n' >"$TMP/a/b/m.obj"
expect_bounded_error 1 "m.obj" "$RL" render "$TMP/a/b/m.obj" --size 32x24 --out "$OUT"
! grep -q 'secret\|root:' "$TMP/err" || fail "the error quotes the referenced file: $(cat "$TMP/err")"
# The path the user named is shown where Assimp quotes it (no reader).
printf 'not a model\n' >"$TMP/model.unknownformat"
expect_bounded_error 1 "No suitable reader found .*\"$TMP/model.unknownformat\"" "$RL" render "$TMP/model.unknownformat" --size 32x24 --out "$OUT"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuvwxyz 1 1\nf 1 2 3\n' >"$TMP/long.obj"
expect_bounded_error 1 '"abcdefghijklmnopqrstuvwxyzabcdefghijklmn\.\.\."' "$RL" render "$TMP/long.obj" --size 32x24 --out "$OUT"

# Issue 34: a 64 MB JSON array of zeros (3.5 GB once parsed before the
# value limit): refused before cJSON builds it, in bounded memory.
python3 -c 'import sys; sys.stdout.write("[" + "0," * (2**25 - 1) + "0]")' >"$TMP/zeros.json"
expect_bounded_error 1 "JSON values, more than the limit" "$RL" render "$TMP/zeros.json" --size 32x24 --out "$OUT"
rm -f "$TMP/zeros.json"

# Issue 34: threads=1024, the documented maximum, under an 8 GB address
# space limit: libgomp used to exit 1 ("Thread creation failed") with no
# rl: line; now the count is clamped to what can be started, with a
# warning. (Sanitizer builds cannot run under such a limit.)
limited_8g() { ( ulimit -v 8000000; exec "$@" ); }
if [ "$RL_SANITIZED" = 0 ]; then
    for algo in whitted pt; do
        budget=()
        [ "$algo" = pt ] && budget=(--time 0.2s)
        expect_exit 0 limited_8g timeout 60 "$RL" render cornell --algo "$algo" --set threads=1024 "${budget[@]}" \
            --size 32x24 --out "$OUT"
        grep -q "^rl: warning: $algo: threads=1024 clamped to " "$TMP/err" || fail "no clamp warning: $(cat "$TMP/err")"
    done
fi

# Issue 34: the texture pixel limit is a flag: a 2048x1024 texture (2 Mi
# pixels) loads by default and is refused, naming it, under a 1 Mi limit.
run_ok "$RL" render cornell --algo raster --size 2048x1024 --out "$TMP/tex2m.png"
printf 'newmtl t\nKd 1 1 1\nmap_Kd tex2m.png\n' >"$TMP/texq.mtl"
printf 'mtllib texq.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n' >"$TMP/texq.obj"
run_ok "$RL" render "$TMP/texq.obj" --size 32x24 --out "$OUT"
expect_bounded_error 1 "tex2m.png" "$RL" --max-texture-pixels 1 render "$TMP/texq.obj" --size 32x24 --out "$OUT"
expect_usage_error "$RL" --max-texture-pixels 0 render "$TMP/texq.obj" --size 32x24 --out "$OUT"

# Issue 34: a frame's memory is estimated before it is allocated (16384 x
# 16384 took 4.2-5.3 GB): refused above --max-memory, with the estimate,
# whether the size comes from --size or from the scene's camera.
rm -f "$OUT"
expect_bounded_error 1 "a 16384x16384 frame of raster needs about 7.00 GiB, more than the 1.00 GiB of --max-memory" \
    "$RL" render cornell --size 16384x16384 --max-memory 1G --out "$OUT"
expect_bounded_error 1 "16384x16384 frame of pt needs about 47" "$RL" render cornell --algo pt --size 16384x16384 \
    --max-memory 1G --out "$OUT"
cat >"$TMP/bigcam.json" <<'JSON'
{ "objects": [ { "generator": "teapot" } ],
  "cameras": [ { "eye": [0, 1, 3], "target": [0, 0, 0], "size": [16384, 16384] } ],
  "camera_path": { "keys": [ { "time_s": 0, "eye": [0, 1, 3], "target": [0, 0, 0] },
                             { "time_s": 1, "eye": [1, 1, 3], "target": [0, 0, 0] } ] } }
JSON
expect_bounded_error 1 "16384x16384 frame" "$RL" render "$TMP/bigcam.json" --max-memory 1G --out "$OUT"
# rl compare checks every renderer's frame at --size (the reference, whitted,
# first) before it samples; rl demo refuses such an image with the estimate.
expect_bounded_error 1 "16384x16384 frame of whitted needs about 7.00 GiB, more than the 4.00 GiB of --max-memory" "$RL" compare cornell \
    --algos raster,pt --size 16384x16384 --max-memory 4G --out "$TMP/cmp_huge"
expect_bounded_error 1 "16384x16384 frame" "$RL" render "$TMP/bigcam.json" --camera-path --max-memory 1G --out "$TMP/f%d.png"
[ ! -e "$OUT" ] || fail "a refused frame still wrote $OUT"
expect_usage_error "$RL" render cornell --max-memory 1X --out "$OUT"
# rl bench pt checks its frame at --size against its --max-memory (GB) too.
expect_bounded_error 1 "16384x16384 frame of pt needs about 45.00 GiB, more than the 1.00 GiB" "$RL" bench pt --size 16384x16384 --max-memory 1 \
    --out "$TMP/bench_huge.json"
[ ! -e "$TMP/bench_huge.json" ] || fail "a refused benchmark still wrote its record"
run_ok "$RL" render cornell --size 32x24 --max-memory 64M --out "$OUT"

# Issue 34: approximation files for visset. A few kilobytes of empty sets
# that each claim 2^26 bits (4 GB once allocated), and sets of the right
# size but of another property, are refused before anything is drawn.
run_ok "$RL" eval cornell --property visibility --set resolution=16 --samples 8 --out "$TMP/ev"
python3 - "$TMP/ev/approx.json" "$TMP" <<'PY'
import json, sys
good = json.load(open(sys.argv[1]))
bomb = dict(good, set_size=1 << 26, nodes=[["leaf"]])
n = 500
bomb["samples"] = [good["samples"][0][:3] + [1]] * n
bomb["sample_sets"] = [[]] * n
bomb["leaves"] = [dict(good["leaves"][0], samples=n, set=[])]
json.dump(bomb, open(sys.argv[2] + "/bomb.json", "w"), separators=(",", ":"))
json.dump(dict(good, property="ops"), open(sys.argv[2] + "/ops.json", "w"))
PY
[ "$(stat -c %s "$TMP/bomb.json")" -lt 50000 ] || fail "bomb.json is not small"
expect_bounded_error 1 "the scene has 8" "$RL" render cornell --algo visset --set approx="$TMP/bomb.json" \
    --size 32x24 --out "$OUT"
expect_bounded_error 1 "'ops', not visibility" "$RL" render cornell --algo visset --set approx="$TMP/ops.json" \
    --size 32x24 --out "$OUT"
run_ok "$RL" render cornell --algo visset --set approx="$TMP/ev/approx.json" --size 32x24 --out "$OUT"
echo "ok"
