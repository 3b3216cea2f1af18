#!/usr/bin/env bash
# test_cli_eval.sh: `rl eval` (a property approximated over a region, Jähn
# 2015 Ch. 4-5), `rl compare` (renderers at the same sampled positions) and
# `rl bench sampling --quick` write complete, sane outputs; bad input gets
# one clear error line and exit 2 (usage) or 1 (input/output).
# Run as: bash test_cli_eval.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# --- bad usage: nothing is sampled, nothing is written ---
expect_usage_error "$RL" eval cornell --out "$TMP/e"
expect_error 2 "no scene" "$RL" eval --property visibility
expect_error 2 "nosuch" "$RL" eval cornell --property nosuch --out "$TMP/e"
expect_error 2 "resolution" "$RL" eval cornell --property visibility --set resolution=0 --out "$TMP/e"
expect_error 2 "frob" "$RL" eval cornell --property visibility --set frob=1 --out "$TMP/e"
expect_error 2 "one of measure, diameter" "$RL" eval cornell --property visibility --quality-size area --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --samples 0 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --dims 4 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --region 1,1,1,0,0,0 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --region 100,100,100,200,200,200 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --height 1e6 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --positions fancy --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --interp cubic --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --idw-neighbors 0 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --idw-neighbors 33 --out "$TMP/e"
expect_usage_error "$RL" eval cornell --property visibility --report "$TMP/e/r.txt"
expect_usage_error "$RL" eval cornell --property time --set renderer=nosuch --out "$TMP/e"
expect_error 2 "expected minus, ratio" "$RL" eval cornell --property time --property2 time --op plus --out "$TMP/e"
expect_error 2 "only with --property2" "$RL" eval cornell --property time --set2 renderer=raster --out "$TMP/e"
expect_error 2 "only with --property2" "$RL" eval cornell --property time --op ratio --out "$TMP/e"
expect_error 2 "nosuch" "$RL" eval cornell --property time --property2 nosuch --out "$TMP/e"
expect_error 2 "frob" "$RL" eval cornell --property time --property2 time --set2 frob=1 --out "$TMP/e"
[ -e "$TMP/e/approx.json" ] && fail "a failed eval wrote approx.json"
expect_exit 1 "$RL" eval no-such-scene.json --property visibility --out "$TMP/e"
expect_exit 0 "$RL" eval --list
for p in visibility time ops quality resolution renderer metric; do expect_in "$TMP/out" "$p"; done
expect_exit 0 "$RL" eval --help
for o in --property --set --validate --dims --region --height --positions --interp --idw-neighbors --samples; do
    expect_in "$TMP/out" "$o"
done

# --- a 2-D visibility approximation with validation ---
run_ok "$RL" eval cornell --property visibility --set resolution=32 --samples 48 --validate 20 \
    --out "$TMP/vis"
for f in approx.json eval.json report.html heatmap.png; do
    [ -s "$TMP/vis/$f" ] || fail "eval did not write $f"
done
expect_in "$TMP/out" "48 samples"
expect_in "$TMP/vis/report.html" "<svg"
# Sec. 5.6's plots: heat map, violin with box plot, histogram; with
# --validate the correlation of measured and approximated values.
for caption in "Heat map of the regions" "Violin plot" "Histogram of the region values" \
        "Pearson r"; do
    expect_in "$TMP/vis/report.html" "$caption"
done
[ "$(grep -o '<svg' "$TMP/vis/report.html" | wc -l)" -ge 4 ] || fail "the eval report lacks plots"
grep -q "<script" "$TMP/vis/report.html" && fail "the report must not need scripts"
grep -Eq '(src|href)="https?:' "$TMP/vis/report.html" && fail "the report must be self-contained"
python3 - "$TMP/vis/eval.json" "$TMP/vis/approx.json" <<'PY' || fail "eval.json/approx.json are not sane"
import json, sys
e = json.load(open(sys.argv[1]))
a = json.load(open(sys.argv[2]))
assert e["property"]["name"] == "visibility" and e["samples"] == 48, e
s = e["region_stats"]
assert 0 < s["min"] <= s["median"] <= s["max"] <= 8, s      # cornell has 8 objects
assert e["validation"]["points"] == 20 and e["validation"]["abs_error"]["mean"] >= 0
assert a["format"] == "renderlab-approx" and len(a["samples"]) == 48
PY

