#!/usr/bin/env bash
# tests/standalone_clone.sh -- a user's clone on its own: clones the committed HEAD into a fresh
# temporary folder with no ../shared beside it, then runs the README's two commands there:
# `make run` (at a small size) and `make test`. Both must succeed; tests that need ../shared must be
# skipped with their reason and counted. `make test-standalone` runs it; CI calls that.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-clone.XXXXXX")
trap 'rm -rf "$T"' EXIT
if [ -n "$(git status --porcelain --untracked-files=no)" ]; then
    echo "standalone clone: note: uncommitted changes are not in the clone (it tests HEAD)"
fi
git clone -q --no-local "$ROOT" "$T/sfsim"
[ ! -e "$T/shared" ] || { echo "standalone clone: $T/shared exists"; exit 1; }
cd "$T/sfsim"
echo "== standalone clone in $T/sfsim (no ../shared): make run"
make --no-print-directory run RUN_SIZE="--set render.width=64 --set render.height=64 --set render.spp=2" >"$T/run.log" 2>&1 ||
    { tail -30 "$T/run.log"; echo "standalone clone: make run failed"; exit 1; }
grep -E '^== headline' "$T/run.log" || { echo "standalone clone: make run printed no headline"; exit 1; }
[ -s out/frame.png ] || { echo "standalone clone: make run wrote no out/frame.png"; exit 1; }
echo "== standalone clone: make test"
if ! make --no-print-directory test >"$T/test.log" 2>&1; then
    grep -E 'FAIL|Synthesis|passed, [0-9]+ failed' "$T/test.log" | head -40
    echo "standalone clone: make test failed"
    exit 1
fi
grep -E 'Synthesis|passed, [0-9]+ failed|test\(s\) skipped|tests skipped' "$T/test.log"
nskip=$(grep -cE '^    skipped .*needs \.\./shared \(absent\)' "$T/test.log" || true)
nother=$(grep -E '^    skipped ' "$T/test.log" | grep -cv 'needs \.\./shared (absent)' || true)
echo "standalone clone: make run and make test passed; $nskip tests skipped for want of ../shared"
[ "$nskip" -gt 0 ] || { echo "standalone clone: expected the ../shared tests to be skipped and named"; exit 1; }
[ "$nother" -eq 0 ] || { echo "standalone clone: $nother tests skipped for another reason"; exit 1; }
