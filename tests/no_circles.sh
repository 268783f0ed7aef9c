#!/bin/sh
# no_circles.sh - lib/ has no circle of calls between its object files and
# no circle of includes between its headers (docs/architecture.md, "Who may
# call whom"). Calls: each lib/X.c's object (OBJDIR, default build/obj) is a
# node, an undefined symbol of one that another defines is an edge (calls
# and data references alike, as nm shows them). Includes: each lib/*.h is a
# node, an #include "Y.h" an edge. Prints every circle with its edges (a
# symbol that makes each call edge) and exits 1 if there is one.
# Run by make check-c after the tests.
set -e
dir=${1:-build/obj}
cd "$(dirname "$0")/.."
# awk: reads "from to why" lines, prints the strongly connected components
# (by reachability; lib/ has about 80 files) of more than one node.
scc='
{ if ($1 != $2 && !(($1 " " $2) in why)) { why[$1 " " $2] = $3; adj[$1] = adj[$1] " " $2 }; node[$1]; node[$2] }
END {
  for (x in node) {
    split("", seen); top = 0; st[++top] = x
    while (top > 0) { y = st[top--]; m = split(adj[y], nb, " ")
      for (k = 1; k <= m; k++) if (!(nb[k] in seen)) { seen[nb[k]]; st[++top] = nb[k] } }
    for (z in seen) reach[x " " z]
  }
  bad = 0
  for (x in node) {
    if (x in done) continue
    comp = " "; n = 0
    for (z in node) if ((x " " z) in reach && (z " " x) in reach) { comp = comp z " "; done[z]; n++ }
    if (n > 1) {
      bad = 1; print what " circle:" comp
      for (e in why) { split(e, p, " "); if (index(comp, " " p[1] " ") && index(comp, " " p[2] " ")) print "    " p[1] " -> " p[2] " (" why[e] ")" }
    }
  }
  exit bad
}'
status=0
for c in lib/*.c; do
    f=$(basename "$c" .c)
    [ -f "$dir/$f.o" ] || { echo "no_circles.sh: $dir/$f.o missing (build first)"; exit 2; }
    nm "$dir/$f.o" | awk -v f="$f" '$1 == "U" { print "U", f, $2 } NF == 3 && $2 ~ /^[TDBRCVWG]$/ { print "D", f, $3 }'
done | awk '$1 == "D" { def[$3] = $2; next } { u[++n] = $2 " " $3 }
            END { for (i = 1; i <= n; i++) { split(u[i], a, " "); if (a[2] in def) print a[1], def[a[2]], a[2] } }' |
    awk -v what=call "$scc" || status=1
for h in lib/*.h; do
    sed -n 's/^#include "\([a-z_0-9]*\)\.h".*/\1/p' "$h" | while read -r to; do echo "$(basename "$h" .h).h $to.h include"; done
done | awk -v what=include "$scc" || status=1
[ $status = 0 ] && echo "no_circles.sh: no circle of calls among lib/*.o, no circle of includes among lib/*.h"
exit $status
