#!/usr/bin/env bash
# test_cli_dist.sh: rl --dist render, eval, compare and bench sampling
# under mpirun (Open MPI, issue 39). Three ranks, oversubscribed on the
# small CI machine, give the same image, depth and IDs as one process, bit
# for bit, for single frames and for a camera path, and the same sampled
# approximation and measured values; Vertex Tracing gives the same image
# for any ranks and drops a stale camera's result; a renderer without regions is refused
# on every rank; without mpirun --dist is a job of one. Skips (saying why)
# where this rl was built without MPI or mpirun is missing.
# Run as: bash test_cli_dist.sh <rl-binary> <scratch-dir>
set -u
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash"

# Not a distributed command: refused before MPI is touched.
expect_usage_error "$RL" --dist bench rays --quick --out "$TMP/br.json"
grep -q "only rl render, eval, compare, bench sampling and bench culling run distributed" "$TMP/err" ||
    fail "--dist bench rays: $(cat "$TMP/err")"

# Open MPI keeps memory past MPI_Finalize in its runtime and components;
# tests/lsan.supp names its libraries, which needs the components kept
# loaded and whole allocation stacks under ASan (its plugins have no frame
# pointers). Only the sanitizer build reads these.
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0"

# One process: --dist is a job of one, the same frame.
if ! "$RL" --dist render cornell --algo whitted --size 32x24 --out "$TMP/one.png" >"$TMP/out" 2>"$TMP/err"; then
    grep -q "no Open MPI" "$TMP/err" || fail "--dist without mpirun failed: $(cat "$TMP/err")"
    echo "test_cli_dist: this rl has no MPI; the distributed cases are skipped"
    exit 0
fi
command -v mpirun >/dev/null || { echo "test_cli_dist: no mpirun; the distributed cases are skipped"; exit 0; }

# Open MPI refuses root without these, and each rank would otherwise spin
# on the two cores; one OpenMP thread per rank keeps three ranks fair.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_mpi_yield_when_idle=1
export OMP_NUM_THREADS=1
MPI=(timeout 120 mpirun --oversubscribe -np 3)
MPI2=(timeout 120 mpirun --oversubscribe -np 2)

run_ok "$RL" render spheres --algo whitted --size 72x53 --out "$TMP/ref.png" --depth-out "$TMP/ref.exr" \
    --id-out "$TMP/ref-id.png"
run_ok "${MPI[@]}" "$RL" --dist render spheres --algo whitted --size 72x53 --out "$TMP/dist.png" \
    --depth-out "$TMP/dist.exr" --id-out "$TMP/dist-id.png"
for f in .png .exr -id.png; do
    cmp -s "$TMP/ref$f" "$TMP/dist$f" || fail "3 ranks differ from one process in ref$f"
done
# One summary line, from the master only, and its per-rank lines.
[ "$(grep -c '^whitted 72x53 spheres: ' "$TMP/out")" -eq 1 ] || fail "expected one summary: $(cat "$TMP/out")"
expect_in "$TMP/out" "^dist: 3 ranks, 4 bands"
expect_in "$TMP/out" "^  rank 2: "

# A camera path: every frame spread, every frame equal.
cat >"$TMP/path.json" <<'JSON'
{ "objects": [ { "generator": "teapot" } ],
  "camera_path": { "keys": [ { "time_s": 0, "eye": [0, 1, 3], "target": [0, 0, 0] },
                             { "time_s": 1, "eye": [2, 1, 2], "target": [0, 0, 0] } ] } }
JSON
run_ok "$RL" render "$TMP/path.json" --algo whitted --camera-path --fps 3 --size 40x30 --out "$TMP/p-ref-%d.png"
run_ok "${MPI[@]}" "$RL" --dist render "$TMP/path.json" --algo whitted --camera-path --fps 3 --size 40x30 \
    --out "$TMP/p-dist-%d.png"
n=0
for f in "$TMP"/p-ref-*.png; do
    cmp -s "$f" "${f/p-ref-/p-dist-}" || fail "camera path frame $f differs"
    n=$((n + 1))
done
[ "$n" -ge 3 ] || fail "the camera path gave $n frames"

