#!/usr/bin/env bash
# tests/cli/run.sh -- end-to-end tests of bin/sfasm and bin/sfsim, run as a user runs them:
# exit codes, messages that name file:line(:col), disassembly round trips, traps, configs.
# `make test` runs it before the Criterion suite. Exit status: 0 when every test passed.
#
# Exit codes under test: sim/exitcodes.def (sfsim help exit-codes) -- 0 ok, 1 bad input (also an
# option value out of range), 2 usage (unknown option or command, missing argument), 3 trap or
# instruction limit, 4 an output could not be written.
set -u

cd "$(dirname "$0")/../.." || exit 2
SFASM=${SFASM:-bin/sfasm}
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT

. tests/cli/lib.sh

for tool in "$SFASM" "$SFSIM"; do
    if [ ! -x "$tool" ]; then
        echo "cli: $tool is missing (run make)"
        echo "cli: 0 passed, 1 failed"
        exit 1
    fi
done

# ---- sfasm --------------------------------------------------------------------------------

begin "sfasm --help exits 0 and prints usage"
run "$SFASM" --help
want_rc 0; want_out "usage"
end

begin "sfasm without arguments is a usage error (2)"
run "$SFASM"
want_rc 2; want_err "usage|--help"
end

begin "sfasm with an unknown option is a usage error (2)"
run "$SFASM" --no-such-option tests/cli/ok.s
want_rc 2
end

begin "sfasm reports every error as file:line:col and exits 1"
run "$SFASM" tests/cli/errors.s -o "$T/errors.sfo"
want_rc 1
want_err "tests/cli/errors.s:3:[0-9]+: .*frob"
want_err "tests/cli/errors.s:4:[0-9]+: "
want_err "tests/cli/errors.s:5:[0-9]+: .*r40"
want_err "tests/cli/errors.s:6:[0-9]+: .*nowhere"
[ -e "$T/errors.sfo" ] && no "an object was written despite the errors"
end

begin "sfasm on a missing file names it and exits 1"
run "$SFASM" tests/cli/no_such_file.s -o "$T/x.sfo"
want_rc 1; want_err "no_such_file.s"
end

begin "sfasm assembles a program into an object"
run "$SFASM" tests/cli/ok.s -o "$T/ok.sfo"
want_rc 0; want_no_err
if [ -s "$T/ok.sfo" ]; then
    [ "$(head -c 3 "$T/ok.sfo")" = "SFO" ] || no "the object does not start with the SFO magic"
else
    no "no object written"
fi
end

begin "sfasm -d then reassembling gives identical bytes"
run "$SFASM" -d "$T/ok.sfo"
want_rc 0
cp "$T/out" "$T/round.s"
grep -q "halt" "$T/round.s" || no "the disassembly has no halt"
if "$SFASM" "$T/round.s" -o "$T/round1.sfo" 2>"$T/err"; then
    "$SFASM" -d "$T/round1.sfo" >"$T/round.s" 2>>"$T/err" || no "sfasm -d of the reassembled object failed"
    cmp -s "$T/out" "$T/round.s" || no "disassembling the reassembled object gives different text"
    if "$SFASM" "$T/round.s" -o "$T/round2.sfo" 2>>"$T/err"; then
        cmp -s "$T/round1.sfo" "$T/round2.sfo" || no "objects from the same disassembly differ (cmp)"
    else
        no "the second reassembly failed"
    fi
else
    no "the disassembly does not reassemble"
fi
end

