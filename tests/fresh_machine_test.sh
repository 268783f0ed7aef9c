#!/bin/sh
# fresh_machine_test.sh - the README's first command, `make demo`, works the
# first time on a fresh Debian machine, where pkg-config and the libraries'
# .pc files appear only once `make deps` has installed them.
#
# Simulated without touching this machine's packages: a clean copy of the
# tree, a PATH holding the system's programs minus pkg-config, a stand-in
# `id` (root) and a stand-in `apt-get` whose `install` puts the real
# pkg-config on that PATH and the .pc files into the only directory
# pkg-config searches (PKG_CONFIG_LIBDIR). Three machines:
#   1. no pkg-config, no .pc files (the Makefile must not ask pkg-config
#      before deps ran: lua.h would not be found);
#   2. pkg-config, but no .pc files (ccd's and Lua's flags appear only later);
#   3. not root: make demo stops at once with the apt-get command to run.
# Run from `make check`; builds at -O0 to keep it quick.
set -eu
cd "$(dirname "$0")/.."
src=$(pwd)
fail() { echo "fresh_machine_test: FAILED: $*"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
real_pkg_config=$(command -v pkg-config) || fail "this machine needs pkg-config to run the test"
pc_files=""
for p in ccd lua5.4 cmocka; do
    dir=$(pkg-config --variable=pcfiledir "$p") || fail "no $p.pc on this machine"
    pc_files="$pc_files $dir/$p.pc"
done

# the programs of a Debian machine, without pkg-config, apt-get and id
mkdir -p "$tmp/system-bin"
for d in /usr/local/sbin /usr/local/bin /usr/sbin /usr/bin /sbin /bin; do
    [ -d "$d" ] || continue
    for f in "$d"/*; do
        name=${f##*/}
        case "$name" in pkg-config|pkgconf|*-pkg-config|*-pkgconf|apt-get|apt|id) continue;; esac
        [ -x "$f" ] && [ ! -e "$tmp/system-bin/$name" ] && ln -s "$f" "$tmp/system-bin/$name"
    done
done
real_id=$(command -v id)

# machine NAME UID PKG_CONFIG_AT_START: a fresh bin/ and pc/ directory
machine() {
    m="$tmp/$1"
    mkdir -p "$m/bin" "$m/pc"
    cat > "$m/bin/id" <<EOF
#!/bin/sh
if [ "\${1:-}" = -u ]; then echo $2; else exec $real_id "\$@"; fi
EOF
    cat > "$m/bin/apt-get" <<EOF
#!/bin/sh
echo "apt-get \$*" >> "$m/apt.log"
case " \$* " in
*" install "*)
    for p in pkg-config libccd-dev liblua5.4-dev libcmocka-dev; do
        case " \$* " in *" \$p "*) ;; *) echo "stand-in apt-get: \$p not asked for" >&2; exit 100;; esac
    done
    ln -sf "$real_pkg_config" "$m/bin/pkg-config"
    for f in $pc_files; do cp "\$f" "$m/pc/"; done;;
esac
exit 0
EOF
    chmod +x "$m/bin/id" "$m/bin/apt-get"
    [ "$3" = no ] || ln -s "$real_pkg_config" "$m/bin/pkg-config"
    mkdir -p "$m/src"
    # a clean copy: the files git knows (tracked and new), no build outputs
    if git rev-parse --git-dir >/dev/null 2>&1; then
        git ls-files -z --cached --others --exclude-standard | tar --null -T - --ignore-failed-read -cf - 2>/dev/null \
            | tar -xf - -C "$m/src"
    else
        tar --exclude=./build --exclude=./bench/out --exclude=./bench/peers/build -cf - . | tar -xf - -C "$m/src"
    fi
    [ ! -e "$m/src/build" ] || fail "the copy has a build/ folder"
}

# run_demo NAME: make demo on that machine; output in $m/out
run_demo() {
    m="$tmp/$1"
    (cd "$m/src" && env -u MAKEFLAGS -u MAKELEVEL -u MFLAGS PATH="$m/bin:$tmp/system-bin" \
        PKG_CONFIG_LIBDIR="$m/pc" PKG_CONFIG_PATH= make demo OPT=-O0 > "$m/out" 2>&1)
}

for case in "no-pkg-config no" "pkg-config-without-pc yes"; do
    set -- $case
    machine "$1" 0 "$2"
    # the machine really is fresh: neither lua.h's flags nor ccd.pc can be found
    if PATH="$tmp/$1/bin:$tmp/system-bin" PKG_CONFIG_LIBDIR="$tmp/$1/pc" sh -c 'pkg-config --exists ccd' 2>/dev/null; then
        fail "$1: ccd.pc is visible before deps"
    fi
    (cd "$tmp/$1/src" && find . | sort) > "$tmp/$1/files.copy"
    run_demo "$1" || { tail -20 "$tmp/$1/out"; fail "$1: make demo failed the first time"; }
    # every output under build/, and make clean takes away all it made
    (cd "$tmp/$1/src" && find . -path ./build -prune -o -print | sort) > "$tmp/$1/files.built"
    diff "$tmp/$1/files.copy" "$tmp/$1/files.built" || fail "$1: make demo wrote outside build/"
    (cd "$tmp/$1/src" && env -u MAKEFLAGS -u MAKELEVEL -u MFLAGS PATH="$tmp/$1/bin:$tmp/system-bin" make -s clean) \
        || fail "$1: make clean failed"
    (cd "$tmp/$1/src" && find . | sort) > "$tmp/$1/files.cleaned"
    diff "$tmp/$1/files.copy" "$tmp/$1/files.cleaned" || fail "$1: make clean left files behind"
    grep -q "apt-get install" "$tmp/$1/apt.log" || fail "$1: deps did not call apt-get install"
    grep -q "showcase: every check above holds" "$tmp/$1/out" || { tail -20 "$tmp/$1/out"; fail "$1: the showcase did not run"; }
    echo "fresh_machine_test: $1: make demo installed the packages, built and ran the showcase the first time;" \
         "it wrote only under build/, and make clean removed all of it"
done

machine not-root 1000 no
if run_demo not-root; then fail "not-root: make demo succeeded without the packages"; fi
[ ! -e "$tmp/not-root/apt.log" ] || fail "not-root: apt-get was called"
grep -q "apt-get update && apt-get install -y pkg-config" "$tmp/not-root/out" \
    || { cat "$tmp/not-root/out"; fail "not-root: no apt-get command printed"; }
[ ! -e "$tmp/not-root/src/build" ] || fail "not-root: something was built before deps stopped"
echo "fresh_machine_test: not-root: make demo stops at once and prints the apt-get command"
echo "fresh_machine_test: passed"