# Parallel adaptive sampling (Jähn 2015, Alg. 5.4): the control node's
# approximation is the one-process one, sample for sample, set for set;
# only its wall time ("seconds") is this run's.
run_ok "$RL" eval city:blocks=1 --property visibility --set resolution=16 --samples 40 --seed 7 --out "$TMP/e1"
run_ok "${MPI[@]}" "$RL" --dist eval city:blocks=1 --property visibility --set resolution=16 --samples 40 \
    --seed 7 --out "$TMP/e3"
expect_in "$TMP/out" "^dist: 3 ranks, [0-9]* chunks"
python3 - "$TMP/e1/approx.json" "$TMP/e3/approx.json" <<'PY' || fail "3 sampling ranks differ from one process"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a.pop("seconds") >= 0 and b.pop("seconds") >= 0
assert a["set_size"] > 0 and len(a["samples"]) == 40, (a["set_size"], len(a["samples"]))
assert a == b
PY
[ ! -e "$TMP/e3/report.html" ] || [ "$(grep -c . "$TMP/e3/report.html")" -gt 0 ] || fail "empty report"

# rl compare and rl bench sampling: the positions placed beforehand (every
# renderer's, the validation points) are measured on every rank too. All
# but the times and the run's own record (command, date, load) is the
# one-process result; the time metric and prep_ms measure the machine.
CMP=(compare cornell --algos raster,whitted:max_depth=2 --samples 12 --resolution 8 --size 24x16 --seed 3)
run_ok "$RL" "${CMP[@]}" --out "$TMP/c1"
run_ok "${MPI[@]}" "$RL" --dist "${CMP[@]}" --out "$TMP/c3"
[ "$(grep -c '^compared 2 renderers at 12 positions' "$TMP/out")" -eq 1 ] || fail "compare: $(cat "$TMP/out")"
python3 - "$TMP/c1/compare.json" "$TMP/c3/compare.json" <<'PY' || fail "compare: 3 ranks differ from one process"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert "dist" not in a and b.pop("dist") == {"ranks": 3}
for r in a, b:
    for k in "experiment", "load":
        r.pop(k)
    for e in r["renderers"]:
        assert e.pop("time")["mean"] > 0, e
        for m in e.values():
            if isinstance(m, dict):
                assert m.pop("prep_ms") >= 0 and "error" not in m, m
assert len(a["positions"]) == 12 and a["renderers"][1]["rays"]["mean"] > 0, a
assert a == b
PY
BS=(bench sampling --quick --only variants,convergence)
run_ok "$RL" "${BS[@]}" --out "$TMP/bs1.json"
run_ok "${MPI[@]}" "$RL" --dist "${BS[@]}" --out "$TMP/bs3.json"
python3 - "$TMP/bs1.json" "$TMP/bs3.json" <<'PY' || fail "bench sampling: 3 ranks differ from one process"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert "dist" not in a and b.pop("dist") == {"ranks": 3}
def drop_seconds(o):
    if isinstance(o, dict):
        o.pop("seconds", None)
        for v in o.values():
            drop_seconds(v)
    elif isinstance(o, list):
        for v in o:
            drop_seconds(v)
for r in a, b:
    for k in "command", "date", "machine":
        r.pop(k)
    drop_seconds(r)
assert len(a["variants"]["cases"]) == 8 and len(a["convergence"]["rows"]) == 3, a
assert a == b
PY
# Its throughput section is samples/s of this machine: refused under --dist.
expect_usage_error "$RL" --dist bench sampling --quick --only throughput --out "$TMP/bst.json"
grep -q "^rl: error: --dist: the throughput section measures this machine's samples/s" "$TMP/err" ||
    fail "--dist bench sampling throughput: $(cat "$TMP/err")"
[ ! -e "$TMP/bst.json" ] || fail "a refused bench sampling wrote a record"

# Fault tolerance (docs/distributed.md). With Open MPI's recovery on, the
# job outlives a rank: rank 2 kills itself (SIGKILL, RL_DIST_FAULT) after
# its first band, the master takes it for lost after RL_DIST_TIMEOUT and
# hands its bands to the others, and the image is still the one-process
# image.
# (4 s: long against a band, but a slow worker, e.g. one still loading its
# scene under ASan, may be taken for lost too: harmless, its bands are
# redone, hence "[12]" below.)
RECOVER=(env OMPI_MCA_orte_enable_recovery=1 OMPI_MCA_orte_abort_on_non_zero_status=0 RL_DIST_TIMEOUT=4)
run_ok "${RECOVER[@]}" RL_DIST_FAULT=2:1 "${MPI[@]}" "$RL" --dist render spheres --algo whitted --size 72x53 \
    --out "$TMP/lost.png"
