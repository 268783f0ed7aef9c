#!/bin/sh
# install_test.sh - the shipped artefacts and `make install` / `make uninstall`:
#  - the shared library's SONAME and exported, versioned symbols;
#  - install into scratch trees (DESTDIR) for PREFIX=/usr, /usr/local and
#    /opt/carom with LIBDIR=/opt/carom/lib: the versioned library and its links in
#    the multiarch LIBDIR, carom.pc (Requires.private: ccd), the CMake package
#    (a consumer project builds against carom::carom and carom::carom_static),
#    the Lua module on Lua 5.4's cpath for that prefix, carom-run, man page, docs;
#  - the README's first C program builds with pkg-config alone and runs;
#  - uninstall leaves exactly the files that were there before install.
# Run from `make check` after `make all`.
set -eu
cd "$(dirname "$0")/.."
fail() { echo "install_test: FAILED: $*"; exit 1; }
version=$(build/carom-run --version | sed 's/^carom-run //') || fail "carom-run --version"
major=${version%%.*}
so=build/lib/libcarom.so.$version
[ -f "$so" ] || fail "no $so (make all first)"
readelf -d "$so" | grep -q "SONAME.*\[libcarom.so.$major\]" || fail "SONAME is not libcarom.so.$major"
bad=$(nm -D --defined-only "$so" | awk '$3 !~ /^carom_/ && $3 != "CAROM_1" {print $3}')
[ -z "$bad" ] || fail "non-carom symbols exported: $bad"
unversioned=$(nm -D --defined-only --with-symbol-versions "$so" | awk '$3 ~ /^carom_/ && $3 !~ /@@CAROM_1$/ {print $3}')
[ -z "$unversioned" ] || fail "symbols not versioned CAROM_1: $unversioned"
count=$(nm -D --defined-only "$so" | grep -c ' carom_')
echo "install_test: $count carom_* symbols, all @@CAROM_1; SONAME libcarom.so.$major; version $version"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
awk '/^```c$/ {on=1; next} /^```$/ {if (on) exit} on {print}' README.md > "$tmp/first.c"
[ -s "$tmp/first.c" ] || fail "no C example found in README.md"
multiarch=$(cc -print-multiarch 2>/dev/null || true)
ma=${multiarch:+/$multiarch}
lua_cpath=$(lua5.4 -e 'io.write(package.cpath)')

# check_prefix PREFIX LIBDIR LUADIR [make arguments]: install into a scratch
# tree that already holds unrelated files, check everything, uninstall.
check_prefix() {
    prefix=$1 libdir=$2 luadir=$3
    shift 3
    root="$tmp/root$(echo "$prefix" | tr / _)"
    mkdir -p "$root$prefix/bin" "$root$libdir/pkgconfig" "$root$prefix/share/doc/other"
    echo other > "$root$prefix/bin/other-tool"
    echo other > "$root$libdir/pkgconfig/other.pc"
    echo other > "$root$prefix/share/doc/other/README"
    manifest() { (cd "$root" && find . ! -type d | sort); }
    manifest > "$tmp/before"
    make -s install DESTDIR="$root" PREFIX="$prefix" "$@" >/dev/null || fail "make install PREFIX=$prefix $*"
    manifest > "$tmp/after"
    r=$root
    [ -f "$r$libdir/libcarom.so.$version" ] && [ ! -L "$r$libdir/libcarom.so.$version" ] \
        || fail "$prefix: no regular file $libdir/libcarom.so.$version"
    [ "$(readlink "$r$libdir/libcarom.so.$major")" = "libcarom.so.$version" ] || fail "$prefix: libcarom.so.$major link"
    [ "$(readlink "$r$libdir/libcarom.so")" = "libcarom.so.$major" ] || fail "$prefix: libcarom.so link"
    [ -f "$r$libdir/libcarom.a" ] || fail "$prefix: no libcarom.a"
    # statically linked, only carom_* may be global (nothing to clash with a user's own symbols)
    leaked=$(nm -g --defined-only "$r$libdir/libcarom.a" | awk 'NF == 3 && $3 !~ /^carom_/ {print $3}')
    [ -z "$leaked" ] || fail "$prefix: libcarom.a exports non-carom symbols: $(echo $leaked | head -c 300)"
    [ -f "$r$prefix/include/carom/carom.h" ] || fail "$prefix: no include/carom/carom.h"
    pc="$r$libdir/pkgconfig/carom.pc"
    grep -qx 'Requires.private: ccd' "$pc" || fail "$prefix: carom.pc lacks Requires.private: ccd"
    ! grep -q -- '-lccd' "$pc" || fail "$prefix: carom.pc names -lccd itself"
    grep -qx "Version: $version" "$pc" || fail "$prefix: carom.pc version"
    [ -x "$r$prefix/bin/carom-run" ] || fail "$prefix: no bin/carom-run"
    [ "$("$r$prefix/bin/carom-run" --version)" = "carom-run $version" ] || fail "$prefix: installed carom-run --version"
    [ -f "$r$prefix/share/man/man1/carom-run.1" ] || fail "$prefix: no man page"
    for d in README.md lua.md examples/showcase.lua; do
        [ -f "$r$prefix/share/doc/carom/$d" ] || fail "$prefix: no share/doc/carom/$d"
    done

    # the Lua module: where the prefix's cpath entry points, and it loads from there
    [ -f "$r$luadir/carom.so" ] || fail "$prefix: no Lua module in $luadir"
    case "$prefix" in /usr|/usr/local)
        case ";$lua_cpath;" in *";$luadir/?.so;"*) ;; *) fail "$luadir is not on lua5.4's cpath ($lua_cpath)";; esac;;
    esac
    out=$(LD_LIBRARY_PATH="$r$libdir" lua5.4 -e "package.cpath = '$r$luadir/?.so'
        local carom = require 'carom'; io.write(carom.version)") || fail "$prefix: lua5.4 cannot load the module"
    [ "$out" = "$version" ] || fail "$prefix: the module says version '$out'"

    # the README's first program, with pkg-config alone
    flags=$(PKG_CONFIG_SYSROOT_DIR="$r" PKG_CONFIG_PATH="$r$libdir/pkgconfig" pkg-config --cflags --libs carom) \
        || fail "$prefix: pkg-config does not find carom"
    static=$(PKG_CONFIG_SYSROOT_DIR="$r" PKG_CONFIG_PATH="$r$libdir/pkgconfig" pkg-config --static --libs carom)
    case " $static " in *" -lccd "*) ;; *) fail "$prefix: pkg-config --static --libs carom lacks -lccd: $static";; esac
    # shellcheck disable=SC2086
    cc -std=c99 -Wall -Wextra -Werror "$tmp/first.c" -o "$tmp/first" $flags || fail "$prefix: README example does not compile"
    out=$(LD_LIBRARY_PATH="$r$libdir" "$tmp/first") || fail "$prefix: README example failed to run"
    case "$out" in "ball at z = "*) ;; *) fail "$prefix: unexpected output: $out";; esac

    # a CMake consumer: find_package(carom CONFIG), the shared and the static target
    if command -v cmake >/dev/null 2>&1; then
        proj="$tmp/cmake$(echo "$prefix" | tr / _)"
        mkdir -p "$proj"
        cp "$tmp/first.c" "$proj/"
        cat > "$proj/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.13)
