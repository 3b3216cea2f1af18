#!/usr/bin/env bash
# test_cli_view.sh: rl view, the interactive viewer, driven by --script
# under Xvfb: its screenshots equal rl render of the same camera (raster,
# whitted, a moved camera, after a window resize), renderers switch mid-run,
# a recorded camera path replays through rl render --camera-path to the
# same frames, pt accumulates, and bad input (an unknown event or key, a
# missing file, no display) fails with one error line; the live controls
# (layers, overlay, reference SSIM, menu) work; the image follows a
# resized window, menu entries are clicked and the live culling options
# step. Skipped (exit 77,
# ctest's SKIP_RETURN_CODE) where rl was built without SDL2 or xvfb-run is
# missing.
# Run as: bash test_cli_view.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"
SSIM="$(dirname "${BASH_SOURCE[0]}")/ssim.py"

run_ok "$RL" view --help
for k in "Tab" "F12" "W A S D" "F1"; do expect_in "$TMP/out" "$k"; done

# No display: one error line, exit 1 (or the build has no viewer at all).
DISPLAY= WAYLAND_DISPLAY= SDL_VIDEODRIVER=x11 "$RL" view cornell --size 16x12 >"$TMP/out" 2>"$TMP/err"
code=$?
if grep -q "built without SDL2" "$TMP/err"; then
    [ "$code" -eq 1 ] || fail "a build without SDL2 should exit 1, got $code"
    echo "test_cli_view: skipped: rl was built without SDL2 (install libsdl2-dev and rebuild)"
    exit 77
fi
[ "$code" -eq 1 ] || fail "no display: expected exit 1, got $code: $(cat "$TMP/err")"
[ "$(grep -c '^rl: error: ' "$TMP/err")" -eq 1 ] || fail "no display: not one error line: $(cat "$TMP/err")"
expect_in "$TMP/err" "^rl: error: view: cannot open a window: "

# Bad scripts fail before any window opens: exit 2 with FILE:LINE.
printf '0 key Tab\n0.5 jump\n' >"$TMP/bad_event.txt"
expect_error 2 "bad_event.txt:2: unknown event 'jump'" "$RL" view cornell --script "$TMP/bad_event.txt"
printf '# a comment\n\n0 key Hyper\n' >"$TMP/bad_key.txt"
expect_error 2 "bad_key.txt:3: unknown key 'Hyper'" "$RL" view cornell --script "$TMP/bad_key.txt"
printf '1 quit\n0.5 quit\n' >"$TMP/bad_time.txt"
expect_error 2 "bad_time.txt:2: time 0.5 s is before" "$RL" view cornell --script "$TMP/bad_time.txt"
printf '0 click left 10\n' >"$TMP/bad_click.txt"
expect_error 2 "bad_click.txt:1: click: expected X Y" "$RL" view cornell --script "$TMP/bad_click.txt"
expect_usage_error "$RL" view cornell --display vulkan
printf '0 algo rayster\n' >"$TMP/bad_algo.txt"
expect_error 2 "bad_algo.txt:1: unknown renderer 'rayster'" "$RL" view cornell --script "$TMP/bad_algo.txt"
expect_error 1 "no-such-script.txt" "$RL" view cornell --script "$TMP/no-such-script.txt"
expect_error 1 "no-such-scene.obj" "$RL" view "$TMP/no-such-scene.obj"
expect_usage_error "$RL" view cornell --screenshot-at 1.0
expect_usage_error "$RL" view cornell --set min_edge

if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "test_cli_view: skipped: xvfb-run is missing (Debian: xvfb xauth)"
    exit 77
fi

# ssim_ok A B: the SSIM of two PNGs is at least 0.99.
ssim_ok() {
    local s
    s=$(python3 "$SSIM" "$1" "$2") || fail "cannot compare $1 and $2"
    python3 -c "import sys; sys.exit(0 if float('$s') >= 0.99 else 1)" || fail "$1 vs $2: SSIM $s < 0.99"
}

