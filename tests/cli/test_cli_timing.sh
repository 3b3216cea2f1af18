#!/usr/bin/env bash
# test_cli_timing.sh: timings a user can trust (issue 33). Preparation and
# frame apart (render line, stats JSON, -v phases); eval and compare name
# the experiment, record the load and give a run-to-run spread with
# min <= median <= max; "did you mean" for unknown names; option ranges
# print whole numbers in full; bench --help lists every kind.
# Run as: bash test_cli_timing.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# prep and frame apart: whitted builds its BVH on the first frame.
run_ok "$RL" render cornell --algo whitted --size 32x24 --out "$TMP/w.png" --stats-json "$TMP/w.json"
grep -Eq '^whitted 32x24 cornell: prep [0-9.]+ m?s, frame [0-9.]+ m?s, ' "$TMP/out" ||
    fail "summary lacks prep and frame: $(cat "$TMP/out")"
python3 - "$TMP/w.json" <<'PY' || fail "stats JSON does not separate prep from frame"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["prep_ms"] > 0 and d["frame_ms"] > 0 and d["inputs_ms"] >= 0, d
# time_ms is the render call: its own preparation plus the frame.
assert abs(d["prep_ms"] - d["inputs_ms"] + d["frame_ms"] - d["time_ms"]) < 1e-6 * max(1, d["time_ms"]), d
PY

# -v adds the phases load, build and frame on stderr.
run_ok "$RL" -v render cornell --size 32x24 --out "$TMP/v.png"
grep -Eq '^rl: debug: timing: load [0-9.]+ ms, build [0-9.]+ ms .*frame [0-9.]+ ms' "$TMP/err" ||
    fail "-v lacks the phase timings: $(cat "$TMP/err")"
run_ok "$RL" render cornell --size 32x24 --out "$TMP/q.png"
grep -q 'timing:' "$TMP/err" && fail "the phases should need -v: $(cat "$TMP/err")"

# eval of a timing names its renderer, records the experiment and the load,
# and measures the spread.
run_ok "$RL" eval cornell --property time --set renderer=whitted --set width=16 --set height=16 \
    --set repeats=1 --samples 6 --spread 3 --out "$TMP/e"
expect_in "$TMP/out" "renderer=whitted"
expect_in "$TMP/out" "spread: 3 runs"
expect_in "$TMP/e/report.html" "renderer=whitted"
expect_in "$TMP/e/report.html" "Run-to-run spread"
python3 - "$TMP/e/eval.json" <<'PY' || fail "eval.json lacks the experiment, load or spread"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["property"]["renderer"] == "whitted" and "renderer=whitted" in d["property"]["label"], d["property"]
e = d["experiment"]
assert " eval cornell --property time " in e["command"] and "renderlab" in e["build"], e
assert e["machine"]["nproc"] >= 1 and e["machine"]["cpu"], e["machine"]
l = d["load"]
assert l["threads"] >= 1 and isinstance(l["exceeds_threads"], bool) and "start" in l and "end" in l, l
s = d["spread"]
assert s["runs"] == 3 and 0 <= s["min"] <= s["q25"] <= s["median"] <= s["q75"] <= s["max"], s
assert d["prep_ms"] >= 0
PY
# A property that is not a timing has no spread.
run_ok "$RL" eval cornell --property visibility --set resolution=8 --samples 6 --out "$TMP/v"
python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["spread"] is None' "$TMP/v/eval.json" ||
    fail "visibility should have no spread"

# compare: per renderer the spread and prep of its time; one repeat is
# "one render", not "the median of 1 renders".
run_ok "$RL" compare cornell --algos raster,whitted --metrics time --size 16x16 --samples 6 \
    --resolution 8 --repeats 1 --spread 3 --out "$TMP/c"
expect_in "$TMP/c/report.html" "one render"
grep -q "median of 1 renders" "$TMP/c/report.html" && fail "compare report says 'median of 1 renders'"
expect_in "$TMP/c/report.html" "run-to-run spread"
expect_in "$TMP/c/report.html" "Command: "
expect_in "$TMP/err" "q25"
python3 - "$TMP/c/compare.json" <<'PY' || fail "compare.json lacks spread, prep or experiment"
import json, sys
d = json.load(open(sys.argv[1]))
assert " compare cornell " in d["experiment"]["command"] and d["load"]["threads"] >= 1
for r in d["renderers"]:
    t = r["time"]
    s = t["spread"]
    assert s["runs"] == 3 and 0 <= s["min"] <= s["median"] <= s["max"], r
    assert t["min"] <= t["median"] <= t["max"] and t["prep_ms"] >= 0, r
PY

# "did you mean": subcommands, renderers, scenes, option keys, properties,
# bench kinds, sampling values.
expect_error 2 "did you mean 'render'" "$RL" rendr cornell
expect_error 2 "did you mean \"raster\"" "$RL" render cornell --algo rastr --out "$TMP/x.png"
expect_error 1 "did you mean 'cornell'" "$RL" render cornel --out "$TMP/x.png"
expect_error 2 "did you mean \"shading\"" "$RL" render cornell --set raster.shadng=flat --out "$TMP/x.png"
expect_error 2 "did you mean \"visibility\"" "$RL" eval cornell --property visibilty --out "$TMP/x"
expect_error 2 "did you mean 'rays'" "$RL" bench rayz
expect_error 2 "did you mean 'adaptive'" "$RL" eval cornell --property visibility --method adaptiv
expect_error 2 "did you mean 'cornell'" "$RL" demo --scenes cornel --out "$TMP/x"
expect_error 2 "did you mean \"whitted\"" "$RL" eval cornell --property time --set renderer=whited

# Integer ranges as integers wherever option tables are printed, and a side
# without a limit (2^53 - 1, +-1e300 in the tables) left out.
for cmd in scenes algos "eval --list"; do
    run_ok "$RL" $cmd
    grep -E '^ +[a-z_0-9]+ +int ' "$TMP/out" | grep -q 'e+' && fail "rl $cmd prints an integer range as %g"
    grep -q '9007199254740991\|1e+300' "$TMP/out" && fail "rl $cmd prints a bound that means no limit"
done
run_ok "$RL" scenes
expect_in "$TMP/out" "random seed of the buildings \[>= 0\]"
run_ok "$RL" eval --list
expect_in "$TMP/out" "repeats .*\[1..1000\]"
grep -q "rl list" "$TMP/out" && fail "eval --list refers to 'rl list'"

# bench --help: one line per kind, where the JSON goes, how long.
run_ok "$RL" bench --help
for k in rays vt pt sampling surfels culling; do
    grep -Eq "^  rl bench $k +[a-zA-Z]" "$TMP/out" || fail "bench --help lacks $k: $(cat "$TMP/out")"
done
expect_in "$TMP/out" "bench/results/KIND-YYYYMMDD-HHMMSS.json"
expect_in "$TMP/out" "2 cores"
echo "ok"