begin "sfasm -d round trip of every tests/isa program (TEXT, DATA, SPAD)"
cmdline="sfasm FILE; sfasm -d; sfasm; sfasm -d; cmp"
: >"$T/out"; : >"$T/err"
n=0
for f in tests/isa/*.s; do
    b=$(basename "$f" .s)
    n=$((n + 1))
    if ! "$SFASM" "$f" -o "$T/p.sfo" 2>>"$T/err"; then no "$f does not assemble"; continue; fi
    if ! "$SFASM" -d "$T/p.sfo" >"$T/p1.s" 2>>"$T/err"; then no "$f: sfasm -d failed"; continue; fi
    if ! "$SFASM" "$T/p1.s" -o "$T/p1.sfo" 2>>"$T/err"; then no "$f: its disassembly does not assemble"; continue; fi
    "$SFASM" -d "$T/p1.sfo" >"$T/p2.s" 2>>"$T/err"
    cmp -s "$T/p1.s" "$T/p2.s" || no "$b: disassembly changes after a round trip"
done
[ "$n" -gt 0 ] || no "no programs in tests/isa"
end

begin "sfasm -D NAME=VALUE defines a symbol"
run "$SFASM" tests/cli/define.s -o "$T/define.sfo" -D VALUE=1234
want_rc 0
end

begin "sfasm without the -D symbol reports it undefined"
run "$SFASM" tests/cli/define.s -o "$T/define2.sfo"
want_rc 1; want_err "tests/cli/define.s:3:[0-9]+: .*VALUE"
end

# ---- sfsim --------------------------------------------------------------------------------

begin "sfsim --help exits 0 and prints usage"
run "$SFSIM" --help
want_rc 0; want_out "usage"
end

begin "sfsim without arguments is a usage error (2)"
run "$SFSIM"
want_rc 2
end

begin "sfsim with an unknown command is a usage error (2)"
run "$SFSIM" frobnicate
want_rc 2
end

begin "sfsim exec of a halting program exits 0 and prints registers"
run "$SFSIM" exec "$T/ok.sfo"
want_rc 0
want_out "r1"
want_out "(42|0x0*2a)"
want_out "(49|0x0*31)"
end

begin "sfsim exec --width sets N (read back with rdn)"
run "$SFSIM" exec "$T/ok.sfo" --width 16
want_rc 0
want_out "r2[^0-9a-z]+(= *)?(16|0x0*10)([^0-9]|$)"
end

begin "sfsim exec --width out of range is an error"
run "$SFSIM" exec "$T/ok.sfo" --width 65
[ "$rc" -eq 1 ] || [ "$rc" -eq 2 ] || no "exit status $rc, expected 1 or 2"
want_err "65|width|lanes"
end

begin "sfsim exec of a -D program shows the defined value"
run "$SFSIM" exec "$T/define.sfo"
want_rc 0; want_out "(1234|0x0*4d2)"
end

begin "sfsim exec: an out-of-bounds read traps with file:line (exit 3)"
"$SFASM" tests/cli/oob.s -o "$T/oob.sfo" 2>/dev/null || no "oob.s does not assemble"
run "$SFSIM" exec "$T/oob.sfo"
want_rc 3; want_any "trap:"; want_any "tests/cli/oob.s:4"
end

begin "sfsim exec --max-instructions stops an endless loop (exit 3)"
"$SFASM" tests/cli/loop.s -o "$T/loop.sfo" 2>/dev/null || no "loop.s does not assemble"
run timeout 20 "$SFSIM" exec "$T/loop.sfo" --max-instructions 1000
want_rc 3; want_any "trap:"; want_any "tests/cli/loop.s:[45]"
end

begin "sfsim exec: a stream with begin > end traps in sfetch (exit 3)"
"$SFASM" tests/cli/badstream.s -o "$T/badstream.sfo" 2>/dev/null || no "badstream.s does not assemble"
run "$SFSIM" exec "$T/badstream.sfo"
want_rc 3; want_any "trap:"; want_any "sfetch"; want_any "tests/cli/badstream.s:5"
end

begin "sfsim exec of a missing object exits 1 naming it"
run "$SFSIM" exec "$T/no_such.sfo"
want_rc 1; want_err "no_such.sfo"
end

begin "sfsim exec of a truncated object exits 1"
head -c 20 "$T/ok.sfo" >"$T/trunc.sfo"
run "$SFSIM" exec "$T/trunc.sfo"
want_rc 1; want_err "trunc.sfo"
end

begin "sfsim exec of a source file instead of an object exits 1"
run "$SFSIM" exec tests/cli/ok.s
want_rc 1; want_err "ok.s"
end

begin "sfsim config --dump prints the configuration"
run "$SFSIM" config --dump
want_rc 0
[ -s "$T/out" ] || no "empty output"
want_out "="
cp "$T/out" "$T/dump.ini"
end

begin "sfsim accepts its own config dump (-c)"
run "$SFSIM" exec "$T/ok.sfo" -c "$T/dump.ini"
want_rc 0; want_out "(42|0x0*2a)"
end

begin "sfsim -c with an unknown key names file, line and key (exit 1)"
run "$SFSIM" exec "$T/ok.sfo" -c tests/cli/bad_key.ini
want_rc 1; want_err "tests/cli/bad_key.ini:4: .*no_such_key"
end

begin "sfsim -c with a malformed line names file and line (exit 1)"
run "$SFSIM" exec "$T/ok.sfo" -c tests/cli/bad_syntax.ini
want_rc 1; want_err "tests/cli/bad_syntax.ini:3"
end

begin "sfsim -c with a missing file exits 1"
run "$SFSIM" exec "$T/ok.sfo" -c tests/cli/no_such.ini
want_rc 1; want_err "no_such.ini"
end

begin "sfsim --set with an unknown key exits 1"
run "$SFSIM" exec "$T/ok.sfo" --set no_such.key=1
want_rc 1; want_err "no_such"
end

# ---- sfsim run --mode reference and sfsim compare ----------------------------------------------
begin "sfsim run --mode reference renders the Cornell box with a report"
run "$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/ref1" --set render.width=48 \
    --set render.height=32 --set render.spp=2 -j 1 --no-progress
want_rc 0
for f in frame.png frame.exr report.txt report.json; do [ -s "$T/ref1/$f" ] || no "missing $f"; done
grep -qE '"mode":[[:space:]]+"reference"' "$T/ref1/report.json" 2>/dev/null || no "report.json has no mode"
grep -qE '"nonfinite":[[:space:]]+0,?$' "$T/ref1/report.json" 2>/dev/null || no "report.json: non-finite pixels"
end

begin "sfsim run gives the same image on 2 threads (compare: RMSE 0)"
run "$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/ref2" --set render.width=48 \
    --set render.height=32 --set render.spp=2 -j 2 --no-progress
want_rc 0
run "$SFSIM" compare "$T/ref1/frame.exr" "$T/ref2/frame.exr"
want_rc 0; want_out "RMSE +0$"; want_out "max diff +0$"
end

begin "sfsim run with a missing scene names it (exit 1)"
run "$SFSIM" run --mode reference -s tests/cli/no_such_scene.ini -o "$T/ref3" --no-progress
want_rc 1; want_err "no_such_scene.ini"
end

begin "sfsim compare of different sizes exits 1"
run "$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/ref4" --set render.width=16 \
    --set render.height=16 --set render.spp=1 --no-progress
run "$SFSIM" compare "$T/ref1/frame.exr" "$T/ref4/frame.exr"
want_rc 1; want_err "sizes differ"
end

begin "sfsim run with an unknown mode is bad input (exit 1: a value out of range, docs/exit-codes.md)"
run "$SFSIM" run --mode nonsense -o "$T/ref5"
want_rc 1; want_err "nonsense"
end

# ---- sfsim run --mode functional: the kernel on the functional core ------------------------------
begin "sfsim run --mode functional renders the Cornell box like the golden model (compare: RMSE 0)"
run "$SFSIM" run --mode functional -s scenes/cornell/scene.ini -o "$T/fun1" --set render.width=48 \
    --set render.height=32 --set render.spp=2 -j 2 --no-progress
want_rc 0
for f in frame.png frame.exr report.txt report.json; do [ -s "$T/fun1/$f" ] || no "missing $f"; done
grep -qE '"mode":[[:space:]]+"functional"' "$T/fun1/report.json" 2>/dev/null || no "report.json has no mode"
for k in utilization stream_length ops tiles rays_per_generation sim_instructions; do
    grep -q "\"$k\"" "$T/fun1/report.json" 2>/dev/null || no "report.json lacks $k"
done
grep -q "utilization" "$T/fun1/report.txt" 2>/dev/null || no "report.txt lacks utilization"
run "$SFSIM" compare "$T/ref1/frame.exr" "$T/fun1/frame.exr"
want_rc 0; want_out "max diff +0$"
end

begin "sfsim run --set workload.kind=phong: kernel and golden model give the same image, shadow rays"
run "$SFSIM" run --mode functional -s scenes/cornell/scene.ini -o "$T/ph1" --set workload.kind=phong \
    --set workload.bounces=1 --set render.width=40 --set render.height=24 --set render.spp=1 --no-progress
want_rc 0
grep -qE '"workload":[[:space:]]+"phong"' "$T/ph1/report.json" 2>/dev/null || no "report.json: workload is not phong"
grep -qE '"bounces":[[:space:]]+1,?$' "$T/ph1/report.json" 2>/dev/null || no "report.json: no bounces"
grep -qE '"shadow":[[:space:]]+[1-9]' "$T/ph1/report.json" 2>/dev/null || no "report.json: no shadow rays"
grep -qE '"indirect":[[:space:]]+[1-9]' "$T/ph1/report.json" 2>/dev/null || no "report.json: no bounce rays"
run "$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/ph2" --set workload.kind=phong \
    --set workload.bounces=1 --set render.width=40 --set render.height=24 --set render.spp=1 --no-progress
want_rc 0
run "$SFSIM" compare "$T/ph1/frame.exr" "$T/ph2/frame.exr"
want_rc 0; want_out "max diff +0$"
end

begin "workload.kind = specular with workload.bounces = 0 is a config error naming the key (exit 1)"
run "$SFSIM" run --mode functional -s scenes/cornell/scene.ini -o "$T/ph3" --set workload.kind=specular \
    --set workload.bounces=0 --no-progress
want_rc 1; want_err "workload.bounces = 0: workload.kind = specular needs at least 1 bounce"
end

begin "sfsim run --mode reference refuses a workload without a golden model (exit 1)"
run "$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/ph4" --set workload.kind=diffuse \
    --set render.width=8 --set render.height=8 --no-progress
want_rc 1; want_err "workload.kind = diffuse has no golden model"
end

begin "sfsim run --mode functional on a too small ray buffer names the key (exit 1)"
run "$SFSIM" run --mode functional -s scenes/cornell/scene.ini -o "$T/fun2" --set raybuf.size_kb=64 \
    --set render.width=16 --set render.height=16 --set render.spp=1 --no-progress
want_rc 1; want_err "raybuf.size_kb"
end

begin "sfsim run --mode functional with a kernel that does not assemble shows file:line (exit 1)"
printf 'start: vfadd v1, r2, v3\n' > "$T/bad_kernel.s"
run "$SFSIM" run --mode functional --kernel "$T/bad_kernel.s" -s scenes/cornell/scene.ini -o "$T/fun3" \
    --set render.width=16 --set render.height=16 --set render.spp=1 --no-progress
want_rc 1; want_err "bad_kernel.s:1:"
end

begin "sfsim run --mode functional: a kernel that traps names pc and tile, keeps finished tiles (exit 3)"
printf '.include "abi.inc"\nstart: spld r1, r0, L_X0\n li r2, 16\n bne r1, r2, ok\n li r1, 0x7FFFFFF0\n ld r2, r1, 0\nok: halt\n' > "$T/trap_kernel.s"
mkdir -p "$T/lib" && cp kernels/lib/abi.inc "$T/lib/"
run "$SFSIM" run --mode functional --kernel "$T/trap_kernel.s" -s scenes/cornell/scene.ini -o "$T/fun4" \
    --set render.width=32 --set render.height=16 --set stream.rays=1024 --set core.simd_width=4 \
    --set stream.mode=packet --set render.spp=1 -j 1 --no-progress
want_rc 3; want_err "tile at \(16, 0\).*trap.*trap_kernel.s:6"; want_err "tiles finished"
[ -s "$T/fun4/frame.partial.exr" ] || no "no frame.partial.exr"
grep -qE '"status":[[:space:]]+"failed"' "$T/fun4/report.json" 2>/dev/null || no "report.json not marked failed"
[ ! -e "$T/fun4/frame.exr" ] || no "a complete-looking frame.exr"
end

# ---- sfsim run (detailed mode, the default): the timing model --------------------------------------
begin "sfsim run (detailed, the default) renders the functional image bits and reports cycles, stalls, cost.png"
run "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/det1" --set render.width=48 --set render.height=32 \
    --set render.spp=2 -j 2 --no-progress
want_rc 0; want_out "cost.png"
for f in frame.png frame.exr report.txt report.json cost.png; do [ -s "$T/det1/$f" ] || no "missing $f"; done
grep -qE '"mode":[[:space:]]+"detailed"' "$T/det1/report.json" 2>/dev/null || no "report.json: mode is not detailed"
for k in cycles busy_cycles fps fps_no_stall clock_mhz stalls stall_shares cycles_by_stage stalls_by_stage \
         cycles_by_generation timing_by_generation utilization_timed units units_not_exercised bank_conflict_cycles hit_rate; do
    grep -q "\"$k\"" "$T/det1/report.json" 2>/dev/null || no "report.json lacks $k"
done
grep -qE '"cycles":[[:space:]]+null' "$T/det1/report.json" && no "cycles is null in detailed mode"
grep -qE '^cycles +[0-9]+ = [0-9]+ busy \+ [0-9]+ stalled; [0-9.]+ fps at 500 MHz' "$T/det1/report.txt" 2>/dev/null \
    || no "report.txt has no cycles line"
run "$SFSIM" compare "$T/fun1/frame.exr" "$T/det1/frame.exr"
want_rc 0; want_out "max diff +0$"
end

begin "sfsim run (detailed): identical cycles and image on 1 and 2 threads"
run "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/det2" --set render.width=48 --set render.height=32 \
    --set render.spp=2 -j 1 --no-progress
want_rc 0
c1=$(grep -E '^cycles ' "$T/det1/report.txt" 2>/dev/null | sed 's/fps.*//')
c2=$(grep -E '^cycles ' "$T/det2/report.txt" 2>/dev/null | sed 's/fps.*//')
[ -n "$c1" ] && [ "$c1" = "$c2" ] || no "cycles differ: '$c1' vs '$c2'"
run "$SFSIM" compare "$T/det1/frame.exr" "$T/det2/frame.exr"
want_rc 0; want_out "max diff +0$"
end

