#!/usr/bin/env bash
# test_cli_bench_surfels.sh: `rl bench surfels --quick` times every step and
# sampling variant of the Progressive Blue Surfels preprocessing (Jaehn
# 2015, Table 6.1) on a tiny scene and writes a complete JSON record with
# sane values; --variants and --max-seconds pick and skip variants; bad
# usage exits 2, an unwritable output 1. Keeps the benchmark from rotting;
# it measures nothing.
# Run as: bash test_cli_bench_surfels.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# Bad usage first (cheap): exit 2 with one error line, before anything runs.
expect_usage_error "$RL" bench surfels --count 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --resolution 20000 --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --variants random,nosuch --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --variants "" --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --max-seconds -1 --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --threads 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --quick --out "$TMP/x.txt"
expect_usage_error "$RL" bench surfels --frobnicate
expect_usage_error "$RL" bench surfels --count
[ -e "$TMP/x.json" ] && fail "a failed run wrote x.json"

# Output folder that does not exist: exit 1, checked before the run.
expect_exit 1 "$RL" bench surfels --quick --out "$TMP/no/such/dir/s.json"
expect_in "$TMP/err" "rl: error: "

# Help, and the bench dispatcher knows surfels.
expect_exit 0 "$RL" bench surfels --help
for o in --scene --resolution --count --variants --max-seconds --seed --threads --out --quick \
         prog-160 const-1000; do
    expect_in "$TMP/out" "$o"
done
expect_exit 0 "$RL" bench --help
expect_in "$TMP/out" "rl bench surfels"
expect_error 2 "surfels" "$RL" bench nosuch

# The quick run: both sections, the table on stdout, JSON where --out says.
expect_exit 0 "$RL" bench surfels --quick --out "$TMP/s.json"
[ -s "$TMP/s.json" ] || fail "s.json was not written"
for s in "atlas" "candidate set" "relative point sizes" "total with the defaults" "target:" \
         "Table 6.1" random prog-1000 const-160 "20 bytes per surfel"; do
    expect_in "$TMP/out" "$s"
done
expect_in "$TMP/err" "bench surfels: wrote"

# The atlas section alone (issue 35, part 6): software and, where a GL 4.5
# context can be made, GL in the same run; otherwise the reason.
expect_usage_error "$RL" bench surfels --only atlas,nosuch --out "$TMP/x.json"
expect_usage_error "$RL" bench surfels --atlas-runs 0 --out "$TMP/x.json"
expect_exit 0 "$RL" bench surfels --quick --only atlas --atlas-runs 1 --out "$TMP/a.json"
expect_in "$TMP/out" "software rasterizer"
python3 - "$TMP/a.json" <<'PY' || fail "a.json does not hold a sane atlas record"
import json, sys
r = json.load(open(sys.argv[1]))
assert "defaults" not in r and "variants" not in r, list(r)
a = r["atlas"]
assert a["runs"] == 1 and a["thesis_atlas_ms"] == 270, a
assert a["software"]["candidates"] > 1000 and a["software"]["min_atlas_ms"] > 0, a
if "gl_unavailable" not in a:
    g = a["gl"]
    assert g["candidates"] > 0 and g["min_atlas_ms"] > 0 and g["drawer_create_ms"] > 0, g
    # Equal counts up to rasterization rules (docs/gl.md: equal on cornell).
    assert abs(g["candidates"] - a["software"]["candidates"]) <= 0.005 * a["software"]["candidates"], a
    assert a["gl_device"]["renderer"], a
PY

python3 - "$TMP/s.json" <<'PY' || fail "s.json does not hold a complete, sane record"
import json, sys
r = json.load(open(sys.argv[1]))
for k in ("benchmark", "renderlab_version", "date", "machine", "parameters", "thesis",
          "defaults", "variants"):
    assert k in r, "missing key " + k
assert r["benchmark"] == "surfels"
for k in ("uname", "cpu", "nproc", "threads"):
    assert k in r["machine"], "machine lacks " + k
p = r["parameters"]
assert p["quick"] is True and p["scene"] == "cornell" and p["resolution"] == 128, p
assert p["count"] == 2000 and len(p["variants"]) == 5, p
t = r["thesis"]
assert t["sampling_prog-160_ms"] == 520 and t["sampling_const-1000_ms"] == 81000, t
d = r["defaults"]
assert d["status"] == "ok", d
assert d["surfels"] == 2000 and d["candidates"] > 2000 and 0 < d["coverage"] <= 1, d
assert d["bytes_per_surfel"] == 20 and d["surfel_bytes"] == 40000, d
for k in ("atlas_ms", "candidates_ms", "sampling_ms", "sizes_ms", "total_ms"):
    assert d["timing"][k] > 0, (k, d["timing"])
assert d["timing"]["total_ms"] >= d["timing"]["sampling_ms"]
assert isinstance(d["target_met"], bool)
v = r["variants"]
assert v["status"] == "ok", v
names = [x["variant"] for x in v["variants"]]
assert names == ["random", "prog-160", "prog-1000", "const-160", "const-1000"], names
for x in v["variants"]:
    if x["skipped"]:
        continue
    assert x["surfels"] == 2000 and x["sampling_ms"] >= 0, x
    pre = x["prefixes"]
    assert [q["prefix"] for q in pre] == [16, 32, 64, 128, 256, 512, 1024, 2000], pre
    for q in pre:
        assert 0 <= q["min_rel"] <= q["mean_rel"], q
byname = {x["variant"]: x for x in v["variants"]}
# Blue noise: the progressive prefixes keep their points apart, random clumps.
assert byname["prog-160"]["prefixes"][-1]["min_rel"] > 2 * byname["random"]["prefixes"][-1]["min_rel"]
PY

# --variants picks, --max-seconds skips what would take too long.
expect_exit 0 "$RL" bench surfels --quick --variants random,const-1000 --max-seconds 0.000001 \
    -q --out "$TMP/v.json"
python3 - "$TMP/v.json" <<'PY' || fail "v.json is wrong"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["parameters"]["variants"] == ["random", "const-1000"], r["parameters"]
v = {x["variant"]: x for x in r["variants"]["variants"]}
assert sorted(v) == ["const-1000", "random"], v
assert v["random"]["skipped"] is False
assert v["const-1000"]["skipped"] is True and v["const-1000"]["estimated_ms"] > 0, v
PY
echo "ok"
