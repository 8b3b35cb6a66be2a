#!/usr/bin/env bash
# tests/cli/cases/docs.sh -- the docs and the help say what the code does: the examples of
# docs/trace.md give the hit file it shows, every relative link of the README and docs/ names a file
# of the repository, and no help text names internal labels (a paper's file number, an issue).
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-docs.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

begin "docs/trace.md: its example rays give, on the shipped Cornell box, the hit file it shows"
rays_block=$(grep -n '^# ox oy oz' docs/trace.md | head -1 | cut -d: -f1)
[ -n "$rays_block" ] || no "docs/trace.md has no example ray file"
awk -v s="$rays_block" 'NR >= s { if (/^```/) exit; print }' docs/trace.md > "$T/rays.txt"
hits_block=$(grep -n '^# sfsim trace: ray  closest' docs/trace.md | head -1 | cut -d: -f1)
awk -v s="$hits_block" 'NR >= s { if (/^```/) exit; print }' docs/trace.md > "$T/want.txt"
for mode in functional reference; do
    run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits-$mode.txt" --mode $mode
    want_rc 0
    diff -u "$T/want.txt" "$T/hits-$mode.txt" > "$T/diff" || no "--mode $mode differs: $(head -12 "$T/diff")"
done
grep -qE '^[0-9]+ [0-9.]+ [0-9]+ ' "$T/want.txt" || no "no example ray hits anything"
end

begin "every relative link of README.md and docs/*.md names a file of the repository"
bad=""
for f in README.md docs/*.md; do
    dir=$(dirname "$f")
    while IFS= read -r link; do
        target=${link%%#*}
        [ -z "$target" ] && continue
        case "$target" in http://* | https://* | mailto:*) continue ;; esac
        [ -e "$dir/$target" ] || bad="$bad $f->$target"
    done < <(grep -oE '\]\([^)]+\)' "$f" | sed -E 's/^\]\(//; s/\)$//')
done
[ -z "$bad" ] || no "links to files that are not there:$bad"
end

begin "no help text or config and statistics description names internal labels"
{
    "$SFSIM" help
    for c in run exec config compare trace sweep merge help exit-codes; do "$SFSIM" help $c; done
    "$SFSIM" config --dump
    bin/sfasm --help
} > "$T/help.txt" 2>&1
grep -nE 'seed 00[0-9]|\b00[014] (Table|Sec)|\(00[014]\)|issue #?[0-9]+|\.\./shared/design' "$T/help.txt" > "$T/labels" &&
    no "internal labels: $(head -3 "$T/labels")"
end

begin "docs/README.md lists no part as in progress that the README's status table calls done"
grep -n "in progress" docs/README.md > "$T/ip" && no "$(cat "$T/ip")"
end

cli_summary "cli docs"