begin "sfsim run with an impossible timing config names the key (exit 1)"
run "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/det3" --set raybuf.line_bytes=48 --no-progress
want_rc 1; want_err "raybuf.line_bytes"
run "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/det3" --set scene.cache_kb=1 --set scene.cache_ways=64 --no-progress
want_rc 1; want_err "scene.cache_kb"
end

begin "sfsim run --mode sampled: same image, an interval; --sample 1 gives detailed mode's cycles"
run "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/det4" --set render.width=96 --set render.height=64 \
    --set render.spp=2 --set stream.rays=1024 -j 2 --no-progress
want_rc 0
run "$SFSIM" run --mode sampled --sample 0.5 -s scenes/cornell/scene.ini -o "$T/samp1" --set render.width=96 \
    --set render.height=64 --set render.spp=2 --set stream.rays=1024 -j 2 --no-progress
want_rc 0; want_out "cost.png"
grep -qE '"mode":[[:space:]]+"sampled"' "$T/samp1/report.json" 2>/dev/null || no "report.json: mode is not sampled"
for k in fps_ci95 cycles_ci95 sample units_sampled rounds r2 instructions; do
    grep -q "\"$k\"" "$T/samp1/report.json" 2>/dev/null || no "report.json lacks $k"
done
grep -qE '^cycles +~[0-9]+ \(95%: [0-9]+ \.\. [0-9]+\).*estimated from 6 of 12 units' "$T/samp1/report.txt" 2>/dev/null \
    || no "report.txt has no estimated cycles line"
run "$SFSIM" compare "$T/det4/frame.exr" "$T/samp1/frame.exr"
want_rc 0; want_out "max diff +0$"
run "$SFSIM" run --mode sampled --sample 1 -s scenes/cornell/scene.ini -o "$T/samp2" --set render.width=96 \
    --set render.height=64 --set render.spp=2 --set stream.rays=1024 -j 2 --no-progress
want_rc 0
cd4=$(grep -E '^cycles +[0-9]' "$T/det4/report.txt" 2>/dev/null | sed -E 's/^cycles +([0-9]+).*/\1/')
cs2=$(grep -E '^cycles +~' "$T/samp2/report.txt" 2>/dev/null | sed -E 's/^cycles +~([0-9]+) \(95%: ([0-9]+) \.\. ([0-9]+)\).*/\1 \2 \3/')
[ -n "$cd4" ] && [ "$cs2" = "$cd4 $cd4 $cd4" ] || no "sampling every unit: '$cs2', detailed: '$cd4'"
end

begin "sfsim run --mode sampled: --target-error (the default) reports its units; --no-image writes no image"
run "$SFSIM" run --mode sampled --target-error 0.02 -s scenes/cornell/scene.ini -o "$T/samp4" --set render.width=128 \
    --set render.height=128 --set render.spp=4 --set stream.rays=1024 -j 2 --no-progress
