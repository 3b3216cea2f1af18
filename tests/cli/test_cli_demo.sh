#!/usr/bin/env bash
# test_cli_demo.sh: rl demo writes one PNG per scene x renderer, report.json
# and index.html. Restricted to the small scenes to stay quick under ASan;
# `make demo` renders them all.
# Run as: bash test_cli_demo.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

DIR="$TMP/demo/nested"   # does not exist yet: rl demo creates it
SCENES="cornell,cornell-teapot,spheres"

"$RL" demo --out "$DIR" --size 64x48 --scenes "$SCENES" --equal-time 200ms >"$TMP/out" 2>"$TMP/err" ||
    fail "rl demo exited $?: $(head -c 400 "$TMP/err")"
[ -s "$DIR/index.html" ] || fail "index.html missing"
[ -s "$DIR/report.json" ] || fail "report.json missing"

algos=$(available_algos)
[ -n "$algos" ] || fail "rl algos listed no renderer"
n=0
for s in ${SCENES//,/ }; do
    for a in $algos; do
        f="$DIR/$s-$a.png"
        [ -s "$f" ] || fail "$f missing"
        [ "$(od -An -tx1 -N8 "$f" | tr -d ' \n')" = "89504e470d0a1a0a" ] || fail "$f is not a PNG"
        grep -q "src=\"$s-$a.png\"" "$DIR/index.html" || fail "index.html does not show $s-$a.png"
        grep -q "\"$s-$a.png\"" "$DIR/report.json" || fail "report.json does not list $s-$a.png"
        n=$((n + 1))
    done
done
# Issue 37: pt and bdpt at equal time on the two Cornell boxes, apart from
# the grid (their own lines, folder, JSON list and table on the page).
eq=0
for v in bitterli shade; do
    for a in pt bdpt; do
        f="$DIR/equal-time/cornell-$v-$a.png"
        [ -s "$f" ] || fail "$f missing"
        grep -q "src=\"equal-time/cornell-$v-$a.png\"" "$DIR/index.html" || fail "index.html does not show $f"
        grep -q "^equal time: cornell:variant=$v $a, [0-9]* spp in " "$TMP/out" || fail "no equal-time line for $v $a"
        eq=$((eq + 1))
    done
done
grep -q "pt and bdpt at equal time" "$DIR/index.html" || fail "index.html lacks the equal-time section"
python3 - "$DIR/report.json" <<'PY' || fail "report.json's equal_time is not as expected"
import json, sys
r = json.load(open(sys.argv[1]))
eq = r["equal_time"]
assert r["equal_time_s"] == 0.2 and len(eq) == 4, eq
for e in eq:
    # Every run reached the budget (CPU time per thread) with at least one sample.
    assert e["spp"] >= 1 and e["cpu_s_per_thread"] >= 0.2 and e["threads"] >= 1, e
    assert all(0 < m < 1 for m in e["means"]), e
PY
# One line per image (plus the closing "report:" line), no other PNGs.
[ "$(grep -c ' ms, ' "$TMP/out")" -eq "$n" ] || fail "expected $n image lines: $(cat "$TMP/out")"
[ "$(ls "$DIR"/*.png | wc -l)" -eq "$n" ] || fail "expected exactly $n PNGs in $DIR"
[ ! -e "$DIR/city-raster.png" ] || fail "--scenes did not restrict the demo"
python3 - "$DIR/report.json" "$n" <<'PY' || fail "report.json is not the expected JSON"
import json, sys
r = json.load(open(sys.argv[1]))
assert len(r["images"]) == int(sys.argv[2]), len(r["images"])
for e in r["images"]:
    assert {"scene", "algorithm", "file", "scene_stats", "render_stats"} <= e.keys(), e.keys()
    assert e["render_stats"]["time_ms"] >= 0
    # One-time preparation apart from the frame.
    assert e["render_stats"]["prep_ms"] >= 0 and e["render_stats"]["frame_ms"] >= 0
    assert e["scene_stats"]["triangles"] > 0
assert r["machine"]["nproc"] >= 1 and r["date"]
assert r["failures"] == []
# Defaults changed on purpose: spheres' glass under whitted shows eq. 3.17's
# transmitted highlight; each listed pair exists and differs.
ch = r["changes"]
assert any(c["scene"] == "spheres" and c["algorithm"] == "whitted" for c in ch), ch
import os
for c in ch:
    assert c["rmse"] > 0 and c["option"] and c["before"], c
    for k in ("file_now", "file_before"):
        assert os.path.getsize(os.path.join(os.path.dirname(sys.argv[1]), c[k])) > 0, c
PY
grep -q "Changed on purpose" "$DIR/index.html" || fail "index.html lacks the changed defaults"
grep -q "processors" "$DIR/index.html" || fail "index.html lacks the machine"
grep -q "prep [0-9.]* ms &middot; frame [0-9.]* ms" "$DIR/index.html" || fail "index.html lacks prep and frame"
grep -q "command: <code>" "$DIR/index.html" || fail "index.html lacks the command line"
# The page fits a screen (the old one-row-per-scene table was ~4,600 px
# wide) and marks every image exact or approximate with its error against
# the reference, as report.json does.
python3 - "$DIR/index.html" "$DIR/report.json" <<'PY' || fail "index.html does not fit a screen or lacks the marks"
import json, re, sys
page = open(sys.argv[1]).read()
r = json.load(open(sys.argv[2]))
for m in re.finditer(r'(?:min-|max-)?width\s*[:=]\s*"?(\d+)(px)?', page):
    assert m.group(0).startswith("max-") or int(m.group(1)) <= 1920, m.group(0)
assert "<table" not in page.split("Changed on purpose")[0], "the images are still a table"
cards = re.findall(r'<figure>(.*?)</figure>', page, re.S)
assert len(cards) == len(r["images"]), (len(cards), len(r["images"]))
for card in cards:
    assert re.search(r'class="mark (exact|approximate)">(exact|approximate)</span> '
                     r'RMSE [0-9.]+ &middot; SSIM -?[0-9.]+', card), card
for e in r["images"]:
    assert e["accuracy"] in ("exact", "approximate") and e["error"]["reference"] == "whitted", e
    assert 0 <= e["error"]["rmse"] <= 1 and -1 <= e["error"]["ssim"] <= 1, e
    # The reference is exact by definition; raster lacks its shadows.
    if e["algorithm"] == "whitted":
        assert e["accuracy"] == "exact" and e["error"]["rmse"] == 0, e
    if e["algorithm"] == "raster":
        assert e["accuracy"] == "approximate" and e["error"]["rmse"] > 0, e
PY

# Issue 34, no lost output: the run's images, report and page commit
# together. A second run at 400x300 under a 20 KB file size limit (rl
# ignores SIGXFSZ, so writes fail with EFBIG) writes raster's image (12 KB)
# and the report (4 KB) but not whitted's (67 KB): it fails and keeps the
# first run whole, with no temporaries, where writing each file on its own
# would have mixed the two runs.
# The equal-time section needs pt, bdpt and cornell, and a sane budget.
run_ok "$RL" demo --out "$TMP/demo-noeq" --size 32x24 --scenes cornell --algos raster,pt --no-compare
[ ! -e "$TMP/demo-noeq/equal-time" ] || fail "equal-time images without bdpt"
expect_error 2 "--equal-time: expected a duration" "$RL" demo --out "$TMP/demo-bad" --equal-time soon
expect_error 2 "--equal-time: expected a duration" "$RL" demo --out "$TMP/demo-bad" --equal-time 2h

KEEP="$TMP/demo-keep"
run_ok "$RL" demo --out "$KEEP" --size 32x24 --scenes cornell --algos raster,whitted --no-compare
cp -r "$KEEP" "$TMP/demo-good"
expect_error 1 "demo: $KEEP/cornell-whitted.png: .*; $KEEP keeps the previous demo" \
    bash -c 'ulimit -f 20; exec "$@"' - "$RL" demo --out "$KEEP" --size 400x300 --scenes cornell \
    --algos raster,whitted --no-compare
diff -r "$KEEP" "$TMP/demo-good" >/dev/null || fail "a failed demo run changed the previous demo"
! ls -A "$KEEP" | grep -q '^\.' || fail "temporary files left: $(ls -A "$KEEP")"
echo "ok"
