#!/usr/bin/env bash
# tests/cli/cases/plots.sh -- a sweep's plots read as users expect: side-by-side panels of stacked
# bars share one y range (each autoscaled on its own, equal heights meant different values), and
# the legend lists the series in the order they stack (the top of the stack first).
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-plots.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

printf '[sweep]\ncore.simd_width = 8, 16\nrender.spp = 1, 2\n' > "$T/s.ini"
run "$SFSIM" sweep --sweep "$T/s.ini" -o "$T/sw" -j 2 --set render.width=32 --set render.height=32
sweep_rc=$rc

begin "stacked bars in panels share one y range, the tallest stack's and a margin"
[ "$sweep_rc" -eq 0 ] || no "the sweep failed (exit $sweep_rc)"
gp="$T/sw/plots/stalls_core.simd_width.gp"
[ -s "$gp" ] || no "no $gp"
grep -q "multiplot layout" "$gp" || no "the stall plot has one panel: the case tests nothing"
grep -qE '^set yrange \[0:[0-9.e+-]+\]$' "$gp" || no "no explicit y range: $(grep yrange "$gp")"
[ "$(grep -c '^set yrange' "$gp")" -eq 1 ] || no "more than one y range"
top=$(grep -oE '^set yrange \[0:[0-9.e+-]+' "$gp" | sed 's/.*://')
# the tallest stack of the data (columns 2.. of every row of every panel)
tallest=$(awk '!/^#/ && NF > 1 { s = 0; for (i = 2; i <= NF; i++) if ($i != "NaN") s += $i; if (s > m) m = s } END { print m + 0 }' \
    "$T/sw/plots/stalls_core.simd_width.dat")
awk -v t="$top" -v m="$tallest" 'BEGIN { exit !(t >= m && t <= 1.1 * m && m > 0) }' ||
    no "y range top $top for a tallest stack of $tallest"
end

begin "the legend of stacked bars lists the series top of the stack first (key invert)"
for f in "$T"/sw/plots/stalls_*.gp "$T"/sw/plots/ops_*.gp; do
    grep -q '^set key .*invert' "$f" || no "$(basename "$f"): the key is not inverted"
done
end

begin "energy by level is stacked against a swept key; the Pareto fronts are the points no other beats"
[ -s "$T/sw/plots/energy_core.simd_width.png" ] || no "no energy plot"
for f in pareto_fps_area pareto_fps_power; do
    d="$T/sw/plots/$f.dat"
    [ -s "$d" ] && [ -s "$T/sw/plots/$f.png" ] || { no "no $f plot"; continue; }
    # block 0: every point (x fps label); block 1: the front (x fps). The front rises in x and fps;
    # each point has a front point at no more x with no less fps; each front point is a point.
    awk 'BEGIN { b = 0 } /^$/ { if (seen) b = 1; next } /^#/ { next }
         { seen = 1; if (b == 0) { n++; x[n] = $1; y[n] = $2 } else { m++; fx[m] = $1; fy[m] = $2 } }
         END {
             if (m < 1 || n < 2) { print "empty: " n " points, " m " on the front"; exit 1 }
             for (i = 2; i <= m; i++) if (!(fx[i] > fx[i-1] && fy[i] > fy[i-1])) { print "front not rising at " i; exit 1 }
             for (i = 1; i <= n; i++) { ok = 0; for (j = 1; j <= m; j++) if (fx[j] <= x[i] && fy[j] >= y[i]) ok = 1
                                       if (!ok) { print "point " x[i] " " y[i] " beats the front"; exit 1 } }
             for (j = 1; j <= m; j++) { ok = 0; for (i = 1; i <= n; i++) if (x[i] == fx[j] && y[i] == fy[j]) ok = 1
                                       if (!ok) { print "front point " fx[j] " is no point"; exit 1 } }
         }' "$d" > "$T/why" || no "$f: $(cat "$T/why")"
done
end

cli_summary "cli plots"