cmp -s "$TMP/ref.png" "$TMP/lost.png" || fail "a lost worker changed the image"
expect_in "$TMP/out" "^dist: [12] workers\? lost"
expect_in "$TMP/err" "rank 2 has not answered for [0-9]* s: taken for lost"
# The same for sampling: rank 2 dies after its first chunk of positions;
# its chunks are measured by the others and the approximation is still the
# one-process one, sample for sample.
# It also keeps a checkpoint; cut short (a job killed while writing), the
# checkpoint lets a new distributed run continue where it ended, with the
# same approximation.
run_ok "${RECOVER[@]}" RL_DIST_FAULT=2:1 "${MPI[@]}" "$RL" --dist eval city:blocks=1 --property visibility \
    --set resolution=16 --samples 40 --seed 7 --out "$TMP/e-lost" --checkpoint "$TMP/e-ck.bin"
expect_in "$TMP/out" "^dist: 1 worker lost"
expect_in "$TMP/err" "rank 2 has not answered for [0-9]* s: taken for lost, its positions go to"
truncate -s $(($(stat -c %s "$TMP/e-ck.bin") / 2)) "$TMP/e-ck.bin"
run_ok "${MPI[@]}" "$RL" --dist eval city:blocks=1 --property visibility --set resolution=16 --samples 40 \
    --seed 7 --out "$TMP/e-resumed" --checkpoint "$TMP/e-ck.bin"
expect_in "$TMP/err" "checkpoint .*e-ck.bin: [0-9]* samples replayed; measuring on from there"
python3 - "$TMP/e1/approx.json" "$TMP/e-lost/approx.json" "$TMP/e-resumed/approx.json" <<'PY' ||
import json, sys
a, b, c = (json.load(open(f)) for f in sys.argv[1:4])
for x in (a, b, c):
    x.pop("seconds")
assert a == b == c
PY
    fail "a lost sampling node or a resumed distributed run changed the approximation"
# rl bench culling through the property service: the workers make each
# property the master samples from its name and options. Everything but the
# times (each rank's own) equals one process's record, also with rank 2
# lost after its first chunk.
run_ok "$RL" bench culling --quick --only svs --out "$TMP/bc1.json"
run_ok "${RECOVER[@]}" RL_DIST_FAULT=2:1 "${MPI[@]}" "$RL" --dist bench culling --quick --only svs \
    --out "$TMP/bc3.json"
expect_in "$TMP/err" "rank 2 has not answered for [0-9]* s: taken for lost, its positions go to"
python3 - "$TMP/bc1.json" "$TMP/bc3.json" <<'PY' || fail "rl --dist bench culling differs from one process"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert b["dist"]["ranks"] == 3 and b["svs"]["status"] == "ok", b.get("dist")
def same(x, y, path):
    if isinstance(x, dict):
        for k in x:
            if "time" not in k and not k.endswith("_ms"):
                same(x[k], y[k], path + "/" + k)
    elif isinstance(x, list):
        assert len(x) == len(y), path
        for u, v in zip(x, y):
            same(u, v, path)
    else:
        assert x == y, (path, x, y)
same(a["svs"], b["svs"], "svs")
assert a["svs"]["positions"] >= 1
PY
# A dead master (it kills itself after its first band): by default mpirun
# ends the job at once; with recovery on, every worker gives up with an
# error after the timeout. Neither hangs (timeout 120 above), neither
# writes an image.
expect_exit 137 env RL_DIST_FAULT=0:1 "${MPI[@]}" "$RL" --dist render spheres --algo whitted --size 72x200 \
    --out "$TMP/dead.png"
[ ! -e "$TMP/dead.png" ] || fail "a dead master wrote an image"
"${RECOVER[@]}" RL_DIST_FAULT=0:1 "${MPI[@]}" "$RL" --dist render spheres --algo whitted --size 72x200 \
    --out "$TMP/dead.png" >"$TMP/out" 2>"$TMP/err"