want_rc 0; want_out "frame.png"
grep -qE '"target_error":[[:space:]]+0.02' "$T/samp4/report.json" 2>/dev/null || no "report.json lacks the target error"
grep -qE '"units":[[:space:]]+64' "$T/samp4/report.json" 2>/dev/null || no "report.json: not 64 units (16 tiles x 4 passes)"
cp "$T/samp4/frame.png" "$T/samp4-frame.png"
run "$SFSIM" run --mode sampled --no-image -s scenes/cornell/scene.ini -o "$T/samp4" --set render.width=128 \
    --set render.height=128 --set render.spp=4 --set stream.rays=1024 -j 2 --no-progress
want_rc 0; want_out "wrote $T/samp4/report.txt"
[ ! -e "$T/samp4/frame.png" ] && [ ! -e "$T/samp4/frame.exr" ] || no "--no-image left (or kept an earlier run's) frame files"
grep -qE '"image":[[:space:]]+false' "$T/samp4/report.json" 2>/dev/null || no "report.json does not say there is no image"
end

begin "sfsim run: bad --sample / --target-error values are bad input (exit 1); sampled options without sampled mode, or both sizes, are usage errors (exit 2)"
run "$SFSIM" run --mode sampled --sample 0 -o "$T/samp3"
want_rc 1; want_err "--sample 0"
run "$SFSIM" run --mode sampled --sample 1.5 -o "$T/samp3"
want_rc 1; want_err "\(0, 1\]"
run "$SFSIM" run --sample 0.1 -o "$T/samp3"
want_rc 2; want_err "--mode sampled only"
run "$SFSIM" run --no-image -o "$T/samp3"
want_rc 2; want_err "--mode sampled only"
run "$SFSIM" run --mode sampled --target-error 0 -o "$T/samp3"
want_rc 1; want_err "--target-error 0: expected a fraction in \(0, 1\)"
run "$SFSIM" run --mode sampled --target-error 1% -o "$T/samp3"
want_rc 1; want_err "--target-error 1%"
run "$SFSIM" run --mode sampled --sample 0.1 --target-error 0.01 -o "$T/samp3"
want_rc 2; want_err "exclude each other"
end

begin "sfsim run: a render key out of range names the key and its range (exit 1, as for machine keys)"
run "$SFSIM" run --set render.spp=0 -o "$T/rk"
want_rc 1; want_err "--set render.spp = 0: expected an integer in 1\.\.1048576"
run "$SFSIM" run --set render.max_depth=64 -o "$T/rk"
want_rc 1; want_err "render.max_depth = 64: expected an integer in 0\.\.63"
end

begin "sfsim exec --timing prints the cycles of a micro-benchmark (kernels/bench/branch.s: 10 cycles)"
run "$SFASM" kernels/bench/branch.s -o "$T/branch.sfo"
want_rc 0
run "$SFSIM" exec "$T/branch.sfo" --timing -q
want_rc 0; want_out "^timing: 10 cycles = 8 busy \+ 2 stall"; want_out "stall control +2"
end

# ---- sfsim trace ---------------------------------------------------------------------------------
begin "sfsim trace: kernel and golden model give the same hits, text and binary (docs/trace.md)"
cp tests/cli/cornell_rays.txt "$T/rays.txt"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits_f.txt" -j 2
want_rc 0; want_out "7 rays \(functional\): 2 hits, 1 misses, 1 occluded, 1 clear, 2 invalid"
run "$SFSIM" trace --mode reference -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits_r.txt"
want_rc 0
cmp -s "$T/hits_f.txt" "$T/hits_r.txt" || no "text hits differ between the kernel and the golden model"
grep -q "^4 invalid$" "$T/hits_f.txt" || no "the NaN ray is not reported invalid"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays tests/fuzz/ray_seeds/two.bin -o "$T/hits_f.bin" --binary
want_rc 0
run "$SFSIM" trace --mode reference -s scenes/cornell/scene.ini --rays tests/fuzz/ray_seeds/two.bin -o "$T/hits_r.bin" --binary
want_rc 0
cmp -s "$T/hits_f.bin" "$T/hits_r.bin" || no "binary hits differ"
[ "$(stat -c %s "$T/hits_f.bin")" -eq 56 ] || no "binary hit file is not 16 + 2 x 20 bytes"
end

begin "sfsim trace --mode detailed: the same hits, and the cycles with their breakdown"
run "$SFSIM" trace --mode detailed -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits_d.txt" -j 2
want_rc 0; want_out "7 rays \(detailed\)"; want_out "^timing: [0-9]+ cycles = [0-9]+ busy"; want_out "stage +traversal"
cmp -s "$T/hits_f.txt" "$T/hits_d.txt" || no "detailed hits differ from functional"
end

begin "sfsim trace: a malformed text ray file names file and line (exit 1)"
printf '0 0 0 1 0 0\n0 0 0 1 x 0\n' > "$T/bad1.txt"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/bad1.txt" -o "$T/h.txt"
want_rc 1; want_err "bad1.txt:2: field 5: 'x' is not a number"
printf '0 0 0 1 0\n' > "$T/bad2.txt"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/bad2.txt" -o "$T/h.txt"
want_rc 1; want_err "bad2.txt:1: 5 fields"
printf '0 0 0 1 0 0 -1\n' > "$T/bad3.txt"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/bad3.txt" -o "$T/h.txt"
want_rc 1; want_err "bad3.txt:1: tmax must be > 0"
end

begin "sfsim trace: a truncated binary ray file names the byte count (exit 1)"
head -c 60 tests/fuzz/ray_seeds/two.bin > "$T/short.bin"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/short.bin" -o "$T/h.bin"
want_rc 1; want_err "short.bin: 60 bytes, but a header claiming 2 rays needs exactly 80"
end

begin "sfsim trace without its required options is a usage error (exit 2)"
run "$SFSIM" trace -s scenes/cornell/scene.ini
want_rc 2; want_err "required"
end

# ---- outputs: written whole or not at all (host/outfile.h, docs/report.md) --------------------
TINY=(--set render.width=32 --set render.height=32 --set render.spp=1 -j 2 --no-progress)
TRAP=(--mode functional --kernel "$T/trap_kernel.s" -s scenes/cornell/scene.ini --set render.width=32 --set render.height=16
      --set stream.rays=1024 --set core.simd_width=4 --set stream.mode=packet --set render.spp=1 -j 1 --no-progress)
RUN_OUTPUTS="frame.exr frame.png report.txt report.json stats.txt cost.png frame.partial.exr"

# no_temporaries DIR: no temporary file of host/outfile.c anywhere under DIR.
no_temporaries() {
    local left
    left=$(find "$1" -name '.*.tmp-*' 2>/dev/null | head -3)
    [ -z "$left" ] || no "temporary files left: $left"
}