# A shifted grid: the flag reaches the sampler and both records.
run_ok "$RL" eval cornell --property visibility --set resolution=16 --method grid --grid-shift \
    --samples 16 --seed 4 --out "$TMP/shift"
python3 - "$TMP/shift/eval.json" "$TMP/shift/approx.json" <<'PY' || fail "--grid-shift is not applied"
import json, sys
e = json.load(open(sys.argv[1]))
a = json.load(open(sys.argv[2]))
assert a["desc"]["grid_shift"] is True and e["sampling"]["grid_shift"] is True, (a["desc"], e["sampling"])
PY

# Queries: idw with 4 neighbours by default, the count and the other
# interpolations reach the sampler and both records.
python3 - "$TMP/vis/eval.json" "$TMP/vis/approx.json" <<'PY' || fail "the default queries are not idw"
import json, sys
e = json.load(open(sys.argv[1]))
a = json.load(open(sys.argv[2]))
assert a["desc"]["interpolation"] == "idw" and a["desc"]["idw_neighbors"] == 4, a["desc"]
assert e["sampling"]["interpolation"] == "idw" and e["sampling"]["idw_neighbors"] == 4, e["sampling"]
PY
run_ok "$RL" eval cornell --property visibility --set resolution=16 --samples 16 --idw-neighbors 7 \
    --validate 8 --out "$TMP/idw7"
run_ok "$RL" eval cornell --property visibility --set resolution=16 --samples 16 --interp nearest \
    --validate 8 --out "$TMP/near"
python3 - "$TMP/idw7/approx.json" "$TMP/near/approx.json" <<'PY' || fail "--idw-neighbors/--interp are not applied"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["desc"]["interpolation"] == "idw" and a["desc"]["idw_neighbors"] == 7, a["desc"]
assert b["desc"]["interpolation"] == "nearest", b["desc"]
PY

# 3-D, grid method, an image-quality property of two renderers
run_ok "$RL" eval cornell --property quality --set renderer=raster --set reference=whitted \
    --set width=24 --set height=24 --dims 3 --method grid --samples 8 --out "$TMP/q"
expect_in "$TMP/out" "SSIM"
# PSNR of a renderer against itself: equal images everywhere, capped at 100 dB
# so that statistics and plots stay finite (+inf once failed the whole run).
run_ok "$RL" eval cornell --property quality --set renderer=raster --set reference=raster \
    --set metric=psnr --set width=16 --set height=16 --samples 8 --out "$TMP/psnr"
expect_in "$TMP/out" "dB mean 100"

# A combined property (Sec. 4.2.6): the op and both parts reach the record,
# and its value is the difference of the parts at the same positions.
run_ok "$RL" eval cornell --property ops --set renderer=whitted --set counter=rays --set width=16 \
    --set height=16 --property2 ops --set2 renderer=whitted --set2 counter=shadow_rays \
    --set2 width=16 --set2 height=16 --samples 8 --method grid --out "$TMP/comb"
run_ok "$RL" eval cornell --property ops --set renderer=whitted --set counter=rays --set width=16 \
    --set height=16 --samples 8 --method grid --out "$TMP/comb-a"
run_ok "$RL" eval cornell --property ops --set renderer=whitted --set counter=shadow_rays --set width=16 \
    --set height=16 --samples 8 --method grid --out "$TMP/comb-b"