[ "$(grep -c '^rl: error: render: rank [12]: .*rank 0.* for 4 s: it is gone or stuck' "$TMP/err")" -ge 1 ] ||
    fail "the workers of a dead master: $(grep -v '^ ' "$TMP/err" | head -c 600)"
[ ! -e "$TMP/dead.png" ] || fail "a dead master wrote an image"

# pt (issue 39): every band accumulates all frames of --spp, so the image
# equals one process's for the same seed, colour, depth and IDs; with
# checkerboard a band's first frame fills its holes from the neighbouring
# rows as one process does. Also with a worker lost after its first band,
# while its band's pixels may still be on their way.
PT=(render cornell --algo pt --size 40x37 --spp 3 --set checkerboard=true --set seed=3)
run_ok "$RL" "${PT[@]}" --out "$TMP/pt-ref.png" --depth-out "$TMP/pt-ref.exr" --id-out "$TMP/pt-ref-id.png"
run_ok "${MPI[@]}" "$RL" --dist "${PT[@]}" --out "$TMP/pt-dist.png" --depth-out "$TMP/pt-dist.exr" \
    --id-out "$TMP/pt-dist-id.png"
for f in .png .exr -id.png; do
    cmp -s "$TMP/pt-ref$f" "$TMP/pt-dist$f" || fail "pt: 3 ranks differ from one process in pt-ref$f"
done
expect_in "$TMP/out" "^pt 40x37 cornell: .* 6 frames, 3 spp"
run_ok "${RECOVER[@]}" RL_DIST_FAULT=1:1 "${MPI[@]}" "$RL" --dist "${PT[@]}" --out "$TMP/pt-lost.png"
cmp -s "$TMP/pt-ref.png" "$TMP/pt-lost.png" || fail "pt: a lost worker changed the image"
expect_in "$TMP/out" "^dist: [12] workers\? lost"
# The filters (Sec. 8.2) work on the whole image: the bands leave them out
# and the master filters the assembled image with a G-buffer of its own,
# which gives the one-process image bit for bit.
for f in gauss atrous; do
    run_ok "$RL" "${PT[@]}" --set filter=$f --out "$TMP/pt-ref-$f.png"
    run_ok "${MPI[@]}" "$RL" --dist "${PT[@]}" --set filter=$f --out "$TMP/pt-dist-$f.png"
    cmp -s "$TMP/pt-ref-$f.png" "$TMP/pt-dist-$f.png" || fail "pt filter=$f: 3 ranks differ from one process"
    cmp -s "$TMP/pt-ref.png" "$TMP/pt-ref-$f.png" && fail "pt filter=$f left the image as it was"
done
# What a band cannot do: a time budget (the frames are fixed before the
# bands go out; a usage error on every rank, which mpirun reports as 1).
expect_exit 1 "${MPI[@]}" "$RL" --dist render cornell --algo pt --size 40x37 --time 1s --out "$TMP/pt-t.png"
grep -q "^rl: error: --dist: pt over several ranks renders a fixed number of samples: give --spp N" "$TMP/err" ||
    fail "pt --time under --dist: $(head -c 600 "$TMP/err")"
[ ! -e "$TMP/pt-t.png" ] || fail "a refused pt run wrote an image"

# Vertex Tracing (Ullmann Sec. 4.3): packages of visible faces instead of
# bands. With queue balancing and a fixed package size the packages are
# the same whoever refines them, so 3 ranks, 2 ranks with a stale result
# (RL_DIST_STALE: a worker first answers its package with an empty part
# marked with the previous camera, which the master must drop) and 3 ranks
# with a worker killed after its first package all give the same image,
# within SSIM 0.998 of one process (tests/cli/ssim.py, the whole image; on
# the VT pixels alone, tests/render/test_vt.c's packages_match_one_process).
VT=(render table --algo vt --size 64x48 --set package=100)
run_ok "$RL" "${VT[@]}" --out "$TMP/vt1.png"
run_ok "${MPI[@]}" "$RL" --dist "${VT[@]}" --out "$TMP/vt3.png" --stats-json "$TMP/vt3.json"
expect_in "$TMP/out" "^dist: 3 ranks, 10 packages, "
python3 -c 'import sys; sys.exit(float(sys.argv[1]) <= 0.998)' "$(python3 "$(dirname "${BASH_SOURCE[0]}")/ssim.py" \
    "$TMP/vt1.png" "$TMP/vt3.png")" || fail "vt: 3 ranks too far from one process"

