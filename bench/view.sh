#!/usr/bin/env bash
# bench/view.sh: the `rl view` figures of issue 38 (bench/README.md, "rl
# view"): per scene and renderer, a scripted run (bench/view_stop.txt: a
# still first frame, 3 frames of flight, then 0.2 s standing still on the
# virtual clock) under Xvfb, or SDL's offscreen driver where xvfb-run is
# missing, whose --stats-out gives the frame rate while the camera moves
# (moving_fps), the latency from a camera change to its first image on
# screen (latency_ms), the first image of the renderer (first_image_ms)
# and the images after the stop until the image is stable (settle_frames;
# null where pt had not converged to half an 8-bit code value per frame by
# the end). Writes bench/results/view-<date>.json (or OUT) with every run's
# statistics and a summary line per run on stdout; RL_MACHINE names the
# machine in the record; VIEW_RUNS, a regular expression, keeps only the
# runs whose line below it matches (e.g. VIEW_RUNS='^city .* (raster|chcpp)$').
# Run from anywhere: bash bench/view.sh [OUT.json] [RL]
set -u
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1
OUT=${1:-bench/results/view-$(date -u +%Y%m%d).json}
RL=${2:-build/rl}
[ -x "$RL" ] || { echo "view.sh: no $RL (make build)"; exit 1; }
# shellcheck source=bench/view_common.sh
. bench/view_common.sh
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
if command -v xvfb-run >/dev/null 2>&1; then
    run_view() { "${VIEW_XVFB[@]}" "$RL" view "$@"; }
else
    run_view() { SDL_VIDEODRIVER=offscreen "$RL" view "$@"; }
fi
VT_EQ="--set vt.criteria=hsv --set vt.min_edge=14 --set vt.progressive=overdraw"
# scene size renderer [options]: the issue's scenes at 1280x720, vt's
# target at 640x480 on table, gl-raster through both --display paths.
RUNS=(
    "table 1280x720 raster"
    "table 1280x720 chcpp"
    "table 1280x720 vt $VT_EQ"
    "table 640x480 vt $VT_EQ"
    "table 1280x720 pt"
    "table 1280x720 gl-raster --display software"
    "table 1280x720 gl-raster --display gl"
    "city 1280x720 raster"
    "city 1280x720 chcpp"
    "city 1280x720 surfels"
    "city 1280x720 gl-raster"
    "ls-cornell:model=bunny 1280x720 raster"
    "ls-cornell:model=bunny 1280x720 vt $VT_EQ"
    "ls-cornell:model=bunny 1280x720 pt"
)
# gl-pt is left out: on llvmpipe its first 1280x720 frame had not finished
# after 5 minutes (bench/README.md).
i=0
for run in "${RUNS[@]}"; do
    view_selected "$run" "${VIEW_RUNS:-}" || continue
    read -r scene size algo sets <<<"$run"
    i=$((i + 1))
    t0=$(date +%s.%N)
    # shellcheck disable=SC2086
    if run_view "$scene" --algo "$algo" --size "$size" $sets --script bench/view_stop.txt \
        --stats-out "$TMP/run$i.json" >"$TMP/run$i.log" 2>&1; then
        python3 - "$TMP/run$i.json" "$run" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["run"] = sys.argv[2]
json.dump(d, open(sys.argv[1], "w"))
r = d["renderers"][0]
print("%-28s %-8s %-9s moving %6.2f fps, latency %7.0f ms, first image %7.0f ms (prep %6.0f), settle %s frames %s ms, display %.1f ms"
      % (d["scene"], "%dx%d" % (d["width"], d["height"]), r["algorithm"], r["moving_fps"], r["latency_ms"],
         r["first_image_ms"], r["first_prep_ms"], r["settle_frames"], None if r["settle_ms"] is None else round(r["settle_ms"]),
         r["display_ms"]), flush=True)
PY
    else
        echo "$run: failed: $(tail -1 "$TMP/run$i.log")"
    fi
    echo "   ($(python3 -c "print(round($(date +%s.%N) - $t0, 1))") s wall, load $(cut -d' ' -f1-3 /proc/loadavg))"
done
view_write_record "$OUT" "$TMP" view.sh "rl view (bench/view.sh, bench/view_stop.txt)" \
    "scripted runs under Xvfb on a shared machine (other agents' builds and tests running): times are upper bounds; see bench/README.md, rl view"