SIZE=96x72
EYE=0.9,0.45,-0.6
TARGET=0.28,0.25,0.28
# The renderer after whitted in Tab order: the next available one.
AFTER=$(available_algos | awk '/^whitted$/ { getline; print; exit }')
[ -n "$AFTER" ] || fail "no renderer after whitted in rl algos"
cat >"$TMP/tour.txt" <<EOT
# cornell: the scene camera with raster, whitted, then Tab; a moved camera.
0    screenshot $TMP/raster.png
0    algo whitted
0    screenshot $TMP/whitted.png
0    key Tab
0    screenshot $TMP/after.png
0.1  algo raster
0.2  move eye $EYE target $TARGET
0.2  screenshot $TMP/moved.png
0.3  resize 200 150
0.4  screenshot $TMP/resized.png
0.5  key Shift+Tab
0.5  key Tab
0.5  capture $TMP/cap_stats.png
0.6  key i
0.6  capture $TMP/cap_clean.png
0.6  key h
0.6  capture $TMP/cap_help.png
0.6  quit
EOT
run_ok xvfb "$RL" view cornell --size $SIZE --script "$TMP/tour.txt" --screenshot-at "0.45:$TMP/at.png" \
    --stats-out "$TMP/stats.json" --record "$TMP/frames"
for a in raster whitted; do
    run_ok "$RL" render cornell --algo $a --size $SIZE --out "$TMP/ref_$a.png"
    ssim_ok "$TMP/$a.png" "$TMP/ref_$a.png"
done
run_ok "$RL" render cornell --algo raster --size $SIZE --eye $EYE --target $TARGET --out "$TMP/ref_moved.png"
ssim_ok "$TMP/moved.png" "$TMP/ref_moved.png"
ssim_ok "$TMP/resized.png" "$TMP/ref_moved.png"
ssim_ok "$TMP/at.png" "$TMP/ref_moved.png"
# The window: the stats overlay (on at the start), nothing once I hides
# it, the key list after H.
ssim_ok "$TMP/cap_clean.png" "$TMP/ref_moved.png"
for c in stats help; do
    cmp -s "$TMP/cap_$c.png" "$TMP/cap_clean.png" && fail "capture: the $c overlay left the window unchanged"
done
python3 - "$TMP" "$AFTER" <<'PY' || fail "the screenshots' stats or the viewer's stats are wrong"
import json, os, sys
tmp, after = sys.argv[1], sys.argv[2]
assert json.load(open(tmp + "/raster.json"))["algorithm"] == "raster"
assert json.load(open(tmp + "/whitted.json"))["algorithm"] == "whitted"
a = json.load(open(tmp + "/after.json"))
assert a["algorithm"] == after and a["final"], a
m = json.load(open(tmp + "/moved.json"))
assert [round(x, 4) for x in m["eye"]] == [0.9, 0.45, -0.6], m
s = json.load(open(tmp + "/stats.json"))
names = [r["algorithm"] for r in s["renderers"]]
assert "raster" in names and "whitted" in names and after in names, names
assert all(r["frames"] >= 1 and r["first_image_ms"] > 0 for r in s["renderers"]), s
frames = sorted(os.listdir(tmp + "/frames"))
assert len(frames) >= 4 and frames[0] == "frame_000000.png", frames
PY

# A recorded camera path replays through rl render --camera-path.
cat >"$TMP/record.txt" <<EOT
0    record $TMP/path.json
0.2  move eye 0.6,0.35,-0.9 target $TARGET
0.4  move eye $EYE target $TARGET
0.4  screenshot $TMP/rec_last.png
0.4  record stop
EOT
run_ok xvfb "$RL" view cornell --size $SIZE --script "$TMP/record.txt"
python3 - "$TMP/path.json" <<'PY' || fail "the recorded path is wrong: $(cat "$TMP/path.json")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["base"] == "cornell", d
keys = d["camera_path"]["keys"]
assert len(keys) == 3 and [round(k["time_s"], 3) for k in keys] == [0, 0.2, 0.4], keys
PY
run_ok "$RL" render "$TMP/path.json" --camera-path --frames 3 --size $SIZE --out "$TMP/replay%d.png"
ssim_ok "$TMP/replay0.png" "$TMP/ref_raster.png"
ssim_ok "$TMP/replay2.png" "$TMP/rec_last.png"
ssim_ok "$TMP/replay2.png" "$TMP/ref_moved.png"
# P plays the saved path in the viewer: at its end, the last key's view.
printf '0 key p\n0.5 screenshot %s\n' "$TMP/played.png" >"$TMP/play.txt"
run_ok xvfb "$RL" view "$TMP/path.json" --size $SIZE --script "$TMP/play.txt"
ssim_ok "$TMP/played.png" "$TMP/ref_moved.png"

