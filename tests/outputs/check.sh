#!/usr/bin/env bash
# tests/outputs/check.sh -- the same-outputs table: runs every row of tests/outputs/outputs.tsv and
# compares what it produced (cycles, simulated instructions, an image hash and a hash of every report
# value) with the committed figures. A change that must not change results (a refactor, a speed-up)
# leaves this table as it is; `make test` runs the check.
#
#   bash tests/outputs/check.sh            check every row (rows whose scene is in ../shared are
#                                          skipped, each named, when ../shared is absent)
#   bash tests/outputs/check.sh --write    run every row and rewrite the table's figures (after a
#                                          change that is meant to change results: say why in the commit)
#   bash tests/outputs/check.sh NAME...    check only these rows
#   bash tests/outputs/check.sh --schedule none|list
#                                          run every row that runs the kernel with kernel.schedule
#                                          set so, and check only its instructions and image (or rays):
#                                          the scheduling pass changes the order, not what is computed
#   bash tests/outputs/check.sh --images-with KEY=VALUE [NAME...]
#                                          the same rows with --set KEY=VALUE, checking only the image
#                                          (or rays): for switches that change the instructions but not
#                                          what they compute (kernel.unroll_box=2)
#
# Columns: name, the file the row needs beyond the repository (a scene in ../shared) or "-", kind,
# arguments, then the figures. Row kinds: run (arguments of `sfsim run`; -o is added), trace (arguments of
# `sfsim trace`; -o is added), exec (an assembly file, sfasm -D options, `--`, `sfsim exec` options).
# Digests: build/outputs_digest (tools/outputs_digest.c) says what they cover.
set -u
cd "$(dirname "$0")/../.."
ROOT=$PWD
TABLE=tests/outputs/outputs.tsv
DIGEST=${OUTPUTS_DIGEST:-build/outputs_digest}
SFSIM=${SFSIM:-bin/sfsim}
SFASM=${SFASM:-bin/sfasm}
write=0
only=()
schedule=
images_with=
for a in "$@"; do
    if [ "$schedule" = next ]; then schedule=$a; continue; fi
    if [ "$images_with" = next ]; then images_with=$a; continue; fi
    case $a in
        --images-with) images_with=next ;;
        --write) write=1 ;;
        --schedule) schedule=next ;;
        -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
        -*) echo "check.sh: unknown option $a" >&2; exit 2 ;;
        *) only+=("$a") ;;
    esac
done
case $schedule in
    ''|none|list) ;;
    *) echo "check.sh: --schedule takes none or list" >&2; exit 2 ;;
esac
[ -n "$schedule$images_with" ] && [ $write = 1 ] && { echo "check.sh: --schedule and --images-with do not go with --write" >&2; exit 2; }
case $images_with in ''|*=*) ;; *) echo "check.sh: --images-with takes KEY=VALUE" >&2; exit 2 ;; esac
for f in "$DIGEST" "$SFSIM" "$SFASM" "$TABLE"; do
    [ -e "$f" ] || { echo "check.sh: $f is missing (make all $DIGEST)" >&2; exit 2; }
done
tmp=$(mktemp -d /tmp/sfsim-outputs.XXXXXX)
trap 'rm -rf "$tmp"' EXIT

