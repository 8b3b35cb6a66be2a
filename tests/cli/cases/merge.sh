#!/usr/bin/env bash
# tests/cli/cases/merge.sh -- `sfsim merge` and `sfsim sweep` tell the truth about a point whose
# report.json is missing, truncated or holds a figure that is not a number (docs/sweep.md,
# "sweep.csv"): the point is failed in sweep.csv with the reason, named on stderr, and counted in
# the exit status (5, as a failed run); the other points stay ok and the point's files stay. A
# figure the mode does not write (cycles in functional mode, null there) is no failure.
# One tiny functional sweep (3 points of 16 x 16 pixels) and one tiny detailed sweep (2 points),
# copied for each case: a few seconds.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-merge.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

TINY=(--set render.width=16 --set render.height=16 --set render.spp=1 -j 2)
printf '[sweep]\ncore.simd_width = 8, 16, 32\n' >"$T/three.ini"
printf '[sweep]\ncore.simd_width = 8, 16\n' >"$T/two.ini"

# col FILE NAME: the column NAME of every data row (quoted fields, only the error's, become Q).
col() {
    sed -E 's/"([^"]|"")*"/Q/g' "$1" |
        awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == c) k = i; next } { print (k ? $k : "NOCOLUMN") }'
}
statuses() { col "$1/sweep.csv" status | tr '\n' ' '; }
# set_cycles REPORT VALUE: the top-level "cycles" of a report.json (a line of its own) set to VALUE.
set_cycles() { sed -i -E 's/^(\t| +)?"cycles":[^,]*,/\1"cycles": '"$1"',/' "$2"; }

begin "a functional sweep: every point ok, exit 0, though its reports hold \"cycles\": null"
run "$SFSIM" sweep --sweep "$T/three.ini" -o "$T/base" --mode functional "${TINY[@]}"
want_rc 0
[ "$(statuses "$T/base")" = "ok ok ok " ] || no "statuses: $(statuses "$T/base")"
grep -qE '^\s*"cycles":\s*null,' "$T/base/points/001/report.json" || no "a functional report.json has no \"cycles\": null"
run "$SFSIM" merge "$T/base"
want_rc 0
want_out "3 points: 3 done, 0 failed"
end

# case NAME: a copy of the base sweep in $T/NAME
case_dir() { rm -rf "$T/$1" && cp -r "$T/base" "$T/$1"; }

# merged NAME REASON: merge exits 5, point 1 failed with REASON (stderr and its error cell), the
# other points ok, point 1's done marker and log kept.
merged() {
    run "$SFSIM" merge "$T/$1"
    want_rc 5
    want_out "3 points: 2 done, 1 failed"
    want_err "point 1 failed: .*$1/points/001/report\.json: $2"
    [ "$(statuses "$T/$1")" = "ok failed ok " ] || no "statuses: $(statuses "$T/$1")"
    grep -qE "^1,16,failed,\"report\.json: $2[^\"]*\"," "$T/$1/sweep.csv" || no "point 1's row: $(sed -n 3p "$T/$1/sweep.csv" | cut -c1-120)"
    [ -f "$T/$1/points/001/done" ] && [ -f "$T/$1/points/001/log.txt" ] || no "point 1's files were not kept"
}

begin "merge: a point whose report.json was deleted is failed, named, and merge exits 5"
case_dir deleted
rm "$T/deleted/points/001/report.json"
merged deleted "missing"
end

begin "merge: a truncated report.json is failed with the byte where the JSON breaks"
case_dir truncated
size=$(stat -c %s "$T/truncated/points/001/report.json")
truncate -s $((size / 2)) "$T/truncated/points/001/report.json"
merged truncated "not valid JSON at byte [0-9]+ of $((size / 2))"
[ "$(stat -c %s "$T/truncated/points/001/report.json")" -eq $((size / 2)) ] || no "the truncated report.json was changed"
end

begin "merge: \"cycles\": \"abc\" is failed even where the mode writes no cycles; the row keeps its other figures"
case_dir abc
set_cycles '"abc"' "$T/abc/points/001/report.json"
merged abc "key 'cycles' is not a number \(a string\)"
[ -n "$(col "$T/abc/sweep.csv" rays_total | sed -n 2p)" ] || no "point 1's rays_total was dropped"
[ -z "$(col "$T/abc/sweep.csv" cycles | sed -n 2p)" ] || no "point 1's cycles cell is not empty"
end

begin "sfsim sweep, run again on that folder, counts the point as failed too: exit 5"
run "$SFSIM" sweep --sweep "$T/three.ini" -o "$T/abc" --mode functional "${TINY[@]}"
want_rc 5
want_err "point 1 failed: .*report\.json: key 'cycles' is not a number"
want_err "2/3 done, 1 failed"
end

begin "a detailed sweep: \"cycles\": null is a failure there (the mode writes cycles)"
run "$SFSIM" sweep --sweep "$T/two.ini" -o "$T/det" --mode detailed "${TINY[@]}"
want_rc 0
set_cycles null "$T/det/points/000/report.json"
grep -qE '^\s*"cycles":\s*null,' "$T/det/points/000/report.json" || no "the test did not null the cycles"
run "$SFSIM" merge "$T/det"
want_rc 5
want_err "point 0 failed: .*det/points/000/report\.json: key 'cycles' is not a number \(null\)"
[ "$(statuses "$T/det")" = "failed ok " ] || no "statuses: $(statuses "$T/det")"
end

cli_summary "cli merge"
