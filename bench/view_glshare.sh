#!/usr/bin/env bash
# bench/view_glshare.sh: rl view's shared path against the readback path for
# the GL renderers (bench/README.md, "rl view: the GL renderers' shared
# path"): per scene, size and renderer, scripted runs of bench/view_stop.txt
# (gl-pt: bench/view_short.txt, its frames take seconds on llvmpipe) with
# --display shared and --display software, interleaved (A B A B ..., REPS
# times; gl-pt PT_REPS times), under Xvfb. Each run's --stats-out (moving frame ms, display
# ms per image, frames shown from a texture) and the process's CPU time
# (user + system, /usr/bin/time) go to bench/results/view-glshare-<date>.json
# (or OUT), with a summary line per run on stdout. RL_MACHINE names the
# machine; GLSHARE_RUNS, a regular expression, keeps only the matching runs.
# Run from anywhere: bash bench/view_glshare.sh [OUT.json] [RL]
set -u
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1
OUT=${1:-bench/results/view-glshare-$(date -u +%Y%m%d).json}
RL=${2:-build/rl}
REPS=${REPS:-2}
PT_REPS=${PT_REPS:-1}
[ -x "$RL" ] || { echo "view_glshare.sh: no $RL (make build)"; exit 1; }
command -v xvfb-run >/dev/null 2>&1 || { echo "view_glshare.sh: needs xvfb-run"; exit 1; }
# shellcheck source=bench/view_common.sh
. bench/view_common.sh
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
RUNS=(
    "cornell 640x480 gl-raster"
    "cornell 1280x720 gl-raster"
    "cornell 640x480 gl-pt"
    "cornell 1280x720 gl-pt"
)
# The record so far (rewritten after every pair, so that a stopped run keeps it).
write_out() {
    view_write_record "$OUT" "$TMP" view_glshare.sh \
        "rl view shared path vs readback (bench/view_glshare.sh, bench/view_stop.txt; gl-pt bench/view_short.txt)" \
        "scripted runs under Xvfb on Mesa llvmpipe, shared and readback interleaved, on a machine shared with other builds: compare runs of one pair; see bench/README.md"
}
i=0
for run in "${RUNS[@]}"; do
    view_selected "$run" "${GLSHARE_RUNS:-}" || continue
    read -r scene size algo <<<"$run"
    script=bench/view_stop.txt
    reps=$REPS
    [ "$algo" = gl-pt ] && script=bench/view_short.txt reps=$PT_REPS
    for rep in $(seq "$reps"); do
        for display in shared software; do
            i=$((i + 1))
            /usr/bin/time -f "%U %S %e" -o "$TMP/time$i" "${VIEW_XVFB[@]}" "$RL" view "$scene" \
                --algo "$algo" --size "$size" --display "$display" --script "$script" \
                --stats-out "$TMP/run$i.json" >"$TMP/run$i.log" 2>&1 || { echo "$run $display: failed: $(tail -1 "$TMP/run$i.log")"; continue; }
            python3 - "$TMP/run$i.json" "$TMP/time$i" "$run" "$display" "$rep" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
user, system, wall = (float(x) for x in open(sys.argv[2]).read().split()[-3:])
d.update(run=sys.argv[3], display_asked=sys.argv[4], rep=int(sys.argv[5]), cpu_s=user + system, process_wall_s=wall,
         load=open("/proc/loadavg").read().split()[:3])
json.dump(d, open(sys.argv[1], "w"))
r = d["renderers"][0]
print("%-8s %-9s %-9s %-9s rep %d: moving %7.0f ms/frame (%5.2f fps), display %6.1f ms/image, %2d of %2d images textures, cpu %6.2f s"
      % (d["scene"], "%dx%d" % (d["width"], d["height"]), r["algorithm"], d["display_path"], d["rep"],
         r["moving_frame_ms"], r["moving_fps"], r["display_ms"], r["shared_frames"], r["frames"], d["cpu_s"]), flush=True)
PY
        done
        echo "   (load $(cut -d' ' -f1-3 /proc/loadavg))"
        write_out
    done
done
