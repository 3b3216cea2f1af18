#!/usr/bin/env bash
# test_cli_model_demo.sh: the user's own model files in rl demo, rl compare
# and rl eval. The demo names a model by its file stem and frames it; the
# samplers place their positions around a model, outside its bounds,
# where each of them sees it (docs/evaluation.md).
# Run as: bash test_cli_model_demo.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# A 1 x 2 x 1 box away from the origin, and another file with the same stem.
mkdir -p "$TMP/b"
cat >"$TMP/box.obj" <<'OBJ'
v 2.5 0.5 -2.5
v 3.5 0.5 -2.5
v 3.5 2.5 -2.5
v 2.5 2.5 -2.5
v 2.5 0.5 -1.5
v 3.5 0.5 -1.5
v 3.5 2.5 -1.5
v 2.5 2.5 -1.5
f 5 6 7 8
f 2 1 4 3
f 1 5 8 4
f 6 2 3 7
f 8 7 3 4
f 1 2 6 5
OBJ
cp "$TMP/box.obj" "$TMP/b/box.obj"

# --- rl demo on model files: every renderer, the page, the marks ---
DIR="$TMP/demo"
run_ok "$RL" demo --out "$DIR" --size 64x48 --scenes "$TMP/box.obj:lights=add,cameras=off,$TMP/b/box.obj"
algos=$(available_algos)
for s in box box-2; do
    for a in $algos; do
        f="$DIR/$s-$a.png"
        [ -s "$f" ] || fail "$f missing"
        grep -q "src=\"$s-$a.png\"" "$DIR/index.html" || fail "index.html does not show $s-$a.png"
    done
done
[ -s "$DIR/compare/report.html" ] || fail "the demo's comparison of the model is missing"
python3 - "$DIR/report.json" "$TMP" <<'PY' || fail "report.json does not describe the model scenes"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["failures"] == [], r["failures"]
names = {s["name"]: s for s in r["scenes"]}
assert names["box"]["source"] == sys.argv[2] + "/box.obj:lights=add,cameras=off", names
assert names["box-2"]["source"] == sys.argv[2] + "/b/box.obj" and not names["box-2"]["builtin"], names
for e in r["images"]:
    # 12 triangles: Assimp splits each quad face in two.
    assert e["scene_stats"]["triangles"] == 12, e
    assert e["accuracy"] in ("exact", "approximate"), e
    assert e["error"]["reference"] == r["reference"] == "whitted", e
    if e["algorithm"] == "whitted":
        assert e["accuracy"] == "exact" and e["error"]["rmse"] == 0 and e["error"]["ssim"] == 1, e
# The framing camera puts the model in the picture, tightly: raster draws a
# good part of the 64x48 pixels.
for e in r["images"]:
    if e["algorithm"] == "raster":
        assert e["render_stats"]["pixels_written"] > 0.1 * 64 * 48, e
PY
# --- bad names: neither a built-in nor a file ---
expect_error 2 "nosuch.obj" "$RL" demo --out "$TMP/bad" --scenes "$TMP/nosuch.obj"
expect_error 2 "did you mean 'cornell'" "$RL" demo --out "$TMP/bad" --scenes cornel
expect_error 2 "default parameters" "$RL" demo --out "$TMP/bad" --scenes city:blocks=2

# --- rl compare on a model: positions outside the model's bounds ---
for dims in 2 3; do
    run_ok "$RL" compare "$TMP/box.obj" --algos raster,whitted --dims $dims --samples 12 --size 16x16 \
        --resolution 16 --repeats 1 --spread 0 --out "$TMP/cmp$dims"
    python3 - "$TMP/cmp$dims/compare.json" <<'PY' || fail "rl compare sampled inside the model (dims $dims)"
import json, sys
c = json.load(open(sys.argv[1]))
b = c["scene_stats"]["bounds"]
lo, hi = b["min"], b["max"]
pos = c["positions"]
assert len(pos) == c["samples"] > 0, c["samples"]
for p in pos:
    inside = all(lo[k] <= p[k] <= hi[k] for k in range(3))
    assert not inside, (p, lo, hi)
# The region holds the model in x and z and lies above it.
r = c["sampling"]["region"]
assert r[0] < lo[0] and r[2] < lo[2] and r[3] > hi[0] and r[5] > hi[2], (r, b)
assert min(p[1] for p in pos) > hi[1], pos
PY
done
# A built-in scene keeps its bounds as the region.
run_ok "$RL" compare cornell --algos raster --samples 6 --size 16x16 --resolution 16 --repeats 1 --spread 0 \
    --metrics time --out "$TMP/cmpc"
python3 - "$TMP/cmpc/compare.json" <<'PY' || fail "a built-in scene's region changed"
import json, sys
c = json.load(open(sys.argv[1]))
b = c["scene_stats"]["bounds"]
assert c["sampling"]["region"] == b["min"] + b["max"], (c["sampling"]["region"], b)
PY

# --- rl eval on a model: every sample sees it (visibility counts it) ---
run_ok "$RL" eval "$TMP/box.obj" --property visibility --set resolution=16 --samples 12 --out "$TMP/ev"
python3 - "$TMP/ev/approx.json" "$TMP/cmp2/compare.json" <<'PY' || fail "rl eval's positions do not see the model"
import json, sys
a = json.load(open(sys.argv[1]))
b = json.load(open(sys.argv[2]))["scene_stats"]["bounds"]
assert len(a["samples"]) == 12
for x, y, z, v in a["samples"]:
    assert y > b["max"][1] and v == 1, (x, y, z, v)
PY
echo "ok"
