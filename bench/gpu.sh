#!/usr/bin/env bash
# bench/gpu.sh: the GL benchmark records of issue 35 on a machine with a GPU
# (NVIDIA through EGL_PLATFORM_DEVICE_EXT, or any GL 4.5 device): builds
# renderlab, then runs each GL benchmark under a time limit, writing JSON
# into bench/results/ (named gpu-*). The whole run stays under 10 minutes.
# Usage: bash bench/gpu.sh            (from the repository root)
#        RL_EGL_DEVICE=1 bash bench/gpu.sh   to pick another EGL device
set -u
cd "$(dirname "${BASH_SOURCE[0]}")/.."
make build >/dev/null || { echo "gpu.sh: make build failed" >&2; exit 1; }
RL=build/rl
OUT=bench/results
STAMP=$(date -u +%Y%m%d-%H%M%S)
mkdir -p "$OUT"
failed=0

# run LIMIT_SECONDS NAME COMMAND...: one benchmark, its output in $OUT/gpu-NAME-$STAMP.log
run() {
    local limit=$1 name=$2
    shift 2
    echo "== $name (limit ${limit}s): $*"
    if ! timeout "$limit" "$@" >"$OUT/gpu-$name-$STAMP.log" 2>&1; then
        echo "gpu.sh: $name failed or ran out of time (see $OUT/gpu-$name-$STAMP.log)" >&2
        failed=1
    fi
    tail -n 12 "$OUT/gpu-$name-$STAMP.log"
}

"$RL" algos | sed -n '/^gl-raster/,/^$/p'

# Jaehn 2015, Sec. 7.4 with real query latency: chcpp and svs frame by
# frame down the city's street, software drawer and GL drawer (with
# chcpp's asynchronous queries), at 1280x1280 and 640x640.
run 300 culling-walk-1280 "$RL" bench culling --only walk --size 1280 --walk-frames 60 \
    --out "$OUT/gpu-culling-walk-1280-$STAMP.json"
run 140 culling-walk-640 "$RL" bench culling --only walk --size 640 --walk-frames 60 --drawer gl \
    --out "$OUT/gpu-culling-walk-640-$STAMP.json"

exit $failed
