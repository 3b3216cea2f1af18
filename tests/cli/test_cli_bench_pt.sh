#!/usr/bin/env bash
# test_cli_bench_pt.sh: `rl bench pt --quick` runs every section of the Line
# Space path-tracing benchmark (Schröder 2017, Table 1, Diagrams 1-3) and
# writes a complete JSON record with sane values; bad usage exits 2, an
# unwritable output 1. Keeps the benchmark from rotting; it measures nothing.
# Run as: bash test_cli_bench_pt.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

expect_usage_error "$RL" bench pt --ref-spp 0 --out "$TMP/x.json"
expect_usage_error "$RL" bench pt --spp-max many --out "$TMP/x.json"
expect_usage_error "$RL" bench pt --size 0x0 --out "$TMP/x.json"
expect_usage_error "$RL" bench pt --error-size 64 --out "$TMP/x.json"
expect_usage_error "$RL" bench pt --only scenes,nosuch --out "$TMP/x.json"
expect_usage_error "$RL" bench pt --quick --out "$TMP/x.txt"
expect_usage_error "$RL" bench pt --frobnicate
expect_usage_error "$RL" bench pt --fixed-k 7 --out "$TMP/x.json"
[ -e "$TMP/x.json" ] && fail "a failed run wrote x.json"

expect_exit 1 "$RL" bench pt --quick --out "$TMP/no/such/dir/pt.json"
expect_in "$TMP/err" "rl: error: "

expect_exit 0 "$RL" bench pt --help
for o in --size --error-size --ref-spp --spp-max --max-memory --builds --fixed-k --small-pages --only --out \
         --quick generation accumulation convergence --conv-size --conv-ref-spp --conv-spp-max --conv-ref-budget --conv-set \
         bdpt; do
    expect_in "$TMP/out" "$o"
done

expect_exit 0 "$RL" bench pt --quick --out "$TMP/pt.json"
[ -s "$TMP/pt.json" ] || fail "pt.json was not written"
for s in generation scenes diffuse shadow error specular accumulation ls-pnmt shadowmap kuwahara; do
    expect_in "$TMP/out" "$s"
done
expect_in "$TMP/err" "bench pt: wrote"

python3 - "$TMP/pt.json" <<'PY' || fail "pt.json does not hold a complete, sane record"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["benchmark"] == "pt"
for k in ("renderlab_version", "date", "machine", "parameters", "thesis"):
    assert k in r, "missing key " + k
p = r["parameters"]
assert p["quick"] is True and p["size"] == "128x72" and p["error_size"] == "64x36", p
for name in ("generation", "scenes", "diffuse", "shadow", "error", "specular", "accumulation"):
    assert r[name]["status"] == "ok", "%s: %s" % (name, r[name].get("reason"))
sp = r["specular"]["variants"]
assert [v["specular"] for v in sp] == ["exact", "exact", "diffuse"], sp   # --quick: the PNMT pair
assert all(0 <= v["rmse"] < 1 and v["ms_per_spp"] > 0 for v in sp), sp

g = r["generation"]["rows"]
assert [(x["voxel_res"], x["n"]) for x in g] == [(8, 4), (8, 5)], g
for x in g:
    assert x["status"] == "ok" and x["triangles"] == 36, x
    assert x["ls_ms"] > 0 and x["grid_ms"] >= 0 and x["ls_bytes"] > 0, x
    assert x["ls_ms_runs"] == [x["ls_ms"]], x          # --quick: one build
    assert x["shafts"] == x["filled_voxels"] * 15 * x["n"] ** 4, x
    assert 0 <= x["empty_shafts"] <= x["shafts"], x
    # The cost of dynamic lists: the same row with fixed lists of k = 8
    # (k slots per occupied shaft: the front and the back half).
    f = x["fixed"]
    assert f["status"] == "ok" and f["k"] == 8 and f["ms_runs"] == [f["ms"]], f
    assert f["ms"] > 0 and f["bytes"] > 0 and f["dynamic_over_fixed_ms"] > 0, f
    occupied = x["shafts"] - x["empty_shafts"]
    assert 0 <= f["truncated_shafts"] <= occupied, f
    assert 0 < f["candidates"] <= 8 * occupied, f

def frames_ok(frames, labels):
    assert [f["label"] for f in frames] == labels, frames
    for f in frames:
        assert f["frame_ms"] > 0 and f["mrays_per_s"] > 0 and f["rays"]["total"] > 0, f
    assert frames[0]["speedup_vs_base"] == 1, frames[0]

