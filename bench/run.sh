#!/bin/sh
# make bench: carom beside ODE and Bullet on the canonical scenes (same run,
# interleaved), broadphase pair finding, the speed/accuracy sweep with its
# Pareto plots, the scaling pile, narrowphase costs and the envelope at each
# preset. Results go to build/bench/out/; each phase prints the time it started;
# the last copies what the README shows to docs/bench/ and rewrites the
# README's presets table (bench/publish.lua).
# --quick (make bench-quick): only the canonical scenes, one round.
set -eu
cd "$(dirname "$0")"
# every output goes under the top-level build/: results in build/bench/out,
# the peers' harnesses in build/peers (peers/Makefile)
out=../build/bench/out
peers_build=../build/peers
mkdir -p "$out" "$peers_build"
quick=0
[ "${1:-}" != --quick ] || { quick=1; RUNS=1; }
RUNS=${RUNS:-3}
start=$(date +%s)
elapsed() { s=$(($(date +%s) - start)); printf '%d:%02d' $((s / 60)) $((s % 60)); }
phase() { echo; echo "== [$(elapsed)] $*"; }
# logged OUT CMD...: runs CMD, shows its output as it comes and keeps it in
# OUT; a CMD that fails (a crash included) stops the bench, since a plain
# pipe into tee would hide its status and publish an empty or partial file.
logged() {
    log=$1; shift
    { status=0; "$@" || status=$?; echo "$status" > "$log.rc"; } | tee "$log"
    rc=$(cat "$log.rc" 2>/dev/null || echo unknown); rm -f "$log.rc"
    [ "$rc" = 0 ] || { echo "bench: '$*' failed (exit $rc); $log is incomplete" >&2; exit 1; }
}

# the peers and the plotter are Debian packages (installed as root, like make deps)
need=""
pkg-config --exists ode bullet 2>/dev/null || need="libode-dev libbullet-dev g++"
[ "$quick" = 1 ] || command -v gnuplot >/dev/null 2>&1 || need="$need gnuplot-nox"
if [ -n "$need" ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "bench: installing $need" >&2
        # shellcheck disable=SC2086
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $need >/dev/null
    else
        echo "bench: missing $need (apt-get install -y $need): peers or plots are skipped" >&2
    fi
fi

phase "canonical scenes: carom vs ODE vs Bullet (RUNS=$RUNS, median ms/step)"
if pkg-config --exists ode bullet 2>/dev/null; then
    make -s -C peers all
else
    cp ../build/bench/bench_carom "$peers_build"/
fi
# Box3D and Jolt join the same rounds where their harnesses are built
# (peers/README.md); peers/run.sh runs every build/peers/bench_* it finds.
for peer in box3d:${BOX3D_BENCH:-} jolt:${JOLT_BENCH:-}; do
    name=${peer%%:*}; bin=${peer#*:}
    rm -f "$peers_build/bench_$name"
    if [ -n "$bin" ] && [ -x "$bin" ]; then ln -s "$bin" "$peers_build/bench_$name"; fi
done
if [ "$quick" = 1 ]; then
    logged "$out"/peers_quick.txt env RUNS=1 ./peers/run.sh
    echo "bench-quick: build/bench/out/peers_quick.txt in $(elapsed) (one round; make bench for 3 rounds and the rest)"
    exit 0
fi
logged "$out"/peers.txt env RUNS="$RUNS" ./peers/run.sh
cp "$peers_build"/raw.txt "$out"/peers_raw.txt

phase "broadphase pair finding"
logged "$out"/broadphase.txt ../build/bench/bench_broadphase

phase "speed/accuracy sweep (every scene, every knob; CSV and Pareto plots)"
# progress: one line per scene as its first row arrives. The error columns
# are deterministic: one run each; ms/step is the median of RUNS only for the
# pyramid, whose front the README shows (the pile, heavy, is timed once).
{ status=0; ../build/bench/sweep --runs "$RUNS" --timed pyramid || status=$?; echo "$status" > "$out"/sweep.rc; } | tee "$out"/sweep.csv | {
    read -r _header; scene=""; rows=0
    while IFS=, read -r name _rest; do
        rows=$((rows + 1))
        if [ "$name" != "$scene" ]; then scene=$name; echo "sweep: [$(elapsed)] $name" >&2; fi
    done
    echo "sweep: $rows rows" >&2
}
rc=$(cat "$out"/sweep.rc); rm -f "$out"/sweep.rc
[ "$rc" = 0 ] || { echo "bench: the sweep failed (exit $rc); "$out"/sweep.csv is incomplete" >&2; exit 1; }
if command -v gnuplot >/dev/null 2>&1; then
    logged "$out"/pareto.txt lua5.4 plot.lua "$out"/sweep.csv "$out"
else
    echo "bench: no gnuplot: plots skipped (apt-get install gnuplot-nox)"
fi

phase "scaling: pile of 100 to 50,000 bodies"
logged "$out"/scaling.csv ../build/bench/scaling
if command -v gnuplot >/dev/null 2>&1; then lua5.4 plot_scaling.lua "$out"/scaling.csv "$out"/scaling; fi

phase "scaling: pyramid grid, 990 to 49,995 bodies, every preset, threads, first step, memory (beside Box3D/Jolt if BOX3D_BENCH/JOLT_BENCH)"
./scaling.sh "$out"/pyramids.csv
if command -v gnuplot >/dev/null 2>&1; then lua5.4 plot_scaling.lua "$out"/pyramids.csv "$out"/pyramids; fi

phase "narrowphase cost per pair type"
logged "$out"/narrowphase.txt ../build/bench/bench_narrowphase

phase "the envelope at each preset (mass ratio, speed, size, distance, time step, 1e6-step soak)"
logged "$out"/extremes.txt ../build/bench/extremes 1000000

phase "level geometry: 1,000 mixed bodies on a 100,352-triangle mesh and a 316 x 316 height field"
logged "$out"/terrain.txt ../build/bench/terrain

phase "snapshots: a settled pile of 10,000 bodies"
logged "$out"/snapshot.txt ../build/bench/snapshot

phase "publish: docs/bench/ and the README's presets table from this run"
lua5.4 publish.lua "$out" ../docs/bench ../README.md

echo
echo "bench: done in $(elapsed); results in build/bench/out/ (peers.txt, broadphase.txt, sweep.csv, pareto.txt," \
     "pareto_*.png/.svg, scaling.csv, scaling.png/.svg, pyramids.csv, pyramids_ms/_us.png/.svg, narrowphase.txt, extremes.txt, snapshot.txt)"
