#!/usr/bin/env bash
# bench/dist.sh: the `rl bench dist` record of issue 39 on a machine with
# 16 cores or more (one rank per core, one OpenMP thread each): builds
# renderlab with Open MPI (make build; RL_MPI is on where the MPI C
# bindings are found) and runs tiles (whitted and pt on table and cluster)
# and Alg. 5.4 sampling (city) at 1, 2, 4, 8 and 16 ranks, writing
# bench/results/dist-<date>-16core.json, then distributed Vertex Tracing
# (both load balancers on table and cluster) into
# bench/results/dist-vt-<date>-16core.json, and the post-pass of Sec. 6.1.3
# (dist_postpass=on, table, 1, 4 and 16 ranks) into
# bench/results/dist-vt-postpass-<date>-16core.json. The build takes 1-2
# minutes on 16 cores, the benchmarks a few minutes (time limits 420, 150
# and 90 s; one run per point, no repeats, to stay inside them): the whole
# run stays under 12 minutes. Larger images and more samples than the 2-core record,
# so that a band and a chunk stay long against their messages at 16 ranks.
# Where one command may run at most 10 minutes (the lent device machine),
# run it in two parts on the same machine: `bash bench/dist.sh tiles`
# (build + tiles and sampling, under 9 minutes), then `bash bench/dist.sh vt`
# (distributed VT and the post-pass, under 5 minutes with the build kept).
# Needs mpirun (Debian: openmpi-bin libopenmpi-dev); as root the Open MPI
# root variables are set by rl bench dist itself.
# Run from anywhere: bash bench/dist.sh [all|tiles|vt]
set -u
part=${1:-all}
case "$part" in all|tiles|vt) ;; *) echo "dist.sh: unknown part '$part' (all, tiles or vt)"; exit 2 ;; esac
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1
command -v mpirun >/dev/null || { echo "dist.sh: no mpirun (install openmpi-bin libopenmpi-dev)"; exit 1; }
echo "== make build"
timeout 300 make build || { echo "dist.sh: the build failed"; exit 1; }
build/rl --dist render cornell --algo whitted --size 8x8 --out /tmp/rl-dist-check.png -q 2>&1 |
    grep -q "no Open MPI" && { echo "dist.sh: this build has no Open MPI"; exit 1; }
date=$(date -u +%Y%m%d)
nproc
rc=0 rc_vt=0 rc_pp=0
if [ "$part" != vt ]; then
echo "== rl bench dist (at most 420 s)"
timeout --signal=INT --kill-after=10 420 build/rl bench dist --ranks 1,2,4,8,16 --size 1280x960 --spp 4 \
    --samples 128 --eval-scene city:blocks=2 --repeats 1 --only tiles,sampling \
    --out "bench/results/dist-$date-16core.json"
rc=$?
echo "== rl bench dist: exit $rc"
fi
[ "$part" = tiles ] && exit "$rc"
# Distributed Vertex Tracing (Ullmann Fig. 5.14): both load balancers on
# table and cluster. At 480x360 one rank takes 5-10 s a frame (2-core
# figures), so 2 scenes x 2 balancers x 5 rank counts stay inside 150 s.
echo "== rl bench dist --only vt (at most 150 s)"
timeout --signal=INT --kill-after=10 150 build/rl bench dist --ranks 1,2,4,8,16 --vt-size 480x360 \
    --repeats 1 --only vt --vt-postpass off --out "bench/results/dist-vt-$date-16core.json"
rc_vt=$?
echo "== rl bench dist --only vt: exit $rc_vt"
# The master's post-pass (dist_postpass, Ullmann Sec. 6.1.3): its serial
# cost against the ranks, on table (both balancers, 1, 4 and 16 ranks).
echo "== rl bench dist --only vt --vt-postpass on (at most 90 s)"
timeout --signal=INT --kill-after=10 90 build/rl bench dist --ranks 1,4,16 --vt-size 480x360 --scenes table \
    --repeats 1 --only vt --vt-postpass on --out "bench/results/dist-vt-postpass-$date-16core.json"
rc_pp=$?
echo "== rl bench dist --only vt --vt-postpass on: exit $rc_pp"
[ "$rc" -ne 0 ] && exit "$rc"
[ "$rc_vt" -ne 0 ] && exit "$rc_vt"
exit "$rc_pp"
