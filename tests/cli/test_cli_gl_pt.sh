#!/usr/bin/env bash
# test_cli_gl_pt.sh: gl-pt on the command line: listed by rl algos,
# unavailable with the device's reason (one error line, exit 1, no image)
# where the EGL device cannot be opened, options it has not ported refused
# as usage errors, and where GL is available a progressive render whose
# stats name the GL device, the record of rl bench gl's pt section, and
# shadow maps drawn by GL.
# Run as: bash test_cli_gl_pt.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

run_ok "$RL" algos
expect_in "$TMP/out" "^gl-pt: "

RL_EGL_DEVICE=bogus expect_error 1 "gl-pt: unavailable: .*bogus" \
    "$RL" render cornell --algo gl-pt --size 16x16 --spp 1 --out "$TMP/none.png"
[ ! -e "$TMP/none.png" ] || fail "an unavailable renderer wrote an image"

expect_error 2 "not ported to GL yet" \
    "$RL" render cornell --algo gl-pt --set gl-pt.shadow=embree --size 16x16 --out "$TMP/none.png"
expect_error 2 "not ported to GL yet" \
    "$RL" render cornell --algo gl-pt --set gl-pt.diffuse=embree --size 16x16 --out "$TMP/none.png"
[ ! -e "$TMP/none.png" ] || fail "a refused option still rendered"

if ! grep -A3 '^gl-pt: ' <("$RL" algos) | grep -q "unavailable:"; then
    run_ok "$RL" render cornell --algo gl-pt --set gl-pt.diffuse=grid --size 24x16 --spp 3 \
        --out "$TMP/glpt.exr" --stats-json "$TMP/glpt.json"
    [ -s "$TMP/glpt.exr" ] || fail "gl-pt wrote no image"
    expect_in "$TMP/out" "^gl-pt 24x16 cornell: .* 3 spp"
    python3 - "$TMP/glpt.json" <<'PY' || fail "gl-pt's stats lack the device or the samples"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["device"].count(" | ") == 2, s
assert s["pixels_written"] > 0 and s["samples"] > 0, s
PY
    run_ok "$RL" bench gl --quick --only pt --frames 1 --pt-size 16x16 --out "$TMP/bench.json"
    python3 - "$TMP/bench.json" <<'PY' || fail "rl bench gl's pt record is not as expected"
import json, sys
r = json.load(open(sys.argv[1]))
rows = r["pt"]["rows"]
assert [row["scene"] for row in rows] == ["cornell"], rows
assert rows[0]["gl_pt"]["min_ms"] > 0 and rows[0]["pt"]["min_ms"] > 0 and rows[0]["gl_pt_fps"] > 0, rows
assert r["parameters"]["pt_size"] == "16x16" and r["gl"]["renderer"], r["parameters"]
PY
    # the thesis' raster modes: G-buffer pass, checkerboard, a filter; the
    # shader's ray counters in the stats
    run_ok "$RL" render cornell --algo gl-pt --set gl-pt.primary=raster --set gl-pt.checkerboard=true \
        --set gl-pt.filter=bilateral --size 17x13 --spp 2 --out "$TMP/glpt_raster.png" \
        --stats-json "$TMP/glpt_raster.json"
    [ -s "$TMP/glpt_raster.png" ] || fail "gl-pt primary=raster wrote no image"
    python3 - "$TMP/glpt_raster.json" <<'PY' || fail "gl-pt primary=raster's ray counts are not as expected"
import json, sys
s = json.load(open(sys.argv[1]))
r = s["rays"]
assert r["primary"] == 0 and r["shadow"] > 0 and r["diffuse"] > 0, s
PY
    # shadow maps drawn by GL (Sec. 8.6): no shadow rays traced; a
    # directional light refused as pt refuses it
    run_ok "$RL" render cornell --algo gl-pt --set gl-pt.shadow=shadowmap --set gl-pt.shadowmap_size=64 \
        --size 16x16 --spp 2 --out "$TMP/glpt_sm.png" --stats-json "$TMP/glpt_sm.json"
    [ -s "$TMP/glpt_sm.png" ] || fail "gl-pt shadow=shadowmap wrote no image"
    python3 - "$TMP/glpt_sm.json" <<'PY' || fail "gl-pt shadow=shadowmap traced shadow rays"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["rays"]["shadow"] == 0 and s["rays"]["diffuse"] > 0, s
PY
    expect_error 1 "directional" \
        "$RL" render spheres --algo gl-pt --set gl-pt.shadow=shadowmap --size 16x16 --spp 1 --out "$TMP/none.png"
    [ ! -e "$TMP/none.png" ] || fail "a refused scene still rendered"
    # the Line Space backends (Diagram 1's configuration), and the pair of
    # options the GPU build cannot serve
    run_ok "$RL" render cornell --algo gl-pt --set gl-pt.shadow=ls-pnmt --set gl-pt.diffuse=ls-pnmt \
        --set gl-pt.ls_n=3 --size 16x16 --spp 2 --out "$TMP/glpt_ls.png"
    [ -s "$TMP/glpt_ls.png" ] || fail "gl-pt with ls-pnmt wrote no image"
    expect_error 1 "ls_build=gpu builds the candidate lists only" \
        "$RL" render cornell --algo gl-pt --set gl-pt.diffuse=ls-preillum --set gl-pt.ls_build=gpu \
        --size 16x16 --spp 1 --out "$TMP/none.png"
    [ ! -e "$TMP/none.png" ] || fail "a refused option pair still rendered"
else
    echo "test_cli_gl_pt: no GL 4.5 context here; the rendering cases are skipped"
fi
echo "test_cli_gl_pt: ok"