python3 - "$TMP/comb" "$TMP/comb-a" "$TMP/comb-b" <<'PY' || fail "--property2 is not applied"
import json, sys
e = json.load(open(sys.argv[1] + "/eval.json"))
p = e["property"]
assert p["name"] == "difference(ops, ops)" and p["op"] == "minus", p
assert p["options"]["counter"] == "rays" and p["second"]["options"]["counter"] == "shadow_rays", p
c, a, b = (json.load(open(d + "/approx.json"))["samples"] for d in sys.argv[1:4])
assert len(c) == len(a) == len(b) == 8
for sc, sa, sb in zip(c, a, b):   # [x, y, z, value]
    assert sc[:3] == sa[:3] == sb[:3], (sc, sa, sb)
    assert sc[3] == sa[3] - sb[3] and sb[3] > 0, (sc, sa, sb)
PY

# --- rl compare ---
expect_usage_error "$RL" compare cornell --out "$TMP/c"
expect_error 2 "nosuch" "$RL" compare cornell --algos raster,nosuch --out "$TMP/c"
expect_usage_error "$RL" compare cornell --algos raster --metrics time,speed --out "$TMP/c"
expect_usage_error "$RL" compare cornell --algos raster:frob=1 --out "$TMP/c"
expect_error 2 "neither KEY=VALUE nor a value" "$RL" compare cornell --algos pt:ls-nosuch --out "$TMP/c"
expect_error 2 "quality-metric" "$RL" compare cornell --algos raster --quality-metric mse --out "$TMP/c"
# pt:ls-pnmt: the issue's own spelling, a bare value for every option
# offering it (shadow and diffuse rays by the PNMT Line Space).
run_ok "$RL" compare cornell --algos raster,whitted:max_depth=2,pt:spp=1,max_depth=2,pt:ls-pnmt,chcpp \
    --size 24x24 --samples 12 --repeats 1 --resolution 16 --out "$TMP/c"
[ -s "$TMP/c/report.html" ] && [ -s "$TMP/c/compare.json" ] || fail "compare outputs missing"
# A violin plot per metric and heat maps side by side (one per renderer
# that does the operation), besides the visibility that placed the samples.
for title in "Rendering time" "Traced rays" "Rasterized triangles" "Occlusion queries" "Image quality"; do
    expect_in "$TMP/c/report.html" "$title"
done
[ "$(grep -o '<svg' "$TMP/c/report.html" | wc -l)" -ge 20 ] || fail "the compare report lacks plots"
python3 - "$TMP/c/compare.json" <<'PY' || fail "compare.json is not sane"
import json, sys
c = json.load(open(sys.argv[1]))
names = [r["renderer"] for r in c["renderers"]]
assert names == ["raster", "whitted:max_depth=2", "pt:spp=1,max_depth=2", "pt:ls-pnmt", "chcpp"], names
assert c["quality_metric"] == "hssim", c["quality_metric"]       # the thesis' SSIM
for r in c["renderers"]:
    assert r["time"]["min"] > 0, r
    assert 0 <= r["quality"]["max"] <= 1.0 + 1e-9, r
raster, whitted, pt, ls, chcpp = c["renderers"]
assert raster["rays"]["max"] == 0 and raster["triangles"]["min"] > 0
assert raster["queries"]["max"] == 0 and chcpp["queries"]["min"] > 0     # CHC++'s occlusion queries
assert ls["rays"]["min"] > 0
assert whitted["rays"]["min"] > 0 and whitted["quality"]["min"] > 0.999   # whitted is the reference
PY

# The Ch. 7 recipes of docs/culling.md in miniature: Sec. 7.5, the times of
# chcpp and svs sampled by rl eval, then select reading them beside both;
# Sec. 7.6, the visible sets sampled by rl eval, then drawn by visset.
run_ok "$RL" eval cornell --property time --set renderer=chcpp --set conditioned=true --set width=24 \
    --set height=24 --samples 8 --out "$TMP/t-chcpp"
run_ok "$RL" eval cornell --property time --set renderer=svs --set renderer_options=resolution=32 \
    --set conditioned=true --set width=24 --set height=24 --samples 8 --out "$TMP/t-svs"
run_ok "$RL" compare cornell --algos chcpp,svs:resolution=32,select:first_time="$TMP/t-chcpp/approx.json",second_time="$TMP/t-svs/approx.json" \
    --metrics time,triangles --size 24x24 --samples 8 --repeats 1 --resolution 16 --out "$TMP/select"
