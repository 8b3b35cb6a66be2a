#!/usr/bin/env bash
# tests/cli/cases/inputs.sh -- every input is checked for what it is before it is read
# (host/infile.h): a folder, a device or a FIFO given to any command that reads a file ends at once
# with exit 1 and the reason, naming the file; a ray file with a UTF-8 byte-order mark is read.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFASM=${SFASM:-bin/sfasm}
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-inputs.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

SCENE=scenes/cornell/scene.ini
mkfifo "$T/fifo" || exit 2
mkdir -p "$T/dir"
"$SFASM" tests/cli/ok.s -o "$T/ok.sfo" >/dev/null 2>&1 || echo "cli inputs: cannot assemble tests/cli/ok.s"
"$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/img" --set render.width=8 --set render.height=8 \
    --set render.spp=1 --no-progress >/dev/null 2>&1 || echo "cli inputs: cannot render an image to compare"

# Each command with BAD where it takes a file. A hang would be caught by timeout (exit 124).
commands() {
    local bad=$1
    printf '%s\n' \
        "$SFSIM exec $bad" \
        "$SFASM -d $bad" \
        "$SFASM $bad -o $T/x.sfo" \
        "$SFSIM trace -s $SCENE --rays $bad -o $T/hits.txt" \
        "$SFSIM compare $bad $bad" \
        "$SFSIM compare $T/img/frame.exr $bad" \
        "$SFSIM run -s $SCENE -c $bad -o $T/o" \
        "$SFSIM run --kernel $bad -o $T/o" \
        "$SFSIM config --dump -c $bad" \
        "$SFSIM exec $T/ok.sfo -c $bad" \
        "$SFSIM sweep --sweep $bad -s $SCENE -o $T/sw"
}

check_all() {
    local bad=$1 why=$2 cmd
    while IFS= read -r cmd; do
        begin "$cmd: refused at once ($why)"
        # shellcheck disable=SC2086
        run timeout 20 $cmd
        want_rc 1
        # sfasm names a source as FILE:1:1 (its diagnostics' form)
        want_err "$bad(:1:1: cannot read file)?: $why"
        [ ! -e "$T/o" ] || no "an output folder was made"
        [ ! -e "$T/x.sfo" ] || no "an object was written"
        end
    done < <(commands "$bad")
}

check_all /dev/zero "not a regular file \(a character device\)"
check_all "$T/fifo" "not a regular file \(a FIFO\)"
check_all "$T/dir" "is a directory"

begin "sfsim trace reads a ray file that starts with a UTF-8 byte-order mark"
printf '\xef\xbb\xbf' > "$T/bom.txt"
cat tests/cli/cornell_rays.txt >> "$T/bom.txt"
run "$SFSIM" trace -s "$SCENE" --rays "$T/bom.txt" -o "$T/bom-hits.txt" --mode reference
want_rc 0
run "$SFSIM" trace -s "$SCENE" --rays tests/cli/cornell_rays.txt -o "$T/plain-hits.txt" --mode reference
want_rc 0
cmp -s "$T/bom-hits.txt" "$T/plain-hits.txt" || no "the hits differ from those of the same rays without the mark"
end

begin "an include of /dev/zero in an assembly file is refused naming the include"
printf '.include "/dev/zero"\nhalt\n' > "$T/inc.s"
run timeout 20 "$SFASM" "$T/inc.s" -o "$T/inc.sfo"
want_rc 1; want_err "/dev/zero.*not a regular file"
end

cli_summary "cli inputs"