# pt accumulates while the camera stands still: the same mean as rl render
# at the samples the screenshot reports.
printf '0.3 screenshot %s\n' "$TMP/pt.png" >"$TMP/pt.txt"
run_ok xvfb "$RL" view cornell --algo pt --size 48x36 --script "$TMP/pt.txt"
SPP=$(python3 -c "import json; print(int(round(json.load(open('$TMP/pt.json'))['spp'])))")
[ "$SPP" -ge 2 ] || fail "pt did not accumulate: spp $SPP"
run_ok "$RL" render cornell --algo pt --size 48x36 --spp "$SPP" --out "$TMP/ref_pt.png"
read -r m1 m2 < <(python3 "$SSIM" "$TMP/pt.png" "$TMP/ref_pt.png" --mean)
python3 -c "import sys; sys.exit(0 if abs($m1 - $m2) <= 0.05 * $m2 + 1 else 1)" ||
    fail "pt: the viewer's mean $m1 differs from rl render's $m2 at $SPP spp"

# Interactive (no script): pt accumulates in the window until Ctrl-C, which
# SDL turns into a quit: exit 0 and the stats written, also with a frame
# in flight (the quit cancels it).
run_ok xvfb bash -c "timeout --preserve-status -k 20 -s INT 3 '$RL' view cornell --algo pt --size 64x48 \
    --stats-out '$TMP/interactive.json'"
python3 - "$TMP/interactive.json" <<'PY' || fail "the interactive run's stats are wrong: $(cat "$TMP/interactive.json")"
import json, sys
s = json.load(open(sys.argv[1]))
assert not s["scripted"] and s["renderers"][0]["algorithm"] == "pt", s
PY

# The live controls: L shows depth and object IDs as rl render --depth-out
# and --id-out draw them; O cycles vt's overlay (the same image as rl
# render with that overlay); X compares with whitted (whitted itself: SSIM
# exactly 1); M draws the menu; a cycle key on a renderer without that
# option changes nothing.
cat >"$TMP/live.txt" <<EOT
0 key i
0 algo whitted
0 key x
0 screenshot $TMP/live_whitted.png
0 key l
0 capture $TMP/live_depth.png
0 key l
0 capture $TMP/live_ids.png
0 key l
0 capture $TMP/live_colour.png
0 key m
0 capture $TMP/live_menu.png
0 key m
0 algo raster
0 key k
0 key x
0 screenshot $TMP/live_raster.png
0 algo vt
0 key o
0 screenshot $TMP/live_vt_wire.png
EOT
run_ok xvfb "$RL" view cornell --size $SIZE --script "$TMP/live.txt"
run_ok "$RL" render cornell --algo whitted --size $SIZE --depth-out "$TMP/ref_depth.png" --id-out "$TMP/ref_ids.png" \
    --out "$TMP/ref_live.png"
ssim_ok "$TMP/live_depth.png" "$TMP/ref_depth.png"
ssim_ok "$TMP/live_ids.png" "$TMP/ref_ids.png"
ssim_ok "$TMP/live_colour.png" "$TMP/ref_live.png"
cmp -s "$TMP/live_menu.png" "$TMP/live_colour.png" && fail "M: the menu left the window unchanged"
run_ok "$RL" render cornell --algo vt --set overlay=wire --size $SIZE --out "$TMP/ref_vt_wire.png"
ssim_ok "$TMP/live_vt_wire.png" "$TMP/ref_vt_wire.png"
cmp -s "$TMP/live_vt_wire.png" "$TMP/ref_live.png" && fail "O: vt's wire overlay is missing"
python3 - "$TMP" <<'PY' || fail "X: the comparisons with the reference are wrong"
import json, sys
tmp = sys.argv[1]
w = json.load(open(tmp + "/live_whitted.json"))["reference"]
assert w["algorithm"] == "whitted" and w["compared"] == "whitted", w
assert w["ssim"] == 1 and w["hssim"] == 1 and w["rmse"] == 0 and w["hssim_levels"] >= 2, w
r = json.load(open(tmp + "/live_raster.json"))["reference"]
assert r["algorithm"] == "whitted" and r["compared"] == "raster", r
assert 0.2 < r["ssim"] < 0.9999 and r["rmse"] > 0, r
PY