# fail_each_write MODE DIR [FRESH]: run a tiny render with SFSIM_FAIL_WRITE=k for k = 1, 2, ...
# until it succeeds; each failure must exit 4 naming a file and the reason, print no "wrote",
# leave no temporary file, and leave DIR as it was: absent (FRESH) or holding the previous run's
# files unchanged (or, when a rename into place failed, none of them). Sets $writes to the number of
# operations and $named to the files the failures named.
fail_each_write() {
    local mode=$1 dir=$2 fresh=${3:-} k f olds gone
    writes=0; named=""
    for ((k = 1; k <= 80; k++)); do
        [ -n "$fresh" ] && rm -rf "$dir"
        run env SFSIM_FAIL_WRITE=$k "$SFSIM" run --mode "$mode" -s scenes/cornell/scene.ini -o "$dir" "${TINY[@]}"
        if [ "$rc" -eq 0 ]; then writes=$((k - 1)); break; fi
        if [ "$rc" -ne 4 ]; then no "k = $k: exit $rc, expected 4"; sed -n '1,3s/^/    stderr| /p' "$T/err"; break; fi
        grep -qE "^sfsim run: $dir(/[a-z.]+)?: .*No space left on device" "$T/err" || no "k = $k: stderr does not name the file and the reason"
        grep -q "wrote" "$T/out" && no "k = $k: a 'wrote' line after a failed write"
        no_temporaries "$(dirname "$dir")"
        f=$(grep -oE "$dir/[a-z.]+: " "$T/err" | head -1 | sed -E 's|.*/||; s|: $||')
        case " $named " in *" ${f:-folder} "*) ;; *) named="$named ${f:-folder}" ;; esac
        if [ -n "$fresh" ]; then
            [ ! -e "$dir" ] || no "k = $k: the run left $dir behind ($(ls -A "$dir" | tr '\n' ' '))"
        else
            olds=0; gone=0
            for f in $RUN_OUTPUTS; do
                if [ ! -e "$dir/$f" ]; then gone=$((gone + 1))
                elif cmp -s "$dir/$f" "$dir.before/$f"; then olds=$((olds + 1))
                else no "k = $k: $f is neither the previous run's nor absent"
                fi
            done
            [ "$olds" -eq 0 ] || [ "$olds" -eq "$(ls "$dir.before" | wc -l)" ] || no "k = $k: $olds of the previous run's files beside $gone removed ones"
        fi
        [ "$failed" -eq 0 ] || break
    done
    [ "$k" -le 80 ] || no "still failing at k = 80"
}

begin "sfsim run --mode functional: each output write fails in turn (SFSIM_FAIL_WRITE): exit 4, file named, nothing left"
mkdir -p "$T/fw"
fail_each_write functional "$T/fw/fun" fresh
# the folder, then frame.exr, frame.png, report.json, report.txt: each created, written, synced,
# closed, renamed into place
[ "$writes" -ge 21 ] || no "only $writes output operations counted (SFSIM_FAIL_WRITE has no effect?)"
for f in folder frame.exr frame.png report.json report.txt; do
    case " $named " in *" $f "*) ;; *) no "no failure named $f (named:$named)" ;; esac
done
for f in frame.exr frame.png report.json report.txt; do [ -s "$T/fw/fun/$f" ] || no "the final run did not write $f"; done
end

begin "sfsim run (detailed): each write fails in turn over a previous run's outputs: they stay whole, no mix"
"$SFSIM" run -s scenes/cornell/scene.ini -o "$T/fw/det" "${TINY[@]}" --set render.spp=2 >/dev/null 2>&1 \
    || no "the previous run failed"
"$SFSIM" run "${TRAP[@]}" -o "$T/fw/trap" >/dev/null 2>&1
cp "$T/fw/trap/frame.partial.exr" "$T/fw/det/" 2>/dev/null || no "no frame.partial.exr from the trap kernel"
rm -rf "$T/fw/det.before"; cp -a "$T/fw/det" "$T/fw/det.before"
fail_each_write detailed "$T/fw/det"
[ "$writes" -ge 25 ] || no "only $writes output operations counted"
for f in frame.exr frame.png report.json report.txt cost.png; do
    case " $named " in *" $f "*) ;; *) no "no failure named $f (named:$named)" ;; esac
done
for f in frame.exr frame.png report.json report.txt cost.png; do
    [ -s "$T/fw/det/$f" ] && ! cmp -s "$T/fw/det/$f" "$T/fw/det.before/$f" || no "the final run did not replace $f"
done
[ ! -e "$T/fw/det/frame.partial.exr" ] || no "an earlier run's frame.partial.exr is left beside complete outputs"
end

begin "sfsim run --mode functional: a stale cost.png of an earlier detailed run is removed"
cp "$T/fw/det/cost.png" "$T/fw/fun/cost.png"
run "$SFSIM" run --mode functional -s scenes/cornell/scene.ini -o "$T/fw/fun" "${TINY[@]}"
want_rc 0
[ ! -e "$T/fw/fun/cost.png" ] || no "cost.png of another run is left beside this run's outputs"
end

begin "sfsim run: a kernel failure whose partial outputs cannot be written says so (exit 3, nothing claimed)"
for ((k = 1; k <= 40; k++)); do
    rm -rf "$T/fw/trap"
    run env SFSIM_FAIL_WRITE=$k "$SFSIM" run "${TRAP[@]}" -o "$T/fw/trap"
    want_rc 3
    no_temporaries "$T/fw"
    if grep -q "frame.partial.exr; unfinished tiles are black" "$T/err"; then
        [ -s "$T/fw/trap/frame.partial.exr" ] || no "k = $k: frame.partial.exr claimed but missing"
        break
    fi
    want_err "the partial image was not kept: .*No space left on device"
    [ ! -e "$T/fw/trap" ] || no "k = $k: the run left $T/fw/trap behind"
    [ "$failed" -eq 0 ] || break
done
[ "$k" -ge 10 ] || no "only $((k - 1)) operations failed before the partial outputs were written"
end

begin "sfsim trace: each write of the hit file fails in turn: exit 4, file named, no file, no temporary"
for ((k = 1; k <= 20; k++)); do
    rm -f "$T/fw/hits.txt"
    run env SFSIM_FAIL_WRITE=$k "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/fw/hits.txt"
    [ "$rc" -eq 0 ] && break
    want_rc 4; want_err "^sfsim trace: $T/fw/hits.txt: .*No space left on device"
    grep -q "wrote" "$T/out" && no "k = $k: a 'wrote' line"
    [ ! -e "$T/fw/hits.txt" ] || no "k = $k: a hit file is left"
    no_temporaries "$T/fw"
    [ "$failed" -eq 0 ] || break
done
[ "$k" -eq 6 ] || no "the hit file took $((k - 1)) failing operations, expected 5 (create, write, fsync, close, rename)"
cmp -s "$T/fw/hits.txt" "$T/hits_f.txt" || no "the hit file differs from an ordinary run's"
end

