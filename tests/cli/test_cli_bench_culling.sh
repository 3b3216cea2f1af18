#!/usr/bin/env bash
# test_cli_bench_culling.sh: `rl bench culling --quick` runs the Jaehn 2015
# Ch. 7 applications (surfels per projected size, octree depth for CHC++, SVS vs CHC++, runtime
# selection, visible sets as a renderer) on a tiny city and writes a
# complete JSON record with sane values; --only picks sections; bad usage
# exits 2. Keeps the benchmark from rotting; it measures nothing.
# Run as: bash test_cli_bench_culling.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

expect_usage_error "$RL" bench culling --samples 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --max-depth 21 --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --select-quantile 1.5 --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --extent 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --visset-positions 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --only depth,nosuch --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --quick --out "$TMP/x.txt"
expect_usage_error "$RL" bench culling --frobnicate
expect_usage_error "$RL" bench culling --only walk --drawer vulkan --out "$TMP/x.json"
expect_usage_error "$RL" bench culling --only walk --walk-frames 1 --out "$TMP/x.json"
[ -e "$TMP/x.json" ] && fail "a failed run wrote x.json"
expect_exit 1 "$RL" bench culling --quick --out "$TMP/no/such/dir/c.json"

expect_exit 0 "$RL" bench culling --help
for o in --scene --only --samples --max-depth --size --height --extent --resolution --select-positions \
         --select-quantile --visset-positions --surfels --budget --threads --seed --out --resume --quick \
         --walk-frames --drawer; do
    expect_in "$TMP/out" "$o"
done
expect_exit 0 "$RL" bench --help
expect_in "$TMP/out" "rl bench culling"

expect_exit 0 "$RL" bench culling --quick --out "$TMP/c.json"
[ -s "$TMP/c.json" ] || fail "c.json was not written"
[ -s "$TMP/culling-visset-approx.json" ] || fail "the visible sets were not saved"
for s in "Sec. 7.2" "[300,400]" "Sec. 7.3" "best depth" "Sec. 7.4" "svs / chcpp" "Sec. 7.5" "selection beats both" \
         "Sec. 7.6" "budget"; do
    expect_in "$TMP/out" "$s"
done

python3 - "$TMP/c.json" <<'PY' || fail "c.json does not hold a complete, sane record"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["benchmark"] == "culling"
for k in ("machine", "parameters", "surfels", "depth", "svs", "select", "visset"):
    assert k in r, "missing " + k
for k in ("surfels", "depth", "svs", "select", "visset"):
    assert r[k]["status"] == "ok", (k, r[k])
sf = r["surfels"]["ranges"]
assert [(x["min_size"], x["max_size"]) for x in sf] == [(50, 100), (100, 200), (200, 300), (300, 400)], sf
for x in sf:
    assert x["time_ms"]["mean"] > 0 and 0 < x["hssim"]["min"] <= 1, x
d = r["depth"]["depths"]
assert [x["max_depth"] for x in d] == [0, 1, 2], d
assert d[0]["octree_nodes"] == 1 and d[2]["octree_nodes"] > d[1]["octree_nodes"] > 1, d
assert 0 <= r["depth"]["best_depth"] <= 2
s = r["svs"]
assert s["positions"] >= 1 and s["chcpp_time_ms"]["mean"] > 0 and s["svs_time_ms"]["mean"] > 0, s
assert 0 < s["svs_ssim"]["mean"] <= 1, s
sel = r["select"]
assert sel["positions"] == 4 and sel["selected_mean_ms"] > 0, sel
# The selection picks per position, so its mean may be below both (that is
# its point) or, with a poor predictor, above both: only sanity here.
assert sel["chcpp_mean_ms"] > 0 and sel["svs_mean_ms"] > 0 and isinstance(sel["selection_beats_both"], bool), sel
# With the svs section's sampled times: the selection judged on the time
# property itself, between the two renderers' means or below both.
assert sel["property_chcpp_mean_ms"] > 0 and sel["property_svs_mean_ms"] > 0, sel
lo = min(sel["property_chcpp_mean_ms"], sel["property_svs_mean_ms"])
hi = max(sel["property_chcpp_mean_ms"], sel["property_svs_mean_ms"])
assert 0 < sel["property_time_selected_mean_ms"] and 0 <= sel["property_time_selected_chcpp"] <= 4, sel
assert sel["property_time_selection_beats_both"] == (sel["property_time_selected_mean_ms"] < lo), sel
v = r["visset"]
assert v["set_bytes"] > 0 and v["budget_triangles"] > 0 and 0 < v["hssim"]["min"] <= 1, v
assert v["positions"] == 4 and 0 <= v["hssim_below_0_9"] <= 4 and len(v["worst_position"]) == 3, v
assert v["budget_time_ms"]["mean"] > 0 and 0 <= v["budget_hssim"]["min"] <= v["budget_hssim"]["max"] <= 1, v
# the svs section ran before, so visset is compared with its sampled time
assert v["svs_sampled_time_mean_ms"] > 0, v
PY