project(first C)
find_package(carom $major.0 CONFIG REQUIRED)
add_executable(first first.c)
target_link_libraries(first PRIVATE carom::carom)
add_executable(first_static first.c)
target_link_libraries(first_static PRIVATE carom::carom_static)
EOF
        cmake -S "$proj" -B "$proj/build" -DCMAKE_PREFIX_PATH="$r$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF \
            -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF >"$proj/log" 2>&1 || { cat "$proj/log"; fail "$prefix: cmake configure"; }
        cmake --build "$proj/build" >>"$proj/log" 2>&1 || { cat "$proj/log"; fail "$prefix: cmake build"; }
        out=$(LD_LIBRARY_PATH="$r$libdir" "$proj/build/first") || fail "$prefix: the CMake-built program failed"
        case "$out" in "ball at z = "*) ;; *) fail "$prefix: CMake-built program: $out";; esac
        readelf -d "$proj/build/first" | grep -q "NEEDED.*libcarom.so.$major" || fail "$prefix: not linked to the shared library"
        out=$("$proj/build/first_static") || fail "$prefix: the static CMake-built program failed"
        case "$out" in "ball at z = "*) ;; *) fail "$prefix: static CMake-built program: $out";; esac
        # a newer major version is not offered
        sed -i "s/carom $major.0 CONFIG/carom $((major + 1)) CONFIG/" "$proj/CMakeLists.txt"
        if cmake -S "$proj" -B "$proj/build2" -DCMAKE_PREFIX_PATH="$r$prefix" >/dev/null 2>&1; then
            fail "$prefix: find_package(carom $((major + 1))) accepted version $version"
        fi
        rm -rf "$proj"
    else
        echo "install_test: (no cmake: the CMake consumer is not checked; make deps installs it)"
    fi

    make -s uninstall DESTDIR="$root" PREFIX="$prefix" "$@" >/dev/null || fail "make uninstall PREFIX=$prefix $*"
    manifest > "$tmp/uninstalled"
    if ! cmp -s "$tmp/before" "$tmp/uninstalled"; then
        diff "$tmp/before" "$tmp/uninstalled" || true
        fail "$prefix: uninstall did not restore the tree"
    fi
    for d in include/carom share/doc/carom; do
        [ ! -e "$r$prefix/$d" ] || fail "$prefix: uninstall left $prefix/$d"
    done
    [ ! -e "$r$libdir/cmake/carom" ] || fail "$prefix: uninstall left $libdir/cmake/carom"
    echo "install_test: PREFIX=$prefix${*:+ $*}: $(comm -13 "$tmp/before" "$tmp/after" | wc -l) files installed in $libdir," \
        "$luadir; pkg-config, CMake (shared, static), Lua and the README program work; uninstall removed exactly them"
}

check_prefix /usr "/usr/lib$ma" "$(pkg-config --variable=INSTALL_CMOD lua5.4 2>/dev/null || echo "/usr/lib$ma/lua/5.4")"
check_prefix /usr/local "/usr/local/lib$ma" /usr/local/lib/lua/5.4
check_prefix /opt/carom /opt/carom/lib /opt/carom/lib/lua/5.4 LIBDIR=/opt/carom/lib

# Without DESTDIR into a prefix ld.so does not search: install says what to set.
out=$(make -s install PREFIX="$tmp/plain") || fail "make install PREFIX=$tmp/plain"
case "$out" in *"LD_LIBRARY_PATH=$tmp/plain/lib"*) ;; *) fail "install did not say LD_LIBRARY_PATH is needed: $out";; esac
make -s uninstall PREFIX="$tmp/plain" >/dev/null
left=$(find "$tmp/plain" ! -type d)
[ -z "$left" ] || fail "uninstall left $left"
echo "install_test: passed"
