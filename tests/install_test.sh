#!/bin/sh
# Checks the shipped artefacts: exported symbols and SONAME of the shared
# library, and that `make install` gives a tree from which the README's C
# example builds with `pkg-config --cflags --libs carom` alone, and runs.
set -eu
cd "$(dirname "$0")/.."
fail() { echo "install_test: FAILED: $*"; exit 1; }
so=lib/libcarom.so.1

readelf -d "$so" | grep -q 'SONAME.*\[libcarom.so.1\]' || fail "SONAME is not libcarom.so.1"
bad=$(nm -D --defined-only "$so" | awk '$3 !~ /^carom_/ && $3 != "CAROM_1" {print $3}')
[ -z "$bad" ] || fail "non-carom symbols exported: $bad"
unversioned=$(nm -D --defined-only --with-symbol-versions "$so" | awk '$3 ~ /^carom_/ && $3 !~ /@@CAROM_1$/ {print $3}')
[ -z "$unversioned" ] || fail "symbols not versioned CAROM_1: $unversioned"
count=$(nm -D --defined-only "$so" | grep -c ' carom_')
echo "install_test: $count carom_* symbols, all @@CAROM_1; SONAME libcarom.so.1"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
make -s install DESTDIR="$tmp/root" PREFIX=/usr >/dev/null
awk '/^```c$/ {on=1; next} /^```$/ {if (on) exit} on {print}' README.md > "$tmp/first.c"
[ -s "$tmp/first.c" ] || fail "no C example found in README.md"
export PKG_CONFIG_SYSROOT_DIR="$tmp/root" PKG_CONFIG_PATH="$tmp/root/usr/lib/pkgconfig"
flags=$(pkg-config --cflags --libs carom) || fail "pkg-config does not find carom"
# shellcheck disable=SC2086
cc -std=c99 -Wall -Wextra -Werror "$tmp/first.c" -o "$tmp/first" $flags || fail "README example does not compile"
out=$(LD_LIBRARY_PATH="$tmp/root/usr/lib" "$tmp/first") || fail "README example failed to run"
echo "install_test: README example prints: $out"
case "$out" in "ball at z = "*) ;; *) fail "unexpected output";; esac
echo "install_test: passed"