sc = r["scenes"]["scenes"]
assert [x["scene"] for x in sc] == ["ls-cornell:model=boxes"], sc
frames_ok(sc[0]["frames"], ["grid", "ls-pnmt", "ls-candidates", "bvh"])
# Diagrams 2-3: every Line Space variant at each voxel resolution of the
# quick sweep (4^3, 8^3), and the fastest per variant.
variants = ("ls-candidates", "ls-fixed-k8", "ls-pnmt", "ls-preillum")
sweep = ["%s@%d" % (v, n) for v in variants for n in (4, 8)]
levels = ["ls-object", "ls-scene/object", "ls-scene/bvh"]     # Sec. 13.1, 13.2
frames_ok(r["diffuse"]["frames"], ["grid", "bvh", "no diffuse rays"] + sweep + levels)
frames_ok(r["shadow"]["frames"], ["grid", "bvh", "shadowmap"] + sweep + levels)
for sec in ("diffuse", "shadow"):
    best = r[sec]["best"]
    assert sorted(best) == sorted(variants), best
    for v, o in best.items():
        times = [f["frame_ms"] for f in r[sec]["frames"] if f["label"].startswith(v + "@")]
        assert o["grid_res"] in (4, 8) and o["frame_ms"] == min(times), (sec, v, o, times)
