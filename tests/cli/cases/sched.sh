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

# kernel.unroll_box = 0 (auto, the default) runs 2 on cornell-detailed-m4096 and 1 on the other rows:
# each explicit value renders the same images as the table's.
for u in 1 2; do
    begin "kernel.unroll_box = $u renders the same images as the default (auto)"
    bash tests/outputs/check.sh --images-with kernel.unroll_box=$u cornell-detailed-n16 cornell-detailed-m4096 \
        cornell-packet cornell-trace-detailed conference-detailed-n16 > "$T/unroll$u" 2>&1 ||
        no "$(grep -A2 FAIL "$T/unroll$u" | head -12)"
    end
done

# What auto resolves to, as the report says (sim/run/kernel.c, box_unroll): 2 in stream mode when a
# tile holds at least 256 ID vectors (rays / N), else 1; packet mode, kd-trees and a trace batch of
# fewer rays 1.
unroll_of() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["kernel"]["unroll_box"])' "$1" 2>/dev/null; }
begin "kernel.unroll_box = 0 (auto) resolves by the stream's length, and report.json and report.txt say so"
i=0
while read -r want sets; do
    i=$((i + 1))
    args=()
    for kv in $sets; do args+=(--set "$kv"); done
    run "$SFSIM" run --mode functional -s scenes/cornell/scene.ini --set render.width=16 --set render.height=16 \
        --set render.spp=1 "${args[@]}" -j 1 -o "$T/auto$i"
    want_rc 0
    got=$(unroll_of "$T/auto$i/report.json")
    [ "$got" = "$want" ] || no "$sets: kernel.unroll_box resolved to '$got', not $want"
done <<'W'
2 stream.rays=4096
2 stream.rays=4096 core.simd_width=8
1 stream.rays=4096 core.simd_width=32
1 stream.rays=1024
2 stream.rays=1024 core.simd_width=4
1 stream.rays=4096 stream.mode=packet
1 stream.rays=4096 accel.structure=kd
1 stream.rays=4096 kernel.unroll_box=1
2 stream.rays=1024 kernel.unroll_box=2
W
grep -q "kernel.unroll_box 2 (0, auto)" "$T/auto1/report.txt" || no "report.txt does not say auto chose 2"
grep -q "BOX_UNROLL" "$T/auto4/report.txt" && no "1024-ray tiles were built with BOX_UNROLL"
run "$SFSIM" config --dump --set kernel.unroll_box=3
want_rc 1; want_err "kernel.unroll_box=3: value 3 out of range 0..2"
end

cli_summary "cli sched"
