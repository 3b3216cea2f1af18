#!/usr/bin/env bash
# bench/gpu.sh: the GL benchmark records on a machine with a GPU (issue 35):
# builds renderlab (make build) and runs the GL benchmarks on the first EGL
# device (RL_EGL_DEVICE=auto: NVIDIA's headless EGL where its driver is
# installed, else Mesa), each under a time limit, writing
# bench/results/gpu-<date>-*.json. The whole run stays under 10 minutes;
# a benchmark that runs out of time is reported and the next one still runs.
# Run from anywhere: bash bench/gpu.sh
set -u
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1

export RL_EGL_DEVICE=${RL_EGL_DEVICE:-auto}
date=$(date -u +%Y%m%d)
out=bench/results
rl=build/rl
failed=0

step() {   # step SECONDS NAME COMMAND...: one benchmark under a time limit
    local limit=$1 name=$2
    shift 2
    echo "== $name (at most ${limit} s)"
    local t0=$SECONDS
    timeout --signal=INT --kill-after=10 "$limit" "$@"
    local rc=$?
    echo "== $name: exit $rc after $((SECONDS - t0)) s"
    [ "$rc" -eq 0 ] || failed=$((failed + 1))
}

echo "== make build"
timeout 300 make build || { echo "gpu.sh: the build failed"; exit 1; }
"$rl" algos | sed -n '/^gl-raster/,/^$/p'

# The quick overview: gl-raster vs raster frames and the visibility property
# on every built-in scene (city with 4 blocks).
step 120 "rl bench gl" "$rl" bench gl --out "$out/gpu-$date-gl.json"
# The thesis' setting of the visibility property (Jähn 2015: 1024² per
# cube face) on the whole city, and its frames at the default size.
step 150 "rl bench gl, city, visibility 1024²" "$rl" bench gl --scenes city --only visibility \
    --resolution 1024 --positions 8 --out "$out/gpu-$date-gl-city-visibility1024.json"
step 120 "rl bench gl, city, frames 1280x720" "$rl" bench gl --scenes city --only frames --size 1280x720 \
    --out "$out/gpu-$date-gl-city-frames.json"

echo "gpu.sh: records in $out/gpu-$date-*.json; $failed benchmark(s) failed"
[ "$failed" -eq 0 ]
