#!/bin/sh
# determinism.sh - the same scene gives bit for bit the same state whatever
# built it: gcc and clang, -O1 and -O2, each on the AVX2 and the SSE2 path
# (CAROM_NO_AVX2). Floating-point contraction (FMA) would break that, so the
# build must forbid it: this checks the Makefile's flags say -ffp-contract=off
# and builds every variant with them. Part of make check (clang needed).
set -eu
cd "$(dirname "$0")/.."
flags=$(make -s --no-print-directory print-cflags)
case "$flags" in *-ffp-contract=off*) ;; *) echo "determinism: the build's CFLAGS lack -ffp-contract=off: $flags"; exit 1;; esac
command -v clang >/dev/null || { echo "determinism: clang is needed (apt-get install clang)"; exit 1; }
out=build/determinism
mkdir -p $out
common="-std=c99 -Wall -Wextra -Werror -g -ffp-contract=off -DCAROM_BUILDING -Iinclude -Ilib $(pkg-config --cflags ccd 2>/dev/null || true)"
libs="$(pkg-config --libs ccd 2>/dev/null || echo -lccd) -lm -pthread"
for cc in gcc clang; do
  for opt in -O1 -O2; do
    extra=""
    # clang -O1 also runs under UBSan (it alone flags a zero offset on a NULL pointer)
    if [ $cc = clang ] && [ $opt = -O1 ]; then extra="-fsanitize=undefined -fno-sanitize-recover=all"; fi
    exe=$out/scene_$cc$opt
    $cc $common $opt $extra lib/*.c tests/determinism_scene.c -o $exe $libs &
  done
  wait
done
ref=""
for exe in $out/scene_gcc-O1 $out/scene_gcc-O2 $out/scene_clang-O1 $out/scene_clang-O2; do
  for path in avx2 sse2; do
    if [ $path = sse2 ]; then CAROM_NO_AVX2=1 ./$exe $exe.$path.snap; else ./$exe $exe.$path.snap; fi
    if [ -z "$ref" ]; then ref=$exe.$path.snap
    elif ! cmp -s "$ref" $exe.$path.snap; then
      echo "determinism: $exe on $path ends in another state than $ref"; exit 1
    fi
  done
done
echo "determinism: gcc and clang x -O1 and -O2 x AVX2 and SSE2: 8 runs, one state"
