#!/usr/bin/env bash
# smoke.sh HARNESS SEED_DIR WORK_DIR RUNS [libFuzzer flags...]: a short,
# deterministic libFuzzer run (fixed seed and count) of HARNESS on a copy of
# its seed corpus in WORK_DIR, which new inputs go to; the seeds stay
# untouched. Fails on any crash, sanitizer report, leak or timeout, also
# on the regression inputs kept for the harness.
set -euo pipefail
bin=$1 seeds=$2 work=$3 runs=$4
shift 4
rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts"
cp "$seeds"/* "$work/corpus/"
cd "$work"   # the harnesses write their temporary files to /dev/shm or /tmp (fuzz_temp.h), run here
# Inputs that once crashed this harness (regressions/<kind>-*, <kind> the
# seed folder's name), fixed since, run first, once each.
shopt -s nullglob
regressions=("$(dirname "$seeds")/../regressions/$(basename "$seeds")"-*)
if [ ${#regressions[@]} -gt 0 ]; then
    "$bin" -timeout=30 -rss_limit_mb=4096 "$@" "${regressions[@]}"
fi
exec "$bin" -seed=1 -runs="$runs" -max_len=4096 -timeout=30 -rss_limit_mb=4096 \
    -artifact_prefix="$work/artifacts/" -print_final_stats=1 "$@" "$work/corpus"