python3 - "$TMP/vt3.json" <<'PY' || fail "vt: the dist record: $(head -c 600 "$TMP/vt3.json")"
import json, sys
d = json.load(open(sys.argv[1]))["dist"]
assert d["task"] == "package" and d["tasks"] == 10 and d["dropped"] == 0, d
assert sum(r["tasks"] for r in d["per_rank"]) == 10 and all("faces" in r for r in d["per_rank"]), d
PY
run_ok env RL_DIST_STALE=1:1 timeout 120 mpirun --oversubscribe -np 2 "$RL" --dist "${VT[@]}" --out "$TMP/vt2.png"
cmp -s "$TMP/vt3.png" "$TMP/vt2.png" || fail "vt: 2 ranks with a stale result differ from 3 ranks"
expect_in "$TMP/out" "^dist: 1 result of an older camera dropped"
# A worker killed after its first package, while the master may pull its
# part (Open MPI's "Read -1"). MPI_Finalize's runtime fence over all ranks,
# the dead one included, did not always return (1 job in 3); in recovery
# mode the ranks end without it (docs/distributed.md). The job must end
# within seconds of the master writing the image: a hang at the end fails
# here, whatever the time the frame took (timeout only stops it).
"${RECOVER[@]}" RL_DIST_FAULT=2:1 timeout 45 mpirun --oversubscribe -np 3 "$RL" --dist "${VT[@]}" \
    --out "$TMP/vt-lost.png" >"$TMP/out" 2>"$TMP/err"
rc=$?
ended=$(date +%s)
[ "$rc" -eq 0 ] || fail "vt: a lost worker: exit $rc: $(grep -v '^\[' "$TMP/err" | head -c 600)"
[ $((ended - $(stat -c %Y "$TMP/vt-lost.png"))) -le 10 ] ||
    fail "vt: a lost worker: the ranks ended $((ended - $(stat -c %Y "$TMP/vt-lost.png"))) s after the image"
cmp -s "$TMP/vt3.png" "$TMP/vt-lost.png" || fail "vt: a lost worker changed the image"
expect_in "$TMP/out" "^dist: [12] workers\? lost"
# precompute: a calibration package per rank, then one per rank sized by
# the measured speeds (a rank may get none of the rest), here by the faces'
# estimated cost b_f (cost=estimate; the cut itself: tests/dist).
run_ok "${MPI[@]}" "$RL" --dist render table --algo vt --size 64x48 --set balance=precompute --set cost=estimate \
    --out "$TMP/vtp.png"
expect_in "$TMP/out" "^dist: 3 ranks, [3-6] packages, "
python3 -c 'import sys; sys.exit(float(sys.argv[1]) <= 0.998)' "$(python3 "$(dirname "${BASH_SOURCE[0]}")/ssim.py" \
    "$TMP/vt1.png" "$TMP/vtp.png")" || fail "vt: precompute too far from one process"
# The master's post-pass (dist_postpass, Ullmann Sec. 6.1.3): the same
# packages, and the master replays one process' refinement over their
# samples, tracing only what no package sampled: the image is the
# one-process image byte for byte, for queue on 3 ranks and precompute on 2.
run_ok "${MPI[@]}" "$RL" --dist "${VT[@]}" --set dist_postpass=on --out "$TMP/vt3pp.png" \
    --stats-json "$TMP/vt3pp.json"
cmp -s "$TMP/vt1.png" "$TMP/vt3pp.png" || fail "vt: dist_postpass: 3 ranks differ from one process"
expect_in "$TMP/out" "^dist: post-pass: [0-9]* samples from the parts, [0-9]* traced on the master"
python3 - "$TMP/vt3pp.json" <<'PY' || fail "vt: dist_postpass: the dist record: $(head -c 600 "$TMP/vt3pp.json")"
import json, sys
d = json.load(open(sys.argv[1]))["dist"]
p = d["postpass"]
assert d["tasks"] == 10 and p["reused"] > 50 * p["traced"] and p["time_ms"] >= 0, d
PY
run_ok "${MPI2[@]}" "$RL" --dist render table --algo vt --size 64x48 --set balance=precompute \
    --set dist_postpass=on --out "$TMP/vtppp.png"
