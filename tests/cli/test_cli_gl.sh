#!/usr/bin/env bash
# test_cli_gl.sh: the GL renderers on the command line: listed by rl algos,
# reported unavailable (with the reason, one error line, exit 1, no output
# file) where the EGL device cannot be opened, and where it can, a frame
# whose stats name the GL device.
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
else
    echo "test_cli_gl: no GL 4.5 context here; the rendering case is skipped"
fi
echo "test_cli_gl: ok"