# The walk section runs only when named (not in c.json above): chcpp (as
# CHC++, latency=frame, and in CHC's order, latency=wait) and svs frame by
# frame on the software drawer, and on GL where a context can be made
# (else the record says why). Every answer is read or carried on.
python3 -c "import json, sys; assert 'walk' not in json.load(open(sys.argv[1]))" "$TMP/c.json" \
    || fail "the walk section ran without --only walk"
expect_exit 0 "$RL" bench culling --quick --only walk --walk-frames 3 --out "$TMP/w.json"
expect_in "$TMP/out" "svs / chcpp (software)"
python3 - "$TMP/w.json" <<'PY' || fail "w.json does not hold a sane walk record"
import json, sys
r = json.load(open(sys.argv[1]))
w = r["walk"]
assert w["status"] == "ok" and w["frames"] == 3 and r["parameters"]["drawer"] == "both", w
runs = w["runs"]
gl = [x for x in runs if x["drawer"] == "gl"]
assert [(x["renderer"], x.get("latency"), x["drawer"]) for x in runs if x["drawer"] == "software"] == \
    [("chcpp", "frame", "software"), ("chcpp", "wait", "software"), ("svs", None, "software")], runs
assert (len(gl) == 3 and all(x["gl_device"] for x in gl)) or (not gl and w["gl_unavailable"]), w
for x in runs:
    assert 0 < x["min_ms"] <= x["median_ms"] <= x["max_ms"] and x["first_frame_ms"] > 0, x
    assert abs(x["queries_ready_mean"] + x["queries_waited_mean"] + x["queries_carried_mean"]
               - x["queries_mean"] - x["queries_carried_in_mean"]) < 1e-9, x
    assert x["drawer"] == "gl" or x["queries_waited_mean"] + x["queries_carried_mean"] == 0, x
    assert x.get("latency") != "wait" or x["queries_carried_mean"] + x["queries_filled_mean"] == 0, x
assert w["svs_over_chcpp_software"] > 0 and w["chcpp_wait_over_frame_software"] > 0
PY

# --extent widens the slice of Sec. 7.4-7.6 about the scene's centre: the
# positions there see the scene from outside.
expect_exit 0 "$RL" bench culling --quick --only svs --extent 3 --out "$TMP/e.json"
python3 - "$TMP/c.json" "$TMP/e.json" <<'PY' || fail "--extent is not applied"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["parameters"]["extent"] == 1 and b["parameters"]["extent"] == 3
assert a["svs"]["visible_polygons"]["mean"] != b["svs"]["visible_polygons"]["mean"], (a["svs"], b["svs"])
PY

# --resume: the slice and every series measured on it are kept; a run that
# stopped (here: series cut short or lost, as a kill would leave them)
# continues with the same command and ends with the same values.
expect_exit 0 "$RL" bench culling --quick --only svs --resume "$TMP/res" --out "$TMP/r1.json"
for f in key.txt slice.json chcpp-time.json svs-time.json chcpp-triangles.json svs-triangles.json svs-quality.json; do
    [ -s "$TMP/res/$f" ] || fail "--resume did not keep $f"