cmp -s "$TMP/vt1.png" "$TMP/vtppp.png" || fail "vt: dist_postpass: precompute on 2 ranks differs from one process"
# The post-pass overlapped with the packages still out (dist_overlap):
# with a slow worker (RL_DIST_DELAY=RANK:MS holds each of its parts back)
# the master starts the replay while that worker's parts are out, takes
# them as they come and traces what is not in yet; the image must stay
# the one-process image whichever rank is slow, and with the overlap off
# (the post-pass after the last part).
for slow in 1 2; do
    run_ok env RL_DIST_DELAY=$slow:700 "${MPI[@]}" "$RL" --dist "${VT[@]}" --set dist_postpass=on \
        --set dist_overlap=1 --out "$TMP/vtov$slow.png" --stats-json "$TMP/vtov$slow.json"
    cmp -s "$TMP/vt1.png" "$TMP/vtov$slow.png" || fail "vt: dist_overlap: rank $slow slow changed the image"
    expect_in "$TMP/out" "^dist: post-pass: .*; overlapped, the image [0-9.]* ms after the last part"
    python3 - "$TMP/vtov$slow.json" <<'PY' || fail "vt: dist_overlap: the dist record: $(head -c 600 "$TMP/vtov$slow.json")"
import json, sys
p = json.load(open(sys.argv[1]))["dist"]["postpass"]
assert p["overlapped"] and p["early_ms"] > 0 and p["tail_ms"] >= 0 and p["traced"] > 0, p
PY
done
# A worker killed after its first package while rank 1 is slow: the
# replay starts with both their packages out, traces what never comes,
# and the master collects the rest once the lost worker's timeout ends.
"${RECOVER[@]}" RL_DIST_FAULT=2:1 RL_DIST_DELAY=1:500 timeout 60 mpirun --oversubscribe -np 3 "$RL" --dist "${VT[@]}" \
    --set dist_postpass=on --set dist_overlap=1 --out "$TMP/vtov-lost.png" >"$TMP/out" 2>"$TMP/err"
rc=$?
[ "$rc" -eq 0 ] || fail "vt: dist_overlap with a lost worker: exit $rc: $(grep -v '^\[' "$TMP/err" | head -c 600)"
cmp -s "$TMP/vt1.png" "$TMP/vtov-lost.png" || fail "vt: dist_overlap: a lost worker changed the image"
expect_in "$TMP/out" "^dist: 1 worker lost"
expect_in "$TMP/out" "^dist: post-pass: .*; overlapped"
run_ok env RL_DIST_DELAY=1:300 "${MPI[@]}" "$RL" --dist "${VT[@]}" --set dist_postpass=on --set dist_overlap=0 \
    --out "$TMP/vtov0.png"
cmp -s "$TMP/vt1.png" "$TMP/vtov0.png" || fail "vt: dist_overlap=0: the image differs from one process"
expect_in "$TMP/out" "^dist: post-pass: .*; not overlapped, the image [0-9.]* ms after the last part"

# reconstruct=gl: the workers refine on the CPU as always and the master
# draws the parts with the GL drawer (Ullmann Sec. 3.5 on the GPU). The
# GL drawing must be used (another triangle count: the GL drawer counts
# every triangle it submits, the rasterizer those its culling keeps) and stay
# within SSIM 0.99 of the software drawing, as in one process
# (tests/gl/test_gl_vt.c). Skipped where this machine has no GL 4.5, and
# in the sanitizer build: with fast_unwind_on_malloc=0 (above) Mesa's
# shader compiles take minutes there; the GL drawing itself runs under the
# sanitizers in tests/gl/test_gl_vt.c.
if [ "$RL_SANITIZED" = 0 ] &&
    "$RL" render table --algo vt --set reconstruct=gl --size 16x12 --out "$TMP/vt-gl-probe.png" >/dev/null 2>&1; then
    run_ok "${MPI2[@]}" "$RL" --dist "${VT[@]}" --set reconstruct=gl --out "$TMP/vt-gl.png" \
        --stats-json "$TMP/vt-gl.json"
    expect_in "$TMP/out" "^dist: 2 ranks, 10 packages, "
    python3 -c 'import sys; sys.exit(float(sys.argv[1]) <= 0.99)' "$(python3 "$(dirname "${BASH_SOURCE[0]}")/ssim.py" \
        "$TMP/vt3.png" "$TMP/vt-gl.png")" || fail "vt: reconstruct=gl too far from the software drawing"
    python3 - "$TMP/vt3.json" "$TMP/vt-gl.json" <<'PY' || fail "vt: reconstruct=gl did not draw with GL"