begin "sfsim run -o naming a file fails before any work, naming it (exit 4)"
: > "$T/fw/a_file"
run "$SFSIM" run -s "$T/no_such_scene.ini" -o "$T/fw/a_file" "${TINY[@]}"
want_rc 4; want_err "^sfsim run: $T/fw/a_file: exists and is not a folder"
run "$SFSIM" run -s "$T/no_such_scene.ini" -o "$T/fw/a_file/sub" "${TINY[@]}"
want_rc 4; want_err "^sfsim run: $T/fw/a_file/sub: $T/fw/a_file exists and is not a folder"
[ ! -s "$T/fw/a_file" ] || no "the file was written to"
end

begin "sfsim trace -o naming a folder or a missing folder fails before any work (exit 4)"
run "$SFSIM" trace -s "$T/no_such_scene.ini" --rays "$T/rays.txt" -o "$T/fw"
want_rc 4; want_err "^sfsim trace: $T/fw: is a folder"
run "$SFSIM" trace -s "$T/no_such_scene.ini" --rays "$T/rays.txt" -o "$T/fw/nowhere/hits.txt"
want_rc 4; want_err "^sfsim trace: $T/fw/nowhere/hits.txt: .*No such file or directory"
end

begin "sfsim run with a kernel that does not assemble leaves no output folder behind (exit 1)"
rm -rf "$T/fw/new"
run "$SFSIM" run --mode functional --kernel "$T/bad_kernel.s" -s scenes/cornell/scene.ini -o "$T/fw/new/out" "${TINY[@]}"
want_rc 1; want_err "bad_kernel.s:1:"
[ ! -e "$T/fw/new" ] || no "$T/fw/new was created"
end

begin "sfsim run on a real full disk (a 128 KiB tmpfs, filled in steps): exit 0 with whole files, or 4 with nothing"
mkdir -p "$T/tmpfs"
if ! mount -t tmpfs -o size=128k tmpfs "$T/tmpfs" 2>"$T/err"; then
    echo "note: cannot mount a tmpfs ($(head -1 "$T/err")): the fault hook above covers full disks alone"
else
    trap 'umount "$T/tmpfs" 2>/dev/null; rm -rf "$T"' EXIT
    "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/fw/ref" "${TINY[@]}" >/dev/null 2>&1 || no "reference run failed"
    oks=0; fulls=0
    for fill in 0 16 24 28 30 32 40 60; do
        rm -rf "$T/tmpfs/"*
        [ "$fill" -gt 0 ] && head -c $((fill * 1024)) /dev/zero > "$T/tmpfs/fill"
        run "$SFSIM" run -s scenes/cornell/scene.ini -o "$T/tmpfs/out" "${TINY[@]}"
        no_temporaries "$T/tmpfs"
        if [ "$rc" -eq 0 ]; then
            oks=$((oks + 1))
            for f in frame.exr frame.png cost.png; do
                "$SFSIM" compare "$T/tmpfs/out/$f" "$T/fw/ref/$f" 2>/dev/null | grep -qE "max diff +0$" \
                    || no "$fill KiB full: $f claimed but not whole"
            done
            python3 -c 'import json,sys; json.load(open(sys.argv[1]))' "$T/tmpfs/out/report.json" 2>/dev/null \
                || no "$fill KiB full: report.json claimed but not whole"
            [ "$(wc -l < "$T/tmpfs/out/report.txt")" -eq "$(wc -l < "$T/fw/ref/report.txt")" ] \
                && tail -1 "$T/tmpfs/out/report.txt" | grep -q "^host " \
                || no "$fill KiB full: report.txt claimed but not whole"
        elif [ "$rc" -eq 4 ]; then
            fulls=$((fulls + 1))
            grep -qE "^sfsim run: $T/tmpfs/out/[a-z.]+: .*No space left on device" "$T/err" \
                || no "$fill KiB full: the message does not name the file and the reason"
            grep -q "wrote" "$T/out" && no "$fill KiB full: a 'wrote' line"
            [ ! -e "$T/tmpfs/out" ] || no "$fill KiB full: $(ls -A "$T/tmpfs/out" | tr '\n' ' ') left behind"
        else
            no "$fill KiB full: exit $rc"
        fi
    done
    [ "$oks" -gt 0 ] && [ "$fulls" -gt 0 ] || no "$oks runs fit and $fulls did not: the test missed a case"
    umount "$T/tmpfs" || no "cannot unmount $T/tmpfs"
    trap 'rm -rf "$T"' EXIT
fi
end


# ---- issue 14: exit codes, crashes and the smaller CLI defects -------------------------------------

begin "sfsim trace of 0 rays (empty, comments only, binary n = 0) in every mode: empty valid hits, exit 0"
: > "$T/rays0.txt"
printf '# no rays here\n\n   # nor here\n' > "$T/rays0c.txt"
printf 'SFRAYS1\0\0\0\0\0\0\0\0\0' > "$T/rays0.bin"
for m in functional detailed reference; do
    for f in rays0.txt rays0c.txt rays0.bin; do
        run "$SFSIM" trace --mode "$m" -s scenes/cornell/scene.ini --rays "$T/$f" -o "$T/h0_${m}_$f.txt" -j 2
        want_rc 0; want_out "0 rays \($m\): 0 hits, 0 misses"
        [ "$(grep -vc '^#' "$T/h0_${m}_$f.txt" 2>/dev/null)" = 0 ] || no "$m $f: the text hit file is not empty"
        run "$SFSIM" trace --mode "$m" -s scenes/cornell/scene.ini --rays "$T/$f" -o "$T/h0_${m}_$f.bin" --binary
        want_rc 0
        [ "$(od -An -c "$T/h0_${m}_$f.bin" 2>/dev/null | tr -d ' \n')" = 'SFHITS1\0\0\0\0\0\0\0\0\0' ] \
            || no "$m $f: the binary hit file is not a header for 0 hits"
    done
done
end

begin "report.json's config holds every key that sfsim config --dump lists, with its value (every mode)"
for m in detailed reference; do
    run "$SFSIM" run --mode "$m" -s scenes/cornell/scene.ini -c configs/streamray.ini --set latency.vfma=7 \
        --set render.width=16 --set render.height=16 --set render.spp=1 -o "$T/cfgblk_$m" -j 1 --no-progress
    want_rc 0
    "$SFSIM" config --dump -c configs/streamray.ini --set latency.vfma=7 >"$T/cfgdump_$m.ini" 2>>"$T/err" \
        || no "sfsim config --dump failed"
    python3 - "$T/cfgdump_$m.ini" "$T/cfgblk_$m/report.json" >"$T/cfgcheck" 2>&1 <<'PY' || no "$m: $(head -c 600 "$T/cfgcheck")"
import json, re, sys
dump, report = open(sys.argv[1]).read().splitlines(), json.load(open(sys.argv[2]))
cfg, section, keys, bad = report["config"], None, 0, []
for line in dump:
    if re.match(r"^\[(.+)\]$", line):
        section = line[1:-1]
    elif re.match(r"^[a-z_0-9]+ = ", line):
        key, value = line.split(" = ", 1)
        keys += 1
        got = cfg.get(section + "." + key)
        if got is None:
            bad.append("missing " + section + "." + key)
        elif (str(got) if isinstance(got, str) else "%g" % got) != ("%g" % float(value) if re.match(r"^-?[0-9.e+]+$", value) else value):
            bad.append("%s.%s = %r, config --dump says %s" % (section, key, got, value))
