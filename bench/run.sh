#!/bin/sh
# make bench: carom beside ODE and Bullet on the canonical scenes (same run,
# interleaved), then the broadphase scaling benchmark. Results go to bench/out/.
# --quick (make bench-quick): only the canonical scenes, one round.
set -eu
cd "$(dirname "$0")"
mkdir -p out
quick=0
[ "${1:-}" != --quick ] || { quick=1; RUNS=1; }
RUNS=${RUNS:-3}
if ! pkg-config --exists ode bullet 2>/dev/null; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "bench: installing the peers (libode-dev libbullet-dev)" >&2
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libode-dev libbullet-dev g++ >/dev/null
    else
        echo "bench: ODE/Bullet not installed (apt-get install libode-dev libbullet-dev); peers skipped" >&2
    fi
fi
echo "== canonical scenes: carom vs ODE vs Bullet (RUNS=$RUNS, median ms/step)"
if pkg-config --exists ode bullet 2>/dev/null; then
    make -s -C peers all
else
    mkdir -p peers/build && cp ../build/bench/bench_carom peers/build/
fi
if [ "$quick" = 1 ]; then
    RUNS=1 ./peers/run.sh | tee out/peers_quick.txt
    echo "bench-quick: bench/out/peers_quick.txt (one round; make bench for 3 rounds and the rest)"
    exit 0
fi
RUNS=$RUNS ./peers/run.sh | tee out/peers.txt
cp peers/build/raw.txt out/peers_raw.txt
echo
echo "== broadphase pair finding"
../build/bench/bench_broadphase | tee out/broadphase.txt
echo
echo "== speed/accuracy sweep (every scene, every knob; CSV and Pareto plots)"
../build/bench/sweep --runs 3 > out/sweep.csv
lua5.4 plot.lua out/sweep.csv out | tee out/pareto.txt
echo
echo "== scaling: pile of 100 to 50,000 bodies"
../build/bench/scaling | tee out/scaling.csv
lua5.4 plot_scaling.lua out/scaling.csv out/scaling.svg
echo
echo "bench: results in bench/out/ (peers.txt, broadphase.txt, sweep.csv, pareto_*.svg, scaling.svg)"
echo
echo "== narrowphase cost per pair type"
../build/bench/bench_narrowphase | tee out/narrowphase.txt
echo
echo "== the envelope at each preset (mass ratio, speed, size, distance, time step, 1e6-step soak)"
../build/bench/extremes 1000000 | tee out/extremes.txt
echo "== snapshots: a settled pile of 10,000 bodies"
../build/bench/snapshot | tee out/snapshot.txt