done
cp "$TMP/res/svs-triangles.json" "$TMP/tri-full.json"
echo '{"values": [1234.5]}' >"$TMP/res/svs-triangles.json"
rm "$TMP/res/svs-quality.json"
expect_exit 0 "$RL" bench culling --quick --only svs --resume "$TMP/res" --out "$TMP/r2.json"
expect_in "$TMP/err" "the slice sampled before"
expect_in "$TMP/err" "svs triangles: 1 of"
cmp -s "$TMP/res/svs-triangles.json" "$TMP/tri-full.json" && fail "the cut series was measured anew, not continued"
python3 - "$TMP/r1.json" "$TMP/r2.json" "$TMP/res/svs-triangles.json" "$TMP/tri-full.json" <<'PY' || fail "a resumed run differs"
import json, sys
a, b = (json.load(open(f))["svs"] for f in sys.argv[1:3])
cut, full = (json.load(open(f))["values"] for f in sys.argv[3:5])
assert a["positions"] == b["positions"] and a["visible_polygons"] == b["visible_polygons"], (a, b)
assert a["chcpp_triangles"] == b["chcpp_triangles"] and a["svs_ssim"] == b["svs_ssim"], (a, b)
# the kept first value, then the rest measured as before
assert len(cut) == len(full) and cut[0] == 1234.5 and cut[1:] == full[1:], (cut, full)
PY
# visset's series are named by their positions and budget (whose default
# depends on whether the svs section ran), so a later run with the other
# budget does not continue them.
expect_exit 0 "$RL" bench culling --quick --only visset --resume "$TMP/res" --out "$TMP/v1.json"
for f in visset-time-at-4-random-positions.json visset-budget-10000-quality-at-4-random-positions.json; do
    [ -s "$TMP/res/$f" ] || fail "--resume did not keep $f"
done
expect_exit 0 "$RL" bench culling --quick --only svs,visset --resume "$TMP/res" --out "$TMP/v2.json"
expect_in "$TMP/err" "visset time at 4 random positions: 4 of 4 positions measured before"
ls "$TMP/res" | grep -q "visset-budget-10000-time" || fail "the budget of 10000 lost its series"
ls "$TMP/res" | grep -v 10000 | grep -q "visset-budget-.*-time-at-4" || fail "the svs section's budget was not measured anew"
expect_error 1 "other options" "$RL" bench culling --quick --only svs --seed 2 --resume "$TMP/res" --out "$TMP/r3.json"
echo 'not json' >"$TMP/res/svs-quality.json"
expect_exit 1 "$RL" bench culling --quick --only svs --resume "$TMP/res" --out "$TMP/r4.json"
expect_in "$TMP/err" "not a saved series"
echo '{"dims": 2' >"$TMP/res/slice.json"
expect_exit 1 "$RL" bench culling --quick --only svs --resume "$TMP/res" --out "$TMP/r5.json"
expect_in "$TMP/err" "slice.json:2:1"
grep -q "sampling polygons" "$TMP/err" && fail "a damaged slice was sampled over"

expect_exit 0 "$RL" bench culling --quick --only depth --max-depth 1 -q --out "$TMP/d.json"
python3 - "$TMP/d.json" <<'PY' || fail "d.json is wrong"
import json, sys
r = json.load(open(sys.argv[1]))
assert len(r["depth"]["depths"]) == 2 and "svs" not in r, r.keys()
PY

# --resume in the depth section: each depth's sampling is kept, a longer run
# continues after the depths done (their noisy times come back unchanged),
# and a damaged depth file is an error, not a silent resample.
expect_exit 0 "$RL" bench culling --quick --only depth --max-depth 1 --resume "$TMP/dres" --out "$TMP/d1.json"
for f in depth-0.json depth-1.json; do
    [ -s "$TMP/dres/$f" ] || fail "--resume did not keep $f"
done
expect_exit 0 "$RL" bench culling --quick --only depth --max-depth 2 --resume "$TMP/dres" --out "$TMP/d2.json"
expect_in "$TMP/err" "depth 0: sampled before"
expect_in "$TMP/err" "depth 1: sampled before"
[ -s "$TMP/dres/depth-2.json" ] || fail "--resume did not keep depth-2.json"
ls "$TMP/dres" "$TMP/res" | grep -q '\.tmp$' && fail "a temporary file was left behind"
python3 - "$TMP/d1.json" "$TMP/d2.json" <<'PY' || fail "a resumed depth run differs"
import json, sys
a, b = (json.load(open(f))["depth"]["depths"] for f in sys.argv[1:3])
assert len(a) == 2 and len(b) == 3, (a, b)
assert a == b[:2], (a, b[:2])
PY
echo 'not json' >"$TMP/dres/depth-1.json"
expect_exit 1 "$RL" bench culling --quick --only depth --max-depth 1 --resume "$TMP/dres" --out "$TMP/d3.json"
echo "ok"
