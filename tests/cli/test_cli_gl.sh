#!/usr/bin/env bash
# test_cli_gl.sh: the GL renderers on the command line: listed by rl algos,
# reported unavailable (with the reason, one error line, exit 1, no output
# file) where the EGL device cannot be opened, and where it can, a frame
# whose stats name the GL device. The visibility property's backend=gl
# likewise: a clear error without GL, and rl eval's samples equal to the
# software property's with it.
# Run as: bash test_cli_gl.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

run_ok "$RL" algos
expect_in "$TMP/out" "^gl-raster: "

# A device that does not exist, by environment and by option.
RL_EGL_DEVICE=bogus run_ok "$RL" algos
sed -n '/^gl-raster: /,/^$/p' "$TMP/out" | grep -q "^  unavailable: .*bogus" ||
    fail "rl algos does not mark gl-raster unavailable: $(cat "$TMP/out")"
RL_EGL_DEVICE=bogus expect_error 1 "gl-raster: unavailable: .*bogus" \
    "$RL" render cornell --algo gl-raster --size 32x24 --out "$TMP/none.png"
[ ! -e "$TMP/none.png" ] || fail "an unavailable renderer wrote an image"
expect_error 1 "unavailable: .*device 15" \
    "$RL" render cornell --algo gl-raster --set gl-raster.device=15 --size 32x24 --out "$TMP/none.png"
[ ! -e "$TMP/none.png" ] || fail "an unavailable renderer wrote an image"

# The culling renderers with drawer=gl: unavailable with the device's reason.
expect_error 1 "chcpp: unavailable: .*bogus" \
    "$RL" render cornell --algo chcpp --set chcpp.drawer=gl --set chcpp.device=bogus --size 32x24 --out "$TMP/none.png"
[ ! -e "$TMP/none.png" ] || fail "an unavailable renderer wrote an image"
RL_EGL_DEVICE=bogus expect_error 1 "surfels: unavailable: .*bogus" \
    "$RL" render cornell --algo surfels --set surfels.drawer=gl --size 32x24 --out "$TMP/none.png"
expect_error 2 "drawer" "$RL" render cornell --algo svs --set svs.drawer=vulkan --size 32x24 --out "$TMP/none.png"
# The surfel atlas (part 6) and VT's reconstruction (part 5) on GL: the same.
expect_error 1 "surfels: unavailable: atlas=gl: .*bogus" \
    "$RL" render cornell --algo surfels --set surfels.atlas=gl --set surfels.device=bogus --size 32x24 --out "$TMP/none.png"
RL_EGL_DEVICE=bogus expect_error 1 "vt: unavailable: reconstruct=gl: .*bogus" \
    "$RL" render table --algo vt --set vt.reconstruct=gl --size 32x24 --out "$TMP/none.png"
[ ! -e "$TMP/none.png" ] || fail "an unavailable renderer wrote an image"
expect_error 2 "reconstruct" "$RL" render table --algo vt --set vt.reconstruct=vulkan --size 32x24 --out "$TMP/none.png"

# The visibility property on GL: a clear error where there is no GL, a
# usage error for a backend that does not exist.
RL_EGL_DEVICE=bogus expect_error 1 "visibility: backend gl: OpenGL unavailable: .*bogus" \
    "$RL" eval cornell --property visibility --set backend=gl --set resolution=16 --samples 8 --out "$TMP/eval-none"
[ ! -e "$TMP/eval-none/approx.json" ] || fail "an unavailable property wrote an approximation"
expect_error 2 "backend" "$RL" eval cornell --property visibility --set backend=vulkan --out "$TMP/eval-none"
expect_error 2 "visibility-backend: unknown value 'vulkan'" \
    "$RL" compare cornell --algos raster --visibility-backend vulkan --out "$TMP/cmp-none"
expect_error 2 "visibility-backend: unknown value 'vulkan'" \
    "$RL" bench sampling --quick --visibility-backend vulkan --out "$TMP/none.json"

RL_EGL_DEVICE=bogus expect_error 1 "bench gl: OpenGL unavailable: .*bogus" \
    "$RL" bench gl --quick --out "$TMP/bench-none.json"
