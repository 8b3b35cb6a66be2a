#!/usr/bin/env bash
# tests/run_criterion.sh BINARY [ARGS...] -- runs a Criterion test binary, then names and counts
# the tests it skipped (from its TAP report). Skips are allowed only in a clone on its own: where
# ../shared (the project's test data) exists, a skipped test is a failure.
# Exit status: the binary's, or 1 when it skipped tests with ../shared present.
set -u
bin=$1
shift
tap=$(mktemp "${TMPDIR:-/tmp}/sfsim-tap.XXXXXX") || exit 2
trap 'rm -f "$tap"' EXIT
"$bin" "$@" --tap="$tap"
rc=$?
name=$(basename "$bin")
skips=$(grep -E '^ok .* # SKIP' "$tap" | sed -E 's/^ok - ([^ ]+) +# SKIP (.*)$/\1: \2/')
n=0
[ -n "$skips" ] && n=$(printf '%s\n' "$skips" | wc -l)
if [ "$n" -gt 0 ]; then
    echo "$name: $n test(s) skipped:"
    printf '%s\n' "$skips" | sed 's/^/    skipped /'
    if [ -e ../shared/scenes/README.md ]; then
        echo "$name: FAIL: ../shared is present, so nothing may be skipped"
        [ "$rc" -eq 0 ] && rc=1
    fi
else
    echo "$name: 0 tests skipped"
fi
exit "$rc"