# One row: prints "cycles instructions image report", or fails with its log on stderr.
digest_row() {
    local kind=$1 args=$2 dir=$tmp/out
    rm -rf "$dir"
    case $kind in
        run)
            # shellcheck disable=SC2086
            $SFSIM run $args -o "$dir" --no-progress >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; return 1; }
            $DIGEST "$dir"
            ;;
        trace)
            # shellcheck disable=SC2086
            $SFSIM trace $args -o "$tmp/hits" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; return 1; }
            local cycles instr
            cycles=$(sed -n 's/^timing: \([0-9]*\) cycles.*/\1/p' "$tmp/log")
            instr=$(sed -n 's/.* \([0-9]*\) simulated instructions.*/\1/p' "$tmp/log")
            sed "s/[0-9.]* s, //; s|$tmp|TMP|g" "$tmp/log" >"$tmp/log.clean"
            echo "${cycles:--} ${instr:--} $($DIGEST --text "$tmp/hits") $($DIGEST --text "$tmp/log.clean")"
            ;;
        exec)
            local src=${args%% -- *} rest=${args#* -- }
            # shellcheck disable=SC2086
            $SFASM $src -o "$tmp/prog.sfo" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; return 1; }
            # shellcheck disable=SC2086
            $SFSIM exec "$tmp/prog.sfo" $rest --no-progress >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; return 1; }
            local cycles instr
            cycles=$(sed -n 's/^timing: \([0-9]*\) cycles.*/\1/p' "$tmp/log")
            instr=$(sed -n 's/.* halted after \([0-9]*\) instructions.*/\1/p' "$tmp/log")
            sed "s/ ([0-9.]* s, [0-9.]* [kMG]* *instructions\/s)//; s|$tmp|TMP|g" "$tmp/log" >"$tmp/log.clean"
            echo "${cycles:--} ${instr:--} - $($DIGEST --text "$tmp/log.clean")"
            ;;
        *) echo "unknown row kind '$kind'" >&2; return 1 ;;
    esac
}

wanted() {
    [ ${#only[@]} -eq 0 ] && return 0
    local n
    for n in "${only[@]}"; do [ "$n" = "$1" ] && return 0; done
    return 1
}

pass=0 fail=0 skip=0
new=$tmp/table
start=$(date +%s)
while IFS= read -r line || [ -n "$line" ]; do
    case $line in ''|'#'*) echo "$line" >>"$new"; continue ;; esac
    IFS=$'\t' read -r name needs kind args want_c want_i want_img want_rep <<<"$line"
    if ! wanted "$name"; then echo "$line" >>"$new"; continue; fi
    if [ "$needs" != - ] && [ ! -e "$needs" ]; then
        echo "skip $name: needs ../shared (absent): $needs"
        skip=$((skip + 1))
        echo "$line" >>"$new"
        continue
    fi
    if [ -n "$schedule$images_with" ]; then
        # only the rows that assemble the kernel: not exec rows, not the golden model
        case "$kind $args" in exec*|*'--mode reference'*) echo "$line" >>"$new"; continue ;; esac
        [ -n "$schedule" ] && args="$args --set kernel.schedule=$schedule"
        [ -n "$images_with" ] && args="$args --set $images_with"
    fi
    t0=$(date +%s.%N)
    if ! got=$(digest_row "$kind" "$args"); then
        echo "FAIL $name: the run failed ($kind $args)"
        fail=$((fail + 1))
        echo "$line" >>"$new"
        continue
    fi
    secs=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    read -r c i img rep <<<"$got"
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$needs" "$kind" "$args" "$c" "$i" "$img" "$rep" >>"$new"
    if [ $write = 1 ]; then
        echo "wrote $name: $c cycles, $i instructions ($secs s)"
        pass=$((pass + 1))
    elif [ -n "$images_with" ] && [ -z "$schedule" ] && [ "$img" = "$want_img" ]; then
        echo "ok   $name: $images_with, $c cycles (table $want_c), $i instructions (table $want_i) ($secs s)"
        pass=$((pass + 1))
    elif [ -n "$schedule" ] && [ "$i $img" = "$want_i $want_img" ]; then
        echo "ok   $name: kernel.schedule=$schedule, $c cycles (table $want_c) ($secs s)"
        pass=$((pass + 1))
    elif [ -z "$schedule$images_with" ] && [ "$c $i $img $rep" = "$want_c $want_i $want_img $want_rep" ]; then
        echo "ok   $name ($secs s)"
        pass=$((pass + 1))
    else
        echo "FAIL $name: $kind $args"
        echo "     table: cycles $want_c, instructions $want_i, image $want_img, report $want_rep"
        echo "     now:   cycles $c, instructions $i, image $img, report $rep"
        fail=$((fail + 1))
    fi
done <"$TABLE"
if [ $write = 1 ]; then
    if [ $fail -ne 0 ]; then
        echo "check.sh: $fail rows failed; $TABLE left as it was" >&2
        exit 1
    fi
    cp "$new" "$TABLE"
fi
echo "same outputs: $pass ok, $fail failed, $skip skipped ($(( $(date +%s) - start )) s)"
[ $fail -eq 0 ]