# Shadow rays alone: the exact structures agree on every ray (the
# candidate Line Space is exact); PNMT and the BVH share the cut rays.
ra = r["shadow"]["rays_alone"]
n = ra["bvh"]["rays"]
assert n > 0 and ra["grid"]["rays"] == n and ra["bvh"]["ms"] > 0, ra
assert abs(ra["grid"]["occluded"] - ra["bvh"]["occluded"]) <= max(2, n // 500), ra
assert [x["voxel_res"] for x in ra["line_spaces"]] == [4, 8], ra
for x in ra["line_spaces"]:
    assert x["candidates"]["rays"] == n, x
    assert abs(x["candidates"]["occluded"] - ra["bvh"]["occluded"]) <= max(2, n // 500), x
    assert 0 < x["pnmt"]["rays"] == x["bvh_same_rays"]["rays"] <= n, x
    assert x["pnmt"]["ms"] > 0 and x["pnmt_speedup_vs_bvh"] > 0, x
# Diffuse rays alone ("occluded" counts their hits), and the scene and
# object Line Spaces: exact, so the BVH's counts (the tolerance as above).
dr = ra["diffuse_rays"]
m = dr["bvh"]["rays"]
near = lambda a, b, k: abs(a - b) <= max(2, k // 500)
assert m > 0 and near(dr["grid"]["occluded"], dr["bvh"]["occluded"], m), dr
lv = ra["scene_and_object_line_spaces"]
assert lv["build"]["ls_object_ms"] > 0 and lv["build"]["ls_scene_ms"] > 0, lv["build"]
assert lv["build"]["ls_object_bytes"] > 0 and 0 < lv["build"]["ls_scene_fill"] <= 1, lv["build"]
for name in levels:
    assert lv["shadow"][name]["rays"] == n and near(lv["shadow"][name]["occluded"], ra["bvh"]["occluded"], n), lv
    assert lv["diffuse"][name]["rays"] == m and near(lv["diffuse"][name]["occluded"], dr["bvh"]["occluded"], m), lv
for x in ra["line_spaces"]:
    assert near(x["candidates_diffuse"]["occluded"], dr["bvh"]["occluded"], m), x
d = {f["label"]: f for f in r["diffuse"]["frames"]}
assert d["no diffuse rays"]["rays"].get("diffuse", 0) == 0, d["no diffuse rays"]["rays"]
assert "rays_speedup_vs_base" in d["ls-pnmt@4"]

e = r["error"]
assert e["reference_spp"] == 64
labels = [v["label"] for v in e["variants"]]
assert labels == ["bvh", "grid", "shadowmap", "ls-candidates@4", "ls-fixed-k8@4", "ls-pnmt@4",
                  "ls-pnmt@8", "ls-preillum@4", "ls-preillum@8", "ls-pnmt@4 exact"], labels
assert [v["ls_origin"] for v in e["variants"]] == ["offset"] * 9 + ["exact"]
assert [v["ls_fixed_lists"] for v in e["variants"]] == [False] * 4 + [True] + [False] * 5
for v in e["variants"]:
    c = v["curve"]
    assert [x["spp"] for x in c] == [1, 2, 4, 8], c
    for x in c:
        assert 0 <= x["rmse"] <= 1 and -1 <= x["ssim"] <= 1 and x["time_ms"] > 0, x
    assert all(c[i]["time_ms"] <= c[i + 1]["time_ms"] for i in range(len(c) - 1))
# The exact variants trace the same paths (up to hits on shared edges,
# where structures may pick either triangle): nearly the same error.
by = {v["label"]: v["curve"] for v in e["variants"]}
for other in ("grid", "ls-candidates@4"):
    for a, b in zip(by["bvh"], by[other]):
        assert abs(a["rmse"] - b["rmse"]) <= 0.02 * a["rmse"] + 1e-6, (other, a, b)
# More samples, less error (exact path tracer, same seed).
assert by["bvh"][-1]["rmse"] < by["bvh"][0]["rmse"]

a = r["accumulation"]
assert [x["spp"] for x in a["convergence"]] == [1, 2, 4, 8]
assert [f["filter"] for f in a["filters"]] == ["none", "gauss", "bilateral", "aniso", "kuwahara"]
for f in a["filters"]:
    assert [x["spp"] for x in f["points"]] == [1, 4], f
# At 1 spp an edge-preserving filter lowers the error of the noisy image
# (plain Gauss need not: on a 64x36 image it blurs the edges as much).
none1 = a["filters"][0]["points"][0]["rmse"]
assert a["filters"][2]["points"][0]["rmse"] < none1, a["filters"]
PY

expect_exit 0 "$RL" bench pt --quick --only generation --builds 3 --small-pages -q --out "$TMP/o.json"
python3 - "$TMP/o.json" <<'PY' || fail "o.json is wrong"
import json, sys
r = json.load(open(sys.argv[1]))
assert "generation" in r and "scenes" not in r and "error" not in r
p = r["parameters"]
assert p["ls_builds"] == 3 and p["ls_huge_pages"] is False, p
for x in r["generation"]["rows"]:
    runs = x["ls_ms_runs"]
    assert len(runs) == 3 and all(t > 0 for t in runs) and x["ls_ms"] == min(runs), x
PY
expect_exit 2 "$RL" bench pt --quick --builds 0
expect_in "$TMP/err" "--builds"
expect_exit 2 "$RL" bench pt --quick --builds 101

# convergence (issue 37): every configuration's curve, the reference cached
# beside the record and reused by the next run.
expect_usage_error "$RL" bench pt --only convergence --conv-ref-spp 1 --out "$TMP/c.json"
expect_usage_error "$RL" bench pt --only convergence --conv-size 0 --out "$TMP/c.json"
mkdir -p "$TMP/conv"
expect_exit 0 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 32 --conv-spp-max 8 \
    --out "$TMP/conv/c.json"
[ -s "$TMP/conv/pt-convergence-ref-16-32.bin" ] || fail "the convergence reference was not cached"
python3 - "$TMP/conv/c.json" <<'PY' || fail "c.json is wrong"
import json, sys
c = json.load(open(sys.argv[1]))["convergence"]
assert c["status"] == "ok", c
assert c["scene"] == "cornell:variant=bitterli" and c["size"] == 16, c
assert c["reference"]["spp"] == 32 and c["reference"]["cached"] is False, c["reference"]
labels = [x["label"] for x in c["configurations"]]
assert labels[0] == "defaults" and labels[1].startswith("thesis") and "mis=off" in labels, labels
assert "adaptive=on" in labels and any(l.startswith("atrous") for l in labels), labels
for x in c["configurations"]:
    assert [p["spp"] for p in x["points"]] == [4, 8], x
    assert all(0 < p["rmse"] < 1 and p["cpu_ms"] > 0 and abs(p["mean_error"]) < 1 for p in x["points"]), x
    # A denoiser's error need not fall at 16 x 16 (its bias dominates).
    if "atrous" not in x["label"]:
        assert x["points"][1]["rmse"] < x["points"][0]["rmse"], x
PY
expect_exit 0 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 32 --conv-spp-max 8 \
    --out "$TMP/conv/c2.json"
python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["convergence"]["reference"]["cached"] is True' \
    "$TMP/conv/c2.json" || fail "the cached reference was not reused"
# --conv-set: one more configuration, pt's options as given, to --conv-spp-max
# against the cached reference ("none" runs it alone); a malformed list or
# an unknown option fails before any rendering.
expect_exit 0 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 32 --conv-spp-max 8 \
    --conv-configs none --conv-set rr_depth=6,light_samples=2 --out "$TMP/conv/c3.json"
python3 - "$TMP/conv/c3.json" <<'PY' || fail "c3.json (--conv-set) is wrong"
import json, sys
c = json.load(open(sys.argv[1]))["convergence"]
assert c["reference"]["cached"] is True, c["reference"]
(x,) = c["configurations"]
assert x["label"] == "custom (rr_depth=6,light_samples=2)", x["label"]
assert x["options"] == {"rr_depth": "6", "light_samples": "2"}, x["options"]
assert [p["spp"] for p in x["points"]] == [4, 8] and all(0 < p["rmse"] < 1 for p in x["points"]), x
PY
mkdir -p "$TMP/conv/bad"
expect_exit 1 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 32 --conv-spp-max 8 \
    --conv-set rr_depth --out "$TMP/conv/bad/c.json"
expect_in "$TMP/err" "expected KEY=VALUE"
expect_exit 1 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 32 --conv-spp-max 8 \
    --conv-set no_such_option=1 --out "$TMP/conv/bad/c.json"
expect_in "$TMP/err" "no_such_option"
[ ! -e "$TMP/conv/bad/pt-convergence-ref-16-32.bin" ] || fail "a bad --conv-set rendered the reference"

# A resumable reference: --conv-ref-budget stops after a chunk (16 spp per
# half here) with exit 1 and the progress saved in .part; reruns of the same
# command continue it, and the finished reference is byte for byte the one
# made at once (64 spp: four chunks, so four slices). A damaged .part is
# ignored: the reference starts over.
mkdir -p "$TMP/conv/once" "$TMP/conv/sliced"
expect_exit 0 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 64 --conv-spp-max 4 \
    --conv-configs defaults --out "$TMP/conv/once/c.json"
sliced() {
    "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 64 --conv-spp-max 4 \
        --conv-configs defaults --conv-ref-budget 0.000001 --out "$TMP/conv/sliced/c.json"
}
expect_error 1 "reference incomplete after --conv-ref-budget: 16 / 64 spp" sliced
[ -s "$TMP/conv/sliced/pt-convergence-ref-16-64.bin.part" ] || fail "no .part after the first slice"
[ -e "$TMP/conv/sliced/pt-convergence-ref-16-64.bin" ] && fail "a slice wrote the finished reference"
python3 -c 'import json,sys; c = json.load(open(sys.argv[1]))["convergence"]
assert c["status"] == "failed" and "rerun the same command" in c["reason"], c' "$TMP/conv/sliced/c.json" ||
    fail "the sliced record does not say why it stopped"
expect_error 1 "32 / 64 spp" sliced
expect_error 1 "48 / 64 spp" sliced
expect_in "$TMP/err" "continuing"
expect_exit 0 sliced
[ -e "$TMP/conv/sliced/pt-convergence-ref-16-64.bin.part" ] && fail "the .part outlived the finished reference"
cmp -s "$TMP/conv/once/pt-convergence-ref-16-64.bin" "$TMP/conv/sliced/pt-convergence-ref-16-64.bin" ||
    fail "the reference made in four slices differs from the one made at once"
python3 -c 'import json,sys; r = json.load(open(sys.argv[1]))["convergence"]["reference"]
assert r["cached"] is False and r["resumed_at_spp"] == 48, r' "$TMP/conv/sliced/c.json" ||
    fail "the last slice's record"
mkdir -p "$TMP/conv/bad"
head -c 100 "$TMP/conv/once/pt-convergence-ref-16-64.bin" >"$TMP/conv/bad/pt-convergence-ref-16-64.bin.part"
expect_exit 0 "$RL" bench pt --only convergence --quick --conv-size 16 --conv-ref-spp 64 --conv-spp-max 4 \
    --conv-configs defaults --out "$TMP/conv/bad/c.json"
cmp -s "$TMP/conv/once/pt-convergence-ref-16-64.bin" "$TMP/conv/bad/pt-convergence-ref-16-64.bin" ||
    fail "a damaged .part changed the reference"
expect_usage_error "$RL" bench pt --only convergence --conv-ref-budget -1 --out "$TMP/c.json"

# bdpt (issue 37): pt and bdpt at equal CPU time on both scenes; behind the
# shade bdpt's error is the lower one
expect_exit 0 "$RL" bench pt --only bdpt --quick --out "$TMP/bdpt.json"
python3 - "$TMP/bdpt.json" <<'PY' || fail "bdpt section"
import json, sys
b = json.load(open(sys.argv[1]))["bdpt"]
assert b["status"] == "ok" and b["size"] == 32, b
assert [s["scene"] for s in b["scenes"]] == ["variant=bitterli", "variant=shade"], b
for s in b["scenes"]:
    assert [r["algo"] for r in s["runs"]] == ["pt", "bdpt"], s
    assert all(r["spp"] > 0 and 0 <= r["rmse"] < 1 and r["cpu_ms"] > 0 for r in s["runs"]), s
shade = b["scenes"][1]["runs"]
assert shade[1]["rmse"] < shade[0]["rmse"], shade
PY
echo "ok"
