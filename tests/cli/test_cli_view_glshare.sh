#!/usr/bin/env bash
# test_cli_view_glshare.sh: rl view's shared path under Xvfb (docs/viewer.md,
# "The GL renderers and the window's context"): with a GL renderer the
# window's EGL context is handed to the library (rl_gl_share_with) and the
# frames are drawn from their textures. Its screenshots equal the readback
# path's and rl render's, byte for byte (gl-raster; gl-pt after 6 frames of
# one sample equals rl render at spp=6); the window's pixels without the
# overlay, drawn by the window's shader, equal the readback path's CPU
# conversion; --stats-out says the shared path was used and how many frames
# came as textures; switching between GL and CPU renderers mid-run works
# (and, in the sanitizer build, leaks nothing); a window context that is not
# EGL (SDL_VIDEO_X11_FORCE_EGL=0: GLX) falls back to the readback path and
# says why. Images are tiny (llvmpipe): 32x24 and 16x12; the shaders are
# those of gl-raster and gl-pt (one variant each) and the window's one.
# Skipped (77) without SDL2, xvfb-run or a GL context.
# Run as: bash test_cli_view_glshare.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

if "$RL" view cornell --size 16x12 --display vulkan 2>&1 | grep -q "built without SDL2"; then
    echo "test_cli_view_glshare: skipped: rl was built without SDL2"
    exit 77
fi
expect_usage_error "$RL" view cornell --display sharde
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "test_cli_view_glshare: skipped: xvfb-run is missing (Debian: xvfb xauth)"
    exit 77
fi
if ! available_algos | grep -qx gl-raster || ! available_algos | grep -qx gl-pt; then
    echo "test_cli_view_glshare: skipped: no GL 4.5 context here (rl algos marks the GL renderers unavailable)"
    exit 77
fi

# json_get FILE EXPR: a Python expression over the JSON object d.
json_get() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print($2)" "$1"; }

EYE=0.9,0.45,-0.6
TARGET=0.28,0.25,0.28
# run_view DISPLAY TAG: the tour below with --display DISPLAY, files TAG_*.
run_view() {
    cat >"$TMP/$2.txt" <<EOT
0    screenshot $TMP/$2_raster.png
0    key i
0    capture $TMP/$2_window.png
0    key i
0.1  move eye $EYE target $TARGET
0.1  screenshot $TMP/$2_moved.png
0.2  algo raster
0.2  screenshot $TMP/$2_cpu.png
0.3  key c
0.3  algo gl-pt
0.5  screenshot $TMP/$2_pt.png
0.5  algo pt
0.6  algo gl-raster
0.6  screenshot $TMP/$2_back.png
0.7  quit
EOT
    xvfb "$RL" view cornell --algo gl-raster --size 32x24 --display "$1" --script "$TMP/$2.txt" \
        --stats-out "$TMP/$2_stats.json" >"$TMP/$2.out" 2>&1 || fail "rl view --display $1: $(cat "$TMP/$2.out")"
}

run_view shared shared
run_view software readback

# The shared path was taken, and gl-raster's and gl-pt's frames came as textures.
[ "$(json_get "$TMP/shared_stats.json" "d['display_path']")" = shared ] ||
    fail "--display shared: not the shared path: $(cat "$TMP/shared_stats.json")"
[ "$(json_get "$TMP/shared_stats.json" "d['display']")" = gl-shared ] || fail "display is not gl-shared"
for a in gl-raster gl-pt; do
    n=$(json_get "$TMP/shared_stats.json" "[r['shared_frames'] for r in d['renderers'] if r['algorithm'] == '$a'][0]")
    [ "$n" -ge 1 ] || fail "$a: no frame came as a texture (shared_frames $n)"
done
n=$(json_get "$TMP/shared_stats.json" "[r['shared_frames'] for r in d['renderers'] if r['algorithm'] == 'raster'][0]")
[ "$n" -eq 0 ] || fail "raster (a CPU renderer) shows $n frames as textures"
[ "$(json_get "$TMP/readback_stats.json" "d['display_path']")" = readback ] || fail "--display software is not readback"

# Screenshots: the shared path's equal the readback path's, byte for byte.
for s in raster moved cpu pt back; do
    cmp -s "$TMP/shared_$s.png" "$TMP/readback_$s.png" || fail "$s: the shared path's screenshot differs from readback"
done
# ... and rl render's of the same camera.
"$RL" render cornell --algo gl-raster --size 32x24 --out "$TMP/render_raster.png" >/dev/null 2>&1 ||
    fail "rl render gl-raster failed"
cmp -s "$TMP/shared_raster.png" "$TMP/render_raster.png" || fail "the shared screenshot differs from rl render"
# gl-pt ran 0.3 .. 0.5 s: 6 frames of 1 sample, the same samples as spp=6 at once.
spp=$(json_get "$TMP/shared_pt.json" "int(d['spp'])")
[ "$spp" -ge 2 ] || fail "gl-pt accumulated $spp samples per pixel in 0.2 s"
"$RL" render cornell --algo gl-pt --set spp="$spp" --size 32x24 --out "$TMP/render_pt.png" >/dev/null 2>&1 ||
    fail "rl render gl-pt failed"
cmp -s "$TMP/shared_pt.png" "$TMP/render_pt.png" || fail "gl-pt: the shared screenshot differs from rl render spp=$spp"

# The window's pixels (overlay off): the shader's sRGB encoding equals the CPU's.
cmp -s "$TMP/shared_window.png" "$TMP/readback_window.png" ||
    fail "the window drawn from the texture differs from the readback path's"

# A window context that is not EGL: the readback path, and why.
cat >"$TMP/glx.txt" <<EOT
0 screenshot $TMP/glx_raster.png
0.1 quit
EOT
SDL_VIDEO_X11_FORCE_EGL=0 xvfb "$RL" view cornell --algo gl-raster --size 32x24 --script "$TMP/glx.txt" \
    --stats-out "$TMP/glx_stats.json" >"$TMP/glx.out" 2>&1 || fail "rl view under GLX: $(cat "$TMP/glx.out")"
[ "$(json_get "$TMP/glx_stats.json" "d['display_path']")" = readback ] || fail "GLX: not the readback path"
expect_in "$TMP/glx_stats.json" "not EGL"
cmp -s "$TMP/glx_raster.png" "$TMP/render_raster.png" || fail "GLX fallback: the screenshot differs from rl render"
echo "test_cli_view_glshare: ok"