[ ! -e "$TMP/bench-none.json" ] || fail "rl bench gl without GL wrote a record"

# The CPU renderers do not care about the GL device.
RL_EGL_DEVICE=bogus run_ok "$RL" render cornell --algo raster --size 32x24 --out "$TMP/raster.png" \
    --stats-json "$TMP/raster.json"
python3 - "$TMP/raster.json" <<'PY' || fail "raster's stats name a device"
import json, sys
assert "device" not in json.load(open(sys.argv[1]))
PY

if ! grep -A3 '^gl-raster: ' <("$RL" algos) | grep -q "unavailable:"; then
    run_ok "$RL" render cornell --algo gl-raster --size 64x48 --out "$TMP/gl.png" --id-out "$TMP/gl-id.png" \
        --stats-json "$TMP/gl.json"
    [ -s "$TMP/gl.png" ] && [ -s "$TMP/gl-id.png" ] || fail "gl-raster wrote no image"
    expect_in "$TMP/out" "^gl-raster 64x48 cornell: "
    python3 - "$TMP/gl.json" <<'PY' || fail "gl-raster's stats lack the device or counters"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["device"].count(" | ") == 2, s["device"]
assert s["pixels_written"] > 0 and s["triangles_rasterized"] > 0, s
PY
    # chcpp on the GL drawer: the stats name the device; the image equals
    # gl-raster's (conservative culling, the same drawer).
    run_ok "$RL" render cornell --algo chcpp --set chcpp.drawer=gl --size 64x48 --out "$TMP/chc.png" \
        --stats-json "$TMP/chc.json"
    cmp -s "$TMP/chc.png" "$TMP/gl.png" || fail "chcpp on GL differs from gl-raster on cornell"
    python3 - "$TMP/chc.json" <<'PY' || fail "chcpp's stats on GL lack the device"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["device"].count(" | ") == 2, s
PY

    # rl eval of the visibility property on GL: the same samples and values
    # as the software property on a tiny setting.
    for b in gl software; do
        run_ok "$RL" eval cornell --property visibility --set backend=$b --set resolution=16 --samples 16 \
            --workers 2 --out "$TMP/eval-$b"
        expect_in "$TMP/out" "^visibility (resolution=16$([ $b = gl ] && echo ', backend=gl')) on cornell: 16 samples"
    done
    python3 - "$TMP/eval-gl/approx.json" "$TMP/eval-software/approx.json" <<'PY' || fail "GL and software visibility differ"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
assert len(a["samples"]) == 16 and a["samples"] == b["samples"], (a["samples"], b["samples"])
assert a["sample_sets"] == b["sample_sets"]
PY

    # rl bench gl --quick: the three sections, the GL strings in the record,
    # the two backends' visibility values equal, the GL-built Line Space
    # with the CPU build's counts.
    run_ok "$RL" bench gl --quick --scenes cornell --frames 1 --out "$TMP/bench-gl.json"
    python3 - "$TMP/bench-gl.json" <<'PY' || fail "rl bench gl's record is incomplete"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["benchmark"] == "gl" and r["gl"]["renderer"] and r["gl"]["version"], r.get("gl")
f, v = r["frames"], r["visibility"]
assert f["status"] == "ok" and v["status"] == "ok", (f, v)
row = f["rows"][0]
assert row["scene"] == "cornell" and row["raster"]["min_ms"] > 0 and row["gl_raster"]["min_ms"] > 0, row
assert row["ids_equal_percent"] > 99, row
row = v["rows"][0]
assert row["values_equal"] == r["parameters"]["positions"] == 2, row
assert row["object_pixels_total"] > 0 and row["gl"]["mean_ms_per_position"] > 0, row
ls = r["linespace"]
assert ls["status"] == "ok", ls
row = ls["rows"][0]
assert row["counts_equal"] is True and row["cpu_ms"] > 0 and row["gl_wall_ms"] > 0, row
PY
else
    echo "test_cli_gl: no GL 4.5 context here; the rendering case is skipped"
fi
echo "test_cli_gl: ok"
