#!/usr/bin/env bash
# tests/cli/cases/sched.sh -- the scheduling pass end to end: sfasm's -O options and report, the
# disassembly of a scheduled object, and the same images, rays and instruction counts with
# kernel.schedule = none and list on every row of the same-outputs table (docs/assembler.md,
# "Instruction scheduling").
set -u
cd "$(dirname "$0")/../../.."
T=$(mktemp -d /tmp/sfsim-cli-sched.XXXXXX)
trap 'rm -rf "$T"' EXIT
SFASM=${SFASM:-bin/sfasm}
SFSIM=${SFSIM:-bin/sfsim}
. tests/cli/lib.sh

cat > "$T/chain.s" <<'S'
        vfma    v1, v2, v3, v4
        vfadd   v5, v1, v1
        vfmul   v6, v7, v8
        halt
S

begin "sfasm keeps the source order by default and with -O0; -O fills the latency"
run "$SFASM" "$T/chain.s" -o "$T/a.sfo"
want_rc 0
run "$SFASM" -O0 "$T/chain.s" -o "$T/b.sfo"
want_rc 0
cmp -s "$T/a.sfo" "$T/b.sfo" || no "-O0 differs from the default"
run "$SFASM" -O "$T/chain.s" -o "$T/c.sfo"
want_rc 0
cmp -s "$T/a.sfo" "$T/c.sfo" && no "-O left the chain as written"
run "$SFASM" -d "$T/c.sfo"
want_rc 0
tr -s ' ' < "$T/out" | grep -v '^\s*\.' | sed 's/^ //' > "$T/dis"
printf 'vfma v1, v2, v3, v4\nvfmul v6, v7, v8\nvfadd v5, v1, v1\nhalt\n' | cmp -s - "$T/dis" ||
    no "the disassembly is not the scheduled order: $(tr '\n' '|' < "$T/dis")"
end

begin "sfasm -O --latency: with 1-cycle units there is nothing to hide and the order stays"
run "$SFASM" -O1 --latency vfma=1 --latency vmul=1 --latency=vadd=1 "$T/chain.s" -o "$T/d.sfo"
want_rc 0
cmp -s "$T/a.sfo" "$T/d.sfo" || no "1-cycle units leave nothing to hide, yet the order changed"
end

begin "sfasm --schedule-report gives each block and the total"
run "$SFASM" -O --schedule-report "$T/chain.s" -o "$T/e.sfo"
want_rc 0
want_out "^block 0-3 \(.*chain.s:1\): 4 instructions, critical path 6, cycles 8 -> 6$"
want_out "^total: 1 blocks, 1 reordered, 2 instructions moved, cycles 8 -> 6"
end

begin "sfasm's scheduling options are checked"
run "$SFASM" -O2 "$T/chain.s"
want_rc 2; want_err "-O2: the levels are -O0"
run "$SFASM" -O --latency vfmaa=3 "$T/chain.s"
want_rc 2; want_err "--latency vfmaa=3: expected CLASS=N"
run "$SFASM" -O --issue vfma=0 "$T/chain.s"
want_rc 2; want_err "--issue vfma=0: N must be an integer in 1..1024"
run "$SFASM" --schedule-report "$T/chain.s"
want_rc 2; want_err "go with -O"
run "$SFASM" -O --lanes 65 "$T/chain.s"
want_rc 2; want_err "--lanes 65"
end

begin "kernel.schedule is a config key with none and list"
run "$SFSIM" config --dump
want_rc 0; want_out "^\[kernel\]"
run "$SFSIM" config --dump --set kernel.schedule=sorted
want_rc 1; want_err "kernel.schedule"
end

# The same images, rays and instruction counts with the other kernel.schedule than the default (the
# table holds the default's), on every row that runs the kernel (about a minute).
other=list
"$SFSIM" config --dump 2>/dev/null | awk '/^\[kernel\]/ { k = 1 } k && /^schedule/ { print; exit }' |
    grep -q list && other=none
begin "every row of the same-outputs table computes the same with kernel.schedule = $other"
bash tests/outputs/check.sh --schedule "$other" > "$T/same" 2>&1 || no "$(grep -A2 FAIL "$T/same" | head -12)"
end

begin "kernel.unroll_box = 2 renders the same images with fewer stalls on the Cornell box"
bash tests/outputs/check.sh --images-with kernel.unroll_box=2 cornell-detailed-n16 cornell-packet cornell-trace-detailed \
    conference-detailed-n16 > "$T/unroll" 2>&1 || no "$(grep -A2 FAIL "$T/unroll" | head -12)"
end

cli_summary "cli sched"