run_ok "$RL" eval cornell --property visibility --set resolution=16 --samples 16 --out "$TMP/vis16"
run_ok "$RL" compare cornell --algos visset:approx="$TMP/vis16/approx.json",chcpp --reference raster \
    --size 24x24 --samples 8 --repeats 1 --resolution 16 --out "$TMP/visset"
python3 - "$TMP/select/compare.json" "$TMP/visset/compare.json" <<'PY' || fail "the Ch. 7 recipes are not sane"
import json, sys
sel = json.load(open(sys.argv[1]))["renderers"]
assert [r["renderer"].split(":")[0] for r in sel] == ["chcpp", "svs", "select"], sel
assert all(r["time"]["min"] > 0 and r["triangles"]["min"] > 0 for r in sel), sel
vis = json.load(open(sys.argv[2]))["renderers"]
assert vis[1]["quality"]["min"] == 1.0, vis[1]          # chcpp is conservative
assert 0 < vis[0]["quality"]["min"] <= 1.0 and vis[0]["triangles"]["min"] > 0, vis
PY

# --- rl bench sampling ---
expect_usage_error "$RL" bench sampling --only nosuch --out "$TMP/b.json"
expect_usage_error "$RL" bench sampling --samples 0 --out "$TMP/b.json"
expect_error 2 "one of measure, diameter" "$RL" bench sampling --quality-size area --out "$TMP/b.json"
expect_error 2 "expected a number" "$RL" bench sampling --samples-base 0 --out "$TMP/b.json"
expect_error 2 "expected a number" "$RL" bench sampling --samples-per-meter nan --out "$TMP/b.json"
expect_usage_error "$RL" bench sampling --repeats 0 --out "$TMP/b.json"
run_ok "$RL" bench sampling --quick --out "$TMP/b.json"
for s in variants convergence throughput grid-idw bn-corners; do expect_in "$TMP/out" "$s"; done
python3 - "$TMP/b.json" <<'PY' || fail "bench sampling JSON is not complete"
import json, sys
r = json.load(open(sys.argv[1]))
for s in ("variants", "convergence", "throughput"):
    assert r[s]["status"] == "ok", (s, r[s])
assert r["variants"]["cases_total"] == 8 and len(r["variants"]["cases"]) == 8
for c in r["variants"]["cases"]:
    for v in ("grid", "grid-idw", "grid~", "random", "bn", "bn-corners", "bnc-region"):
        assert c[v]["abs_error"]["mean"] >= 0, c
        assert c[v]["mean_abs_error"] == c[v]["abs_error"]["mean"], c
assert r["throughput"]["rows"][0]["samples_per_second"] > 0
assert "machine" in r
assert r["parameters"]["samples_base"] == 5 and r["parameters"]["samples_per_meter"] == 0.05
PY
# --samples-base reaches the adaptive variants but not the grid or the
# thesis' bnc-region.
run_ok "$RL" bench sampling --quick --only variants --samples-base 12 --out "$TMP/b12.json"
python3 - "$TMP/b.json" "$TMP/b12.json" <<'PY' || fail "--samples-base is not applied as documented"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert b["parameters"]["samples_base"] == 12
ca, cb = a["variants"]["cases"], b["variants"]["cases"]
err = lambda c, v: c[v]["abs_error"]["mean"]
for x, y in zip(ca, cb):
    assert err(x, "grid") == err(y, "grid") and err(x, "bnc-region") == err(y, "bnc-region"), (x, y)