import json, sys
sw, gl = (json.load(open(f)) for f in sys.argv[1:3])
assert gl["samples"] == sw["samples"] and gl["rays_total"] == sw["rays_total"], (sw, gl)
assert gl["triangles_rasterized"] != sw["triangles_rasterized"], (sw, gl)
PY
else
    echo "test_cli_dist: the reconstruct=gl case is skipped (sanitizer build, or no GL 4.5 context)"
fi
# Without GL the master stops before handing out a package: one error line.
RL_EGL_DEVICE=bogus expect_error 1 "vt: unavailable: reconstruct=gl: .*bogus" \
    "${MPI2[@]}" "$RL" --dist "${VT[@]}" --set reconstruct=gl --out "$TMP/vt-nogl.png"
[ ! -e "$TMP/vt-nogl.png" ] || fail "vt: a distributed run without GL wrote an image"

# rl bench dist starts this rl under mpirun itself: its record has every
# workload at every rank count, with the one-rank run as the reference.
run_ok "$RL" bench dist --quick --only tiles --out "$TMP/bench-dist.json"
python3 - "$TMP/bench-dist.json" <<'PY' || fail "rl bench dist: $(head -c 600 "$TMP/bench-dist.json")"
import json, sys
r = json.load(open(sys.argv[1]))
runs = r["tiles"]["runs"]
assert r["tiles"]["status"] == "ok" and [w["algorithm"] for w in runs] == ["whitted", "pt"], runs
for w in runs:
    one, two = w["ranks"]
    assert one["ranks"] == 1 and two["ranks"] == 2 and one["speedup"] == 1, w
    assert two["messages_per_frame"] > 0 and two["bytes_per_frame"] > 0 and two["imbalance"] >= 1, two
    assert len(two["dist"]["per_rank"]) == 2, two
PY
# Its vt section with --vt-postpass ran by hand (bench/README.md): a run
# here would add 40 s to this test under the sanitizers.
expect_exit 2 "$RL" bench dist --vt-postpass maybe
grep -q "^rl: error: bench dist: --vt-postpass: expected off, on or off,on" "$TMP/err" ||
    fail "bench dist --vt-postpass maybe: $(cat "$TMP/err")"
expect_exit 2 "$RL" bench dist --vt-overlap 2
grep -q "^rl: error: bench dist: --vt-overlap: expected a share from 0 to 1, got '2'" "$TMP/err" ||
    fail "bench dist --vt-overlap 2: $(cat "$TMP/err")"
expect_exit 2 "$RL" bench dist --ranks 0,2
grep -q "^rl: error: bench dist: --ranks: expected" "$TMP/err" || fail "bench dist --ranks 0: $(cat "$TMP/err")"

# A renderer whose pixels depend on each other is refused, on every rank,
# and nothing is written.
expect_exit 1 "${MPI[@]}" "$RL" --dist render cornell --algo raster --size 32x24 --out "$TMP/raster.png"
grep -q "^rl: error: raster renders whole images only and cannot be distributed" "$TMP/err" ||
    fail "raster under --dist: $(head -c 600 "$TMP/err")"
[ ! -e "$TMP/raster.png" ] || fail "a refused distributed run wrote an image"
run_ok "$RL" algos
sed -n '/^whitted: /,/^$/p' "$TMP/out" | grep -q "^  distributable:" || fail "rl algos does not mark whitted"
sed -n '/^pt: /,/^$/p' "$TMP/out" | grep -q "^  distributable:" || fail "rl algos does not mark pt"
sed -n '/^raster: /,/^$/p' "$TMP/out" | grep -q "^  distributable:" && fail "rl algos marks raster distributable"
echo "test_cli_dist: ok"
