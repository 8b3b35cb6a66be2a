#!/usr/bin/env bash
# tests/cli/cases/outputs.sh -- every output written whole, by every tool (host/outfile.h): a
# file-size limit (ulimit -f) or a full disk (SFSIM_FAIL_WRITE, the fault hook) ends sfasm, sfsim
# run, sfsim trace and sfsim sweep with exit 4 naming the file, leaves no partial or temporary file,
# and keeps what was there before.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFASM=${SFASM:-bin/sfasm}
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-outputs.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

KFLAGS=(-I kernels/lib -I kernels -D RAYS=4096 -D SPAD_BYTES=65536)
TINY=(--set render.width=16 --set render.height=16 --set render.spp=1 --no-progress)

# no_temporaries DIR: no temporary file of host/outfile.c or of the plots anywhere under DIR.
no_temporaries() {
    local left
    left=$(find "$1" -name '.*.tmp-*' 2>/dev/null | head -3)
    [ -z "$left" ] || no "temporary files left: $left"
}

# limited BLOCKS CMD...: CMD under a file-size limit of BLOCKS KiB (ulimit -f), as run does.
limited() {
    local blocks=$1
    shift
    cmdline="ulimit -f $blocks; $*"
    (ulimit -f "$blocks" && exec "$@") >"$T/out" 2>"$T/err"
    rc=$?
}

mkdir -p "$T/asm"
"$SFASM" kernels/pathtrace.s "${KFLAGS[@]}" -o "$T/asm/k.sfo" >/dev/null 2>&1 || echo "cli outputs: cannot assemble the kernel"
cp "$T/asm/k.sfo" "$T/asm/k.before"
size=$(stat -c %s "$T/asm/k.before")

begin "sfasm under a file-size limit smaller than its object: exit 4, the file named, the old object kept"
limited 4 "$SFASM" kernels/pathtrace.s "${KFLAGS[@]}" -o "$T/asm/k.sfo"
want_rc 4; want_err "k.sfo: .*File too large"
[ "$size" -gt 4096 ] || no "the object ($size bytes) is not larger than the limit: the case tests nothing"
cmp -s "$T/asm/k.sfo" "$T/asm/k.before" || no "the object that was there was changed"
no_temporaries "$T/asm"
end

begin "sfasm on a full disk, at every write in turn (SFSIM_FAIL_WRITE): exit 4, the old object kept, no temporary"
ops=0
for ((k = 1; k <= 20; k++)); do
    run env SFSIM_FAIL_WRITE=$k "$SFASM" kernels/pathtrace.s "${KFLAGS[@]}" -o "$T/asm/k.sfo"
    [ "$rc" -eq 0 ] && { ops=$((k - 1)); break; }
    [ "$rc" -eq 4 ] || { no "k = $k: exit $rc, expected 4"; break; }
    grep -q "k.sfo: .*No space left on device" "$T/err" || no "k = $k: the file and the reason are not named"
    cmp -s "$T/asm/k.sfo" "$T/asm/k.before" || no "k = $k: the object that was there was changed"
    no_temporaries "$T/asm"
done
[ "$ops" -ge 4 ] || no "only $ops write operations failed in turn (create, write, sync, close, rename expected)"
cmp -s "$T/asm/k.sfo" "$T/asm/k.before" || no "the last, successful run did not write the same object"
end

begin "sfsim run under a file-size limit: exit 4, the file named, no output and no temporary, no 'wrote'"
limited 1 "$SFSIM" run --mode functional -o "$T/run" "${TINY[@]}"
want_rc 4; want_err "File too large"
grep -q wrote "$T/out" && no "'wrote' printed"
[ ! -e "$T/run" ] || no "the run left $T/run: $(ls -A "$T/run" | tr '\n' ' ')"
no_temporaries "$T"
end

begin "sfsim trace under a file-size limit: exit 4, no hit file and no temporary"
for _ in $(seq 200); do cat tests/cli/cornell_rays.txt; done > "$T/rays.txt"
limited 1 "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits.txt" --mode reference
want_rc 4; want_err "hits.txt: .*File too large"
[ ! -e "$T/hits.txt" ] || no "a partial hit file was left"
no_temporaries "$T"
end

printf '[sweep]\ncore.simd_width = 8, 16\n' > "$T/s.ini"
SW=(sweep --sweep "$T/s.ini" -j 2 --mode functional --set render.width=32 --set render.height=32 --set render.spp=1)

begin "sfsim sweep under a limit the points exceed: exit 5, the points failed, no temporary"
# 4 KiB: each point's frame.exr (9 KB), report.json (10 KB) and stats.txt exceed it; sweep.csv (2.2 KB with the
# energy, power and area columns) fits, so the sweep itself only reports its failed points.
limited 4 "$SFSIM" "${SW[@]}" -o "$T/sw1"
want_rc 5; want_err "File too large"
no_temporaries "$T/sw1"
[ -z "$(find "$T/sw1/points" -name 'frame.*')" ] || no "a point kept a partial image"
end

begin "sfsim merge under a limit only the plots exceed: exit 4, no partial PNG, the plots named"
run "$SFSIM" "${SW[@]}" -o "$T/sw2"
want_rc 0
[ "$(find "$T/sw2/plots" -name '*.png' | wc -l)" -ge 2 ] || no "the sweep drew no plots to replace"
limited 12 "$SFSIM" merge "$T/sw2"
want_rc 4; want_err "plots/.*\.png: .*incomplete"
want_err "0 plots"
no_temporaries "$T/sw2"
[ -z "$(find "$T/sw2/plots" -name '*.png')" ] || no "a PNG was left: $(find "$T/sw2/plots" -name '*.png' | head -2)"
[ -s "$T/sw2/sweep.csv" ] || no "the CSV was not written"
end

begin "sfsim merge after the limit is lifted draws the plots whole"
run "$SFSIM" merge "$T/sw2"
want_rc 0
n=$(find "$T/sw2/plots" -name '*.png' | wc -l)
[ "$n" -ge 2 ] || no "$n plots after the merge"
for f in "$T"/sw2/plots/*.png; do
    [ -e "$f" ] && [ "$(tail -c 8 "$f" | head -c 4)" = "IEND" ] || no "$f does not end with IEND"
done
end

begin "sfsim sweep on a real full disk (a small tmpfs): exit 4 or 5, every file left whole, no temporary"
mkdir -p "$T/full"
if mount -t tmpfs -o size=160k tmpfs "$T/full" 2>"$T/err"; then
    run "$SFSIM" "${SW[@]}" -o "$T/full/sw"
    [ "$rc" -eq 4 ] || [ "$rc" -eq 5 ] || no "exit $rc on a full disk, expected 4 or 5"
    no_temporaries "$T/full"
    for f in $(find "$T/full" -name '*.json'); do
        python3 -c 'import json, sys; json.load(open(sys.argv[1]))' "$f" 2>/dev/null || no "$f is not whole JSON"
    done
    for f in $(find "$T/full" -name '*.png'); do
        [ "$(tail -c 8 "$f" | head -c 4)" = "IEND" ] || no "$f is not a whole PNG"
    done
    grep -qE "No space left on device|incomplete PNG" "$T/err" "$T/full/sw"/points/*/log.txt 2>/dev/null ||
        no "no failure named a file the full disk cut short"
    umount "$T/full"
else
    echo "note: cannot mount a tmpfs ($(head -1 "$T/err")): the fault hook covers full disks alone"
fi
end

cli_summary "cli outputs"
