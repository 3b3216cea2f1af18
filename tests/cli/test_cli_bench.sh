#!/usr/bin/env bash
# test_cli_bench.sh: `rl bench rays --quick` runs every available accelerator
# on the Cornell box and writes a complete JSON record in which our own
# accelerators (which share the watertight triangle test) agree on every hit
# count, with the packet section (bvh and embree, single rays and packets of
# 8, whose hit counts agree too); missing mesh files are skipped, bad usage exits 2, an unwritable
# output 1. Keeps the benchmark from rotting; it measures nothing.
# Run as: bash test_cli_bench.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# The quick run: table on stdout, JSON where --out says.
expect_exit 0 "$RL" bench rays --quick --out "$TMP/b.json"
[ -s "$TMP/b.json" ] || fail "b.json was not written"
expect_in "$TMP/out" "cornell"
for a in bvh grid brute; do expect_in "$TMP/out" " $a "; done

python3 - "$TMP/b.json" <<'EOF' || fail "b.json does not hold a complete record"
import json, math, sys
r = json.load(open(sys.argv[1]))
for k in ("benchmark", "renderlab_version", "date", "machine", "parameters", "scenes", "hit_mismatches"):
    assert k in r, "missing key " + k
for k in ("uname", "cpu", "nproc", "threads"):
    assert k in r["machine"], "machine lacks " + k
assert r["parameters"]["size"] == "64x48" and r["parameters"]["quick"] is True
assert [s["scene"] for s in r["scenes"]] == ["cornell"], "quick runs cornell only"
s = r["scenes"][0]
assert s["status"] == "ok" and s["triangles"] == 36
assert s["rays"]["primary"] == 64 * 48, "one primary ray per pixel"
# Every primary hit spawns one shadow and one diffuse ray.
assert 0 < s["rays"]["shadow"] == s["rays"]["diffuse"] <= 64 * 48
accels = {a["accel"]: a for a in s["accels"]}
want = {"bvh", "grid", "brute"} | ({"embree"} if r["embree"] else set())
assert set(accels) == want, "accels %s, expected %s" % (sorted(accels), sorted(want))
for name, a in accels.items():
    assert a["status"] == "ok", name + " " + a["status"]
    assert a["build"]["memory_bytes"] >= 0 and a["build"]["build_ms"] >= 0
    for w in ("primary", "shadow", "diffuse"):
        x = a["workloads"][w]
        assert x["rays"] == s["rays"][w] and x["runs"] == 1 and x["deterministic"]
        assert x["seconds"] > 0 and x["mrays_per_s"] > 0
        assert x["cpu_seconds"] >= 0 and x["mrays_per_cpu_s"] > 0
        for k in ("ratio_to_embree", "cpu_ratio_to_embree"):
            if r["embree"]:
                assert x[k] > 0, k
            else:
                assert x[k] is None, k
# Primary hits feed the other workloads: each is the number of shadow rays.
assert accels["brute"]["workloads"]["primary"]["hits"] == s["rays"]["shadow"]
# Our accelerators share the watertight test: identical hit counts.
for w in ("primary", "shadow", "diffuse"):
    hits = {n: accels[n]["workloads"][w]["hits"] for n in ("bvh", "grid", "brute")}
    assert len(set(hits.values())) == 1, "%s hits differ: %s" % (w, hits)
    # The shadow and diffuse workloads are neither all hits nor all misses.
    if w != "primary":
        assert 0 < hits["brute"] < s["rays"][w], "%s: %s of %s rays hit" % (w, hits, s["rays"][w])
# The packet section: bvh (and embree) with single queries and with the
# batch queries in packets of 8, on the primary rays of 4x2 tiles and their
# shadow rays, in the same run. Our packets find exactly the single rays'
# hits; the workloads are the main ones in another order.
p = s["packets"]
assert p["tile"] == "4x2" and p["packet_size"] == 8
assert p["rays"]["primary"] == s["rays"]["primary"] and p["rays"]["shadow"] == s["rays"]["shadow"]
runs = {(x["accel"], x["mode"]): x for x in p["runs"]}
want = {("bvh", "single"), ("bvh", "packets")} | ({("embree", "single"), ("embree", "packets")} if r["embree"] else set())
assert set(runs) == want, "packet runs %s" % sorted(runs)
for (name, mode), x in runs.items():
    for w in ("primary", "shadow"):
        y = x["workloads"][w]
        assert y["runs"] == 1 and y["deterministic"] and y["cpu_seconds"] >= 0 and y["mrays_per_cpu_s"] > 0
        assert y["hits"] == accels["bvh"]["workloads"][w]["hits"], (name, mode, w)
        assert y["cpu_ratio_to_single"] > 0
        if mode == "single":
            assert y["cpu_ratio_to_single"] == 1
        if r["embree"]:
            assert y["cpu_ratio_to_embree_packets"] > 0
        else:
            assert y["cpu_ratio_to_embree_packets"] is None
    if (name, mode) == ("embree", "packets"):
        assert x["calls"] == "rtcIntersect8/rtcOccluded8"
        assert all(x["workloads"][w]["cpu_ratio_to_embree_packets"] == 1 for w in ("primary", "shadow"))
assert p["hits_agree"] == {"primary": True, "shadow": True}
EOF
expect_in "$TMP/out" "packets of 8 (4x2 tiles)"
expect_in "$TMP/out" "rtcIntersect8"

# --rays sets the number of primary rays; k=v after a comma continues the
# previous scene's parameters; a mesh file that is not there is skipped.
expect_exit 0 "$RL" bench rays --quick --accels brute --rays 100 -q \
    --scenes "cornell-teapot:triangles=200,size=0.1,$TMP/no-such-mesh.ply" --out "$TMP/s.json"
expect_in "$TMP/out" "skipped"
python3 - "$TMP/s.json" "$TMP/no-such-mesh.ply" <<'EOF' || fail "s.json is wrong"
import json, sys
r = json.load(open(sys.argv[1]))
s = r["scenes"]
assert [x["scene"] for x in s] == ["cornell-teapot:triangles=200,size=0.1", sys.argv[2]], s
assert s[0]["status"] == "ok" and 90 <= s[0]["rays"]["primary"] <= 110, s[0]
assert s[1]["status"] == "skipped" and "no such file" in s[1]["reason"], s[1]
# Without bvh or embree there is no packet section.
assert s[0]["packets"] is None, s[0]["packets"]
EOF

# Bad usage: exit 2 with one error line, before anything runs.
expect_usage_error "$RL" bench
expect_usage_error "$RL" bench nosuch
expect_usage_error "$RL" bench rays --quick --accels bvh,nosuch --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --accels "" --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --scenes "cornell,,city" --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --scenes "blocks=4" --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --scenes "city:nosuch=1" --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --size 0x48 --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --size 8192x8192 --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --threads 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --rays ten --out "$TMP/x.json"
expect_usage_error "$RL" bench rays --quick --out "$TMP/x.txt"
expect_usage_error "$RL" bench rays --quick --frobnicate
[ -e "$TMP/x.json" ] && fail "a failed run wrote x.json"

# Output folder that does not exist: exit 1, checked before the run.
expect_exit 1 "$RL" bench rays --quick --out "$TMP/no/such/dir/b.json"
expect_in "$TMP/err" "rl: error: "

# Help.
expect_exit 0 "$RL" bench rays --help
for o in --scenes --accels --rays --size --threads --out --quick example; do expect_in "$TMP/out" "$o"; done
expect_exit 0 "$RL" help bench
expect_in "$TMP/out" "usage: rl bench rays"
echo "ok"
