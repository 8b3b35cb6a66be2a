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

cli_summary "cli plots"
