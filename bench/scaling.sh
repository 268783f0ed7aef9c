#!/bin/sh
# scaling.sh - the pyramid grid (peers/scenes.h pyramidsN: base-10 pyramids of
# 55 unit boxes, mu 0.6, sleeping off) at about 1k, 5k, 20k and 50k bodies:
# ms/step, us per body-step, the first step after adding the bodies (with and
# without a box at the speed clamp) and peak memory per body, carom at each
# preset, and the thread pool's speed-up at the largest size for 1, 2, 4, 8
# and 16 workers (only counts up to the machine's cores). Box3D and Jolt
# beside it where their harnesses are built (peers/README.md): set BOX3D_BENCH
# and JOLT_BENCH to the bench_box3d and bench_jolt binaries.
#
#   ./scaling.sh OUT.csv            (from make bench, via run.sh)
#   SIZES="990 5005" ./scaling.sh   quicker
# Bounded for make bench: 30 untimed steps, then TIMED (60) timed ones (the
# median is printed), 30 at 49,995 bodies; fast and accurate skip 49,995.
# Then the switches' table: 1,024 separated boxes resting on the ground (and
# the same locked to the x-z plane), all on and each switch off side by side
# in one process with a second all-on world (its ratio is the run's noise
# floor), timed in 101 interleaved rounds: median ms/step, CPU ms/step and
# the median of the paired per-round CPU ratio to all on with its 95 %
# interval; a switch reads slower (faster) only when its interval lies above
# (below) 1 and the second all-on world's (OUT minus .csv plus
# _switches.csv; scaling.c's run_switch_table).
set -eu
cd "$(dirname "$0")"
out=${1:-../build/bench/out/pyramids.csv}
SIZES=${SIZES:-990 5005 20020 49995}
TIMED=${TIMED:-60}
bin=../build/bench/scaling
cores=$(nproc 2>/dev/null || echo 1)
largest=$(echo "$SIZES" | tr ' ' '\n' | sort -n | tail -1)
timed_for() { if [ "$1" -ge 40000 ]; then echo 30; else echo "$TIMED"; fi; }

$bin pyramids header > "$out"
row() { $bin pyramids "$@" | tee -a "$out"; }
for n in $SIZES; do
    row "$n" 1 default "$(timed_for "$n")"
    if [ "$n" -lt 40000 ]; then
        row "$n" 1 fast "$(timed_for "$n")"
        row "$n" 1 accurate "$(timed_for "$n")"
    fi
done
for k in 2 4 8 16; do
    [ "$k" -le "$cores" ] || break
    row "$largest" "$k" default "$(timed_for "$largest")"
done

# the peers: their result line's ms_per_step, and GNU time's peak RSS (KB)
peer() { # engine-name binary size
    [ -n "$2" ] && [ -x "$2" ] || return 0
    tmp=$(mktemp)
    # a peer that fails (Jolt's harness runs out of temp memory at 49,995) is said, not dropped
    /usr/bin/time -f 'peak_kb=%M' "$2" "pyramids$3" > "$tmp" 2>&1 || {
        echo "scaling: $1 at $3 bodies printed no result: $(grep -v -e '^peak_kb=' -e '^Command exited' "$tmp" | tail -n 1)"
        rm -f "$tmp"; return 0; }
    awk -v e="$1" -v n="$3" '
        /ms_per_step=/ { for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] } }
        /^peak_kb=/ { split($0, kv, "="); kb = kv[2] }
        END { if (v["ms_per_step"] != "") printf "%s,default,1,%d,%.4f,%.3f,,,%d,%.3f,\n", e, v["bodies"],
              v["ms_per_step"], 1e3 * v["ms_per_step"] / v["bodies"], kb, kb / v["bodies"] }' "$tmp" | tee -a "$out"
    rm -f "$tmp"
}
for n in $SIZES; do
    peer box3d "${BOX3D_BENCH:-}" "$n"
    peer jolt "${JOLT_BENCH:-}" "$n"
done
[ -n "${BOX3D_BENCH:-}${JOLT_BENCH:-}" ] || echo "scaling: BOX3D_BENCH / JOLT_BENCH not set: no peers in $out (peers/README.md)"

# summary: growth of the cost per body-step, memory, first step, speed-up
awk -F, 'NR > 1 && $1 == "carom" && $2 == "default" && $3 == 1 { n[++k] = $4; us[k] = $6; kb[k] = $10;
                                                               first[k] = $7; clamp[k] = $8; ms[k] = $5 }
         NR > 1 && $1 == "carom" && $2 == "default" && $3 > 1 { sp[$3] = $5 }
    END {
        if (k < 2) exit
        printf "scaling: carom default, us per body-step %.2f at %d bodies -> %.2f at %d: x%.2f (slope %.3f)\n",
               us[1], n[1], us[k], n[k], us[k] / us[1], 1 + log(us[k] / us[1]) / log(n[k] / n[1])
        for (i = 1; i <= k; i++)
            printf "scaling: %d bodies: %.3f ms/step, first step %.3f ms (x%.2f), with a body at the clamp %.3f ms (x%.2f), peak %.2f KB/body\n",
                   n[i], ms[i], first[i], first[i] / ms[i], clamp[i], clamp[i] / ms[i], kb[i]
        for (w in sp) printf "scaling: %d workers at %d bodies: x%.2f of one worker'"'"'s time\n", w, n[k], sp[w] / ms[k]
    }' "$out"

sw=${out%.csv}_switches.csv
echo "switch,planar,ms_step,cpu_ms_step,cpu_vs_on,cpu_vs_on_lo,cpu_vs_on_hi" > "$sw"
for planar in 0 1; do $bin switch-table "$planar" >> "$sw"; done
awk -F, 'NR > 1 { n++; name[n] = $1; pl[n] = $2; ms[n] = $3; cpu[n] = $4; r[n] = $5; lo[n] = $6; hi[n] = $7
                  if ($1 == "none") on[$2] = $3
                  if ($1 == "again") { aa_lo[$2] = $6; aa[$2] = $7 } }
         END {
             for (i = 1; i <= n; i++) {
                 s = name[i]; p = pl[i]
                 # slower: the whole interval above 1 and above that of the second all-on world (the noise floor)
                 bad = s != "none" && s != "again" && lo[i] > 1 && lo[i] > aa[p]
                 verdict = s == "none" ? "" : s == "again" ? "  (noise floor: the same work)" : bad ? "  SLOWER" : hi[i] < 1 && hi[i] < aa_lo[p] ? "  faster" : "  the same within the noise"
                 if (bad) slower = slower " " s (p ? " (planar)" : "")
                 printf "switches: %-16s %s  %8.3f ms/step (x%.3f of all on)  cpu %8.3f ms, x%.4f of all on (95 %%: %.4f-%.4f)%s\n",
                        s == "none" ? "all on" : s == "again" ? "all on again" : s == "rotation" ? "rotation locked" : s " off",
                        p ? "planar" : "3D    ", ms[i], ms[i] / on[p], cpu[i], r[i], lo[i], hi[i], verdict
             }
             print slower == "" ? "switches: no switch off is slower than all on" : "switches: slower than all on:" slower
         }' "$sw"