if keys < 60 or bad or len(cfg) != keys or report.get("config_file") != "configs/streamray.ini":
    sys.exit("%d keys dumped, %d in report.json; config_file %r; %s" % (keys, len(cfg), report.get("config_file"), "; ".join(bad)))
PY
done
end

begin "sfsim compare of a PNG with an EXR warns that they hold different encodings (exit 0); EXR with EXR does not"
run "$SFSIM" run --mode reference -s scenes/cornell/scene.ini -o "$T/enc" --set render.width=16 \
    --set render.height=16 --set render.spp=1 -j 1 --no-progress
want_rc 0
run "$SFSIM" compare "$T/enc/frame.png" "$T/enc/frame.exr"
want_rc 0; want_out "RMSE"
want_err "warning: .*frame.png holds display values \(sRGB-encoded.*frame.exr linear radiance"
run "$SFSIM" compare "$T/enc/frame.exr" "$T/enc/frame.exr"
want_rc 0; want_no_err
run "$SFSIM" compare "$T/enc/frame.png" "$T/enc/frame.png"
want_rc 0; want_no_err
end

begin "exit codes: a value out of range is bad input (1) for render and machine keys alike; unknown options are usage (2)"
run "$SFSIM" run --set render.width=0 -o "$T/ec"
want_rc 1; want_err "render.width = 0"
run "$SFSIM" run --set core.simd_width=0 -o "$T/ec"
want_rc 1; want_err "core.simd_width"
run "$SFSIM" run -j 0 -o "$T/ec"
want_rc 1; want_err "sfsim run: -j 0: expected an integer in 1\.\.1024"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays tests/fuzz/ray_seeds/cornell.txt -o "$T/ec.txt" -j 0
want_rc 1; want_err "sfsim trace: -j 0"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays tests/fuzz/ray_seeds/cornell.txt -o "$T/ec.txt" --mode fast
want_rc 1; want_err "--mode fast"
run "$SFSIM" exec "$T/ok.sfo" --width 0
want_rc 1; want_err "core.simd_width"
run "$SFSIM" config --dump --set render.width=5
want_rc 1
run "$SFSIM" run --no-such-option -o "$T/ec"
want_rc 2; want_err "no-such-option"
run "$SFSIM" run -o
want_rc 2
run "$SFSIM" exec
want_rc 2
run "$SFSIM" compare only_one.exr
want_rc 2
[ -e "$T/ec" ] && no "a refused run created its output folder"
end

begin "sfsim run --exposure refuses inf, nan, 0, negative, overflowing and non-numbers (exit 1)"
for x in inf -inf nan 0 -1 1e39 abc "" 1x; do
    run "$SFSIM" run --exposure "$x" -o "$T/ex"
    want_rc 1; want_err "--exposure .*finite positive"
done
[ -e "$T/ex" ] && no "a refused run created its output folder"
end

begin "sfsim trace: a hit file that cannot be written exits 4 (EXIT_IO) naming it"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays tests/fuzz/ray_seeds/cornell.txt -o "$T/no_such_dir/h.txt"
want_rc 4; want_err "no_such_dir/h.txt"; grep -q "wrote" "$T/out" && no "claims to have written the hits"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays tests/fuzz/ray_seeds/cornell.txt -o /dev/full
want_rc 4; want_err "/dev/full"
end