assert any(err(x, "bn-corners") != err(y, "bn-corners") for x, y in zip(ca, cb))
PY
# --repeats: grid~, bn (the target) and bn-corners over seeds 1..R, their
# mean compared; seed 1 is the run without repeats, the rest untouched.
run_ok "$RL" bench sampling --quick --only variants --repeats 3 --out "$TMP/b3.json"
python3 - "$TMP/b.json" "$TMP/b3.json" <<'PY' || fail "--repeats is not applied as documented"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert b["parameters"]["repeats"] == 3
for x, y in zip(a["variants"]["cases"], b["variants"]["cases"]):
    for v in ("grid", "grid-idw", "grid~", "random", "bn", "bn-corners", "bnc-region"):
        seeds = y[v]["mean_abs_error_per_seed"]
        assert len(seeds) == (3 if v in ("grid~", "bn", "bn-corners") else 1), (v, y)
        assert seeds[0] == x[v]["abs_error"]["mean"], (v, x, y)
        assert abs(y[v]["mean_abs_error"] - sum(seeds) / len(seeds)) < 1e-12, (v, y)
    m, g, gi, s = (y[v]["mean_abs_error"] for v in ("bn", "grid", "grid-idw", "grid~"))
    assert y["adaptive_no_worse_than_grid"] == (m <= min(g, gi)), y
    assert y["adaptive_no_worse_than_thesis_grid"] == (m <= g), y
    assert y["adaptive_no_worse_than_shifted_grid"] == (m <= s), y
    # grid-idw queries the grid's own samples: the same count, the same time
    assert y["grid-idw"]["samples_taken"] == y["grid"]["samples_taken"], y
r = b["variants"]
assert r["cases_met"] == sum(c["adaptive_no_worse_than_grid"] for c in r["cases"])
assert r["cases_met_thesis_grid"] == sum(c["adaptive_no_worse_than_thesis_grid"] for c in r["cases"])
assert r["cases_met_shifted_grid"] == sum(c["adaptive_no_worse_than_shifted_grid"] for c in r["cases"])
PY
# --checkpoint: a journal of the measured batches. A run that stopped (here
# the file cut in the middle of a batch, as a kill while writing leaves it)
# is continued by the same command: the recorded batches are replayed, the
# rest measured, and the approximation is the uninterrupted run's. A file of
# another evaluation is refused and left alone; so is a folder.
CK=(city:blocks=1 --property visibility --set resolution=16 --samples 60 --seed 7)
run_ok "$RL" eval "${CK[@]}" --out "$TMP/ck0" -q
run_ok "$RL" eval "${CK[@]}" --out "$TMP/ck1" --checkpoint "$TMP/ck.bin" -q
size=$(stat -c %s "$TMP/ck.bin")
cp "$TMP/ck.bin" "$TMP/ck-whole.bin"
truncate -s $((size * 2 / 3)) "$TMP/ck.bin"
run_ok "$RL" eval "${CK[@]}" --out "$TMP/ck2" --checkpoint "$TMP/ck.bin"
expect_in "$TMP/err" "checkpoint .*ck.bin: [0-9]* samples replayed; measuring on from there"
cmp -s "$TMP/ck.bin" "$TMP/ck-whole.bin" || fail "the resumed run's checkpoint differs from an uninterrupted one's"
python3 - "$TMP/ck0/approx.json" "$TMP/ck1/approx.json" "$TMP/ck2/approx.json" <<'PY' ||
import json, sys
a, b, c = (json.load(open(f)) for f in sys.argv[1:4])
for x in (a, b, c):
    x.pop("seconds")
assert a == b == c
PY
    fail "a checkpointed or resumed run differs from the plain one"
expect_exit 1 "$RL" eval "${CK[@]}" --set resolution=32 --out "$TMP/ck3" --checkpoint "$TMP/ck.bin"
expect_in "$TMP/err" "checkpoint .*ck.bin: it belongs to another evaluation"
cmp -s "$TMP/ck.bin" "$TMP/ck-whole.bin" || fail "a refused checkpoint was changed"
[ ! -e "$TMP/ck3/approx.json" ] || fail "a refused checkpoint run wrote an approximation"
expect_exit 1 "$RL" eval "${CK[@]}" --out "$TMP/ck3" --checkpoint "$TMP"
expect_in "$TMP/err" "not a regular file"
printf 'garbage' >"$TMP/ck-bad.bin"
expect_exit 1 "$RL" eval "${CK[@]}" --out "$TMP/ck3" --checkpoint "$TMP/ck-bad.bin"
expect_in "$TMP/err" "not a renderlab sampling checkpoint"
echo "ok"