# The image follows the window (--size window): a resize re-renders at
# the new size (as rl render at that size); the menu's entries are clicked
# (a renderer; an enum option back with the right button and forward with
# the left); the live culling options ([ ] + -) change the options and the
# stats. Where the entries are: the menu's fixed cells (docs/viewer.md),
# from half the height down, 6 x 9 pixels each, renderers wrapped to the
# width, the current one marked ">".
read -r VS_X VS_Y RA_X RA_Y SH_X SH_Y < <(available_algos | python3 -c '
import sys
names, cols, col, row, at = sys.stdin.read().split(), 320 // 6 - 1, 0, 0, {}
for n in names:
    k = len(n) + (n == "raster")
    if col > 0 and col + 2 + k > cols:
        row, col = row + 1, 0
    elif col > 0:
        col += 2
    at[n] = (3 + col * 6 + 2, 120 + row * 9 + 3)
    col += k
# raster options: a heading two lines below the renderers, shading first.
print(*at["visset"], *at["raster"], 5, 120 + (row + 3) * 9 + 3)')
cat >"$TMP/window.txt" <<EOT
0 key i
0 resize 320 240
0 screenshot $TMP/win.png
0 key m
0 click right $SH_X $SH_Y
0 screenshot $TMP/win_gouraud.png
0 click $SH_X $SH_Y
0 screenshot $TMP/win_back.png
0 click $VS_X $VS_Y
0 set budget=1024
0 screenshot $TMP/win_vs1024.png
0 key -
0 screenshot $TMP/win_vs512.png
0 click $RA_X $RA_Y
0 algo chcpp
0 key ]
0 key +
0 key ]
0 key ]
0 key +
0 screenshot $TMP/win_chcpp.png
0 resize 64 48
0 screenshot $TMP/win_small.png
EOT
run_ok xvfb "$RL" view table --size window --set visset.samples=16 --set visset.resolution=32 \
    --script "$TMP/window.txt"
run_ok "$RL" render table --size 320x240 --out "$TMP/ref_win.png"
run_ok "$RL" render table --size 320x240 --set shading=gouraud --out "$TMP/ref_gouraud.png"
ssim_ok "$TMP/win.png" "$TMP/ref_win.png"
ssim_ok "$TMP/win_gouraud.png" "$TMP/ref_gouraud.png"
ssim_ok "$TMP/win_back.png" "$TMP/ref_win.png"
cmp -s "$TMP/win_gouraud.png" "$TMP/win.png" && fail "click: shading did not change the image"
python3 - "$TMP" <<'PY' || fail "the window's size, the menu's clicks or the live options are wrong"
import json, sys
tmp = sys.argv[1]
j = lambda n: json.load(open(tmp + "/win_" + n + ".json"))
w = json.load(open(tmp + "/win.json"))
assert (w["width"], w["height"]) == (320, 240), w
assert (j("small")["width"], j("small")["height"]) == (64, 48)
assert j("gouraud")["options"]["shading"] == "gouraud" and j("back")["options"]["shading"] == "textured"
a, b = j("vs1024"), j("vs512")
assert a["algorithm"] == "visset" and a["options"]["budget"] == "1024" and b["options"]["budget"] == "512", (a, b)
assert b["triangles_rasterized"] < a["triangles_rasterized"] <= w["triangles_rasterized"], (a, b, w)
c = j("chcpp")
assert c["algorithm"] == "chcpp" and c["options"]["batch"] == "100" and c["options"]["tight"] == "false", c
assert c["occlusion_queries"] > 0, c
PY

# A set in the script that the renderer refuses: exit 2 with FILE:LINE.
printf '0 set raster.shading=plaid\n0.1 quit\n' >"$TMP/bad_set.txt"
expect_error 2 "bad_set.txt:1: set raster.shading=plaid" xvfb "$RL" view cornell --size 16x12 --script "$TMP/bad_set.txt"
echo "test_cli_view: ok"