begin "sfsim help knows itself and the exit codes; --help of sfsim and sfasm print every row of sim/exitcodes.def"
run "$SFSIM" help help
want_rc 0; want_out "usage: sfsim help"; want_no_err
run "$SFSIM" help --help
want_rc 0; want_out "usage: sfsim help"
run "$SFSIM" help exit-codes
want_rc 0; cp "$T/out" "$T/help_ec"
run "$SFSIM" help no-such-topic
want_rc 2; want_err "unknown command 'no-such-topic'"
run "$SFSIM" --help
cp "$T/out" "$T/help_sfsim"
run "$SFASM" --help
cp "$T/out" "$T/help_sfasm"
rows=0
while IFS= read -r line; do
    [[ "$line" =~ ^EXITCODE\(([A-Z]+),\ *([0-9]+), ]] || continue
    rows=$((rows + 1))
    for f in help_ec help_sfsim help_sfasm; do
        grep -qE "^ +${BASH_REMATCH[2]}\+? +${BASH_REMATCH[1]} " "$T/$f" || no "$f lacks the row ${BASH_REMATCH[2]} ${BASH_REMATCH[1]}"
    done
done < sim/exitcodes.def
[ "$rows" -ge 7 ] || no "read only $rows rows of sim/exitcodes.def"
end

begin "sfasm exit codes: errors 1, usage 2, an object or disassembly that cannot be written 4"
run "$SFASM" tests/cli/ok.s -o "$T/no_such_dir/ok.sfo"
want_rc 4; want_err "no_such_dir/ok.sfo"
if [ -w /dev/full ]; then
    run bash -c "\"$SFASM\" -d \"$T/ok.sfo\" > /dev/full"
    want_rc 4; want_err "cannot write the disassembly"
fi
run "$SFASM" -d "$T/no_such.sfo"
want_rc 1
end

begin "standard output that cannot be written is an I/O failure (exit 4), not success"
if [ -w /dev/full ]; then
    for c in "config --markdown" "config --dump" "help exit-codes" "--help"; do
        run bash -c "\"$SFSIM\" $c > /dev/full"
        want_rc 4; want_err "cannot write to standard output"
    done
    run bash -c "\"$SFASM\" --help > /dev/full"
    want_rc 4
fi
end

begin "sfasm: a macro that calls itself twice gives one error naming it and its line, fast (was 125,000 lines)"
printf '.macro m\n    m\n    m\n.endm\n    m\n' > "$T/bomb.s"
run timeout 20 "$SFASM" "$T/bomb.s" -o "$T/bomb.sfo"
want_rc 1; want_err "macro 'm' \(defined at .*bomb.s:1\) nested too deeply"
[ "$(wc -l < "$T/err")" -le 2 ] || no "$(wc -l < "$T/err") lines of errors"
end

begin "sfasm prints at most 50 errors, then how many more (exit 1)"
{ for i in $(seq 1 120); do echo "  frob$i r1"; done; } > "$T/many.s"
run "$SFASM" "$T/many.s" -o "$T/many.sfo"
want_rc 1
[ "$(grep -c ": unknown instruction" "$T/err")" -eq 50 ] || no "$(grep -c ": unknown instruction" "$T/err") errors printed"
want_err "many.s:50:3: unknown instruction 'frob50'"; want_err "^\.\.\. and 70 more errors"; want_err "sfasm: 120 errors"
end

begin "sfsim exec --dump-mem is checked before the program runs (a looping program: exit 1 at once)"
for d in spad:2:1 spad:0x10000:1 spad:0xfffc:2 nosuch:0:1 spad:0 spad:-4:1 spad:0:1x; do
    run timeout 10 "$SFSIM" exec "$T/loop.sfo" --dump-mem "$d"
    want_rc 1; want_err "--dump-mem $d"
    [ -s "$T/out" ] && no "$d: the program ran"
done
run "$SFSIM" exec "$T/ok.sfo" -q --dump-mem spad:0xfffc:1 --dump-mem scene:0:2
want_rc 0; want_out "^spad from 0x0000fffc:"; want_out "^scene from 0x00000000:"
end

begin "sfsim exec: a long run says on stderr how far it is and the limit; stdout unchanged; --no-progress"
run env SFSIM_PROGRESS_AFTER=0 "$SFSIM" exec "$T/loop.sfo" --max-instructions 3000000
want_rc 3
want_err "still running after [0-9]+ s: 1048576 instructions of the limit 3000000 \(sim.max_instructions"
want_err "trap: instruction limit of 3000000 reached at pc [0-9]+ .*tests/cli/loop.s:[45]"
grep -q "still running" "$T/out" && no "progress on stdout"
sed -E 's/\([0-9.]+ s, [0-9.]+ M instructions\/s\)//' "$T/out" > "$T/prog_on"
run env SFSIM_PROGRESS_AFTER=0 "$SFSIM" exec "$T/loop.sfo" --max-instructions 3000000 --no-progress
want_rc 3
grep -q "still running" "$T/err" && no "--no-progress still shows progress"
sed -E 's/\([0-9.]+ s, [0-9.]+ M instructions\/s\)//' "$T/out" > "$T/prog_off"
cmp -s "$T/prog_on" "$T/prog_off" || no "stdout differs with progress"
want_err "trap: instruction limit of 3000000 reached"

# ---- INI files: machine configs and scene.ini, one reader, one set of rules (docs/ini.md) ------

begin "-c DIRECTORY is refused by run, trace, exec and config: 'is a directory' (exit 1)"
mkdir -p "$T/confdir"
printf '0 1 3.5 0 0 -1\n' >"$T/ini-rays.txt"
run "$SFSIM" run -c "$T/confdir" -o "$T/confdir-run" --set render.width=8 --set render.height=8 --set render.spp=1
want_rc 1; want_err "confdir: is a directory"
run "$SFSIM" trace -c "$T/confdir" -s scenes/cornell/scene.ini --rays "$T/ini-rays.txt" -o "$T/confdir-hits.txt"
want_rc 1; want_err "confdir: is a directory"
run "$SFSIM" exec "$T/ok.sfo" -c "$T/confdir"
want_rc 1; want_err "confdir: is a directory"
run "$SFSIM" config --dump -c "$T/confdir"
want_rc 1; want_err "confdir: is a directory"
end

begin "-c /dev/zero and -c FIFO are refused at once, not read forever (exit 1)"
run timeout 20 "$SFSIM" exec "$T/ok.sfo" -c /dev/zero
want_rc 1; want_err "/dev/zero: not a regular file \(a character device\)"
mkfifo "$T/conf.fifo"
run timeout 20 "$SFSIM" config --dump -c "$T/conf.fifo"
want_rc 1; want_err "conf.fifo: not a regular file \(a FIFO\)"
end

begin "an INI file over 16 MiB or with a line over 198 characters is refused, naming the limit (exit 1)"
truncate -s 17M "$T/huge.ini"
run timeout 20 "$SFSIM" config --dump -c "$T/huge.ini"
want_rc 1; want_err "huge.ini: larger than 16 MiB"
printf '[core]\n; %0200d\nsimd_width = 8\n' 0 >"$T/longline.ini"
run "$SFSIM" config --dump -c "$T/longline.ini"
want_rc 1; want_err "longline.ini:2: line longer than 198 characters"
end

begin "a machine config with a UTF-8 BOM and CRLF line ends loads (exit 0)"
printf '\xef\xbb\xbf; written on Windows\r\n[core]\r\nsimd_width = 8\r\n' >"$T/bom.ini"
run "$SFSIM" config --dump -c "$T/bom.ini"
want_rc 0; want_out "^simd_width = 8"
end

begin "a machine key given twice is refused naming both lines, also across a repeated section (exit 1)"
printf '[core]\nsimd_width = 8\n\nsimd_width = 4\n' >"$T/twice.ini"
run "$SFSIM" exec "$T/ok.sfo" -c "$T/twice.ini"
want_rc 1; want_err "twice.ini:4: key 'core.simd_width': given twice \(first at line 2\)"
printf '[core]\nsimd_width = 8\n[stream]\nrays = 1024\n[core]\nsimd_width = 4\n' >"$T/twice-sec.ini"
run "$SFSIM" config --dump -c "$T/twice-sec.ini"
want_rc 1; want_err "twice-sec.ini:6: key 'core.simd_width': given twice \(first at line 2\)"
printf '[core]\nsimd_width = 8\n    4\n' >"$T/cont.ini"
run "$SFSIM" config --dump -c "$T/cont.ini"
want_rc 1; want_err "cont.ini:2: key 'core.simd_width': continued on an indented line"
end

begin "a machine config may repeat a section (as config --dump does): its keys join (exit 0)"
printf '[core]\nsimd_width = 8\n[stream]\nrays = 1024\n[core]\nclock_mhz = 400\n' >"$T/again.ini"
run "$SFSIM" config --dump -c "$T/again.ini"
want_rc 0; want_out "^simd_width = 8"; want_out "^clock_mhz = 400"; want_out "^rays = 1024"
end

# A scene of one emitting sphere: no glTF file, so it can live in $T.
SPHERE_SCENE='[camera]\nposition = 0 0 5\nlook_at = 0 0 0\n[material.glow]\nemission = 1 1 1\n[sphere.s]\ncenter = 0 0 0\nradius = 1\nmaterial = glow\n[render]\nwidth = 8\nheight = 8\nspp = 1\n'

begin "scene.ini follows the same rules: a BOM is fine; a directory, a device, a key twice are refused"
printf "\xef\xbb\xbf$SPHERE_SCENE" >"$T/bom-scene.ini"
run "$SFSIM" run --mode reference -s "$T/bom-scene.ini" -o "$T/bom-scene" -j 1 --no-progress
want_rc 0
mkdir -p "$T/dir-scene.ini"
run "$SFSIM" run --mode reference -s "$T/dir-scene.ini" -o "$T/dir-scene" -j 1 --no-progress
want_rc 1; want_err "dir-scene.ini: is a directory"
printf "${SPHERE_SCENE}width = 16\n" >"$T/twice-scene.ini"
run "$SFSIM" run --mode reference -s "$T/twice-scene.ini" -o "$T/twice-scene" -j 1 --no-progress
want_rc 1; want_err "twice-scene.ini:14: key 'render.width': given twice \(first at line 11\)"
end

begin "sfsim trace warns, like run, about what a glTF file leaves out (points and lines)"
run "$SFSIM" trace --mode reference -s tests/scenes/ok_points_lines.gltf --rays tests/cli/cornell_rays.txt -o "$T/pl_hits.txt"
want_rc 0
want_err "^sfsim trace: warning: tests/scenes/ok_points_lines.gltf: skipped 3 of 4 primitives"
end

cli_summary cli
