#!/usr/bin/env bash
# tests/cli/cases/mem.sh -- `sfsim mem`: the four trace shapes of docs/validation.md (DRAM section)
# at an idle and a saturating rate on DDR4-2400 and DDR5-4800 give the documented figures (each
# beside its closed form there), both trace formats and the clock conversion, every preset's DRAM
# energy (LPDDR5's and GDDR6's per command as tests/unit/test_energy.c derives them), -o and --json, and
# every bad input gets a message naming file and line and exit code 1, without a hang; 10^6
# requests replay within a minute even on a loaded machine (a guard against a hang, not a benchmark).
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-mem.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

bash tests/mem/gen_traces.sh ddr4_2400 "$T/d4" || exit 2
bash tests/mem/gen_traces.sh ddr5_4800 "$T/d5" || exit 2

# shape rate preset "figures the report must show" (closed forms: docs/validation.md)
figures() {
    begin "mem: $3 $1 at the $2 rate: $4"
    local dir=d4
    [ "$3" = ddr5_4800 ] && dir=d5
    run "$SFSIM" mem --trace "$T/$dir/$1-$2.trc" --set dram.preset="$3"
    want_rc 0
    local pat
    IFS='|' read -ra pats <<<"$4"
    for pat in "${pats[@]}"; do
        grep -A9 '^total' "$T/out" | grep -qE -- "$pat" || no "total does not match /$pat/"
    done
    end
}
# Idle: the latency of a row hit CL + 4 = 20, a miss tRCD + CL + 4 = 36, a conflict tRP + tRCD +
# CL + 4 = 52 (DDR4); saturating: the share of peak the binding constraint leaves, times
# 1 - tRFC / tREFI for refresh.
figures seq  idle ddr4_2400 'p50/p95/p99 20 / '
figures row  idle ddr4_2400 'p50/p95/p99 20 / |978 hits, 22 misses, 0 conflicts'
figures conf idle ddr4_2400 'p50/p95/p99 52 / |0 hits, 22 misses, 978 conflicts'
figures rand idle ddr4_2400 'p50/p95/p99 52 / '
figures seq  sat  ddr4_2400 '95\.5% of peak'
figures row  sat  ddr4_2400 '63\.7% of peak'
figures conf sat  ddr4_2400 '6\.9% of peak'
figures rand sat  ddr4_2400 '58\.5% of peak'
figures seq  idle ddr5_4800 'p50/p95/p99 48 / '
figures conf idle ddr5_4800 'p50/p95/p99 128 / '
figures seq  sat  ddr5_4800 '92\.3% of peak'
figures row  sat  ddr5_4800 '30\.7% of peak'
figures conf sat  ddr5_4800 '3\.1% of peak'
figures rand sat  ddr5_4800 '89\.4% of peak'

begin "mem: tests/mem/example.trc gives the cycles derived in its comment"
run "$SFSIM" mem --trace tests/mem/example.trc
want_rc 0; want_out 'cycles 0\.\.252 of the DRAM clock'; want_out 'latency average +44\.50 cycles'
want_out 'p50/p95/p99 42 / 52 / 52 cycles'; want_out '2 hits, 1 misses, 1 conflicts'
end

begin "mem: tests/mem/example.mtr (sfsim format, 500 MHz) gives the cycles derived in its comment"
run "$SFSIM" mem --trace tests/mem/example.mtr
want_rc 0; want_out 'sfsim format\), 3 requests, cycles 0\.\.233 of'; want_out 'latency average +34\.67 cycles'
want_out '0 hits, 3 misses, 0 conflicts'
end

begin "mem: the sfsim format, its clock converted exactly (600 MHz cycles 100 -> DRAM cycle 200)"
printf 'sfsim-memtrace 1 clock_mhz=600\n# a comment\n\n100 R 0x0 l1\n100 W 0x40 wb\n' >"$T/a.mtr"
run "$SFSIM" mem --trace "$T/a.mtr"
want_rc 0; want_out 'sfsim format\), 2 requests, cycles 200\.\.'; want_out ' 2 \(1 reads, 1 writes\)'
end

begin "mem: an empty trace, and channels no request goes to (regression: no latency array to sort)"
: >"$T/empty.trc"
run "$SFSIM" mem --trace "$T/empty.trc"
want_rc 0; want_out 'requests +0 \(0 reads, 0 writes\)'
run "$SFSIM" mem --trace "$T/d4/row-idle.trc" --set dram.preset=hbm2_2000
want_rc 0; want_out '^channel 7'; want_out 'requests +1000 '
end

begin "mem: -o writes report.txt and report.json; --json prints the JSON"
run "$SFSIM" mem --trace "$T/d4/seq-idle.trc" -o "$T/rep" --json
want_rc 0
[ -s "$T/rep/report.txt" ] && [ -s "$T/rep/report.json" ] || no "report files missing"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["total"]["reads"]==1000' "$T/out" 2>/dev/null ||
    no "--json output is not the JSON report"
cmp -s "$T/out" "$T/rep/report.json" || no "stdout differs from report.json"
end

# bad FILE CONTENT "message": exit 1, the message names file (and line).
bad() {
    begin "mem: bad input: $1"
    printf "$2" >"$T/bad.trc"
    run timeout 20 "$SFSIM" mem --trace "$T/bad.trc" ${4:-}
    want_rc 1; want_err "$3"
    end
}
bad "cycles going back"   '0x0 READ 5\n0x40 READ 4\n'   'bad\.trc:2: cycle 4 is before the previous request.s 5'
bad "a bad address"       '0x0 READ 5\n0xZZ READ 6\n'   'bad\.trc:2: bad address .0xZZ.'
bad "an address too long" '0x11112222333344445 READ 1\n' 'bad\.trc:1: bad address'
bad "a bad operation"     '0x0 READ 5\n0x0 FETCH 6\n'   'bad\.trc:2: bad operation .FETCH.'
bad "a negative cycle"    '0x0 READ -5\n'               'bad\.trc:1: bad cycle .-5.'
bad "garbage"             '\x7fELF\x01\x02\n'           'bad\.trc:1: expected .0xADDR READ\|WRITE CYCLE.'
bad "too many fields"     '0x0 READ 1 2\n'              'bad\.trc:1: expected'
bad "a bad sfsim header"  'sfsim-memtrace 2 clock_mhz=500\n1 R 0x0\n' 'bad\.trc:1: expected the header'
bad "a bad sfsim line"    'sfsim-memtrace 1 clock_mhz=500\n1 R 0x0\n2 X 0x0\n' 'bad\.trc:3: bad operation .X.'
bad "a DRAMsim3 line read as sfsim" '0x0 READ 1\n' 'bad\.trc:1: expected the header' '--format sfsim'

# Every preset has IDD currents (sim/mem/dram_presets.def, sources in docs/energy.md), so each prints
# its energy; LPDDR5's and GDDR6's per-command figures are the closed forms of tests/unit/test_energy.c
# (LPDDR5: 1.3125 V ns x 429 and x 666 mA CK; GDDR6: 1.35 / 1.75 V ns x 816 and x 374 mA CK).
begin "mem: every preset reports the DRAM's energy; LPDDR5's and GDDR6's per command as derived"
for preset in ddr4_2400 ddr5_4800 lpddr5_6400 gddr6_14000 hbm2_2000; do
    run "$SFSIM" mem --trace tests/mem/example.trc --set dram.preset=$preset
    want_rc 0
    grep -q 'not computed' "$T/out" && no "$preset: energy not computed"
    grep -qE '^  total +[0-9.]+ nJ, [0-9.]+ pJ/bit' "$T/out" || no "$preset: no energy total"
    case $preset in
    lpddr5_6400) want_out 'VDD 1\.05 V; IDD0 45,'; want_out 'ACT\+PRE 563\.06 pJ, RD burst 874\.13 pJ' ;;
    gddr6_14000) want_out 'VDD 1\.35 V; IDD0 71,'; want_out 'ACT\+PRE 629\.49 pJ, RD burst 288\.51 pJ' ;;
    esac
    # I/O apart: DDR4's termination figure (docs/energy.md, "DRAM I/O") over the trace's 4 x 64 bytes,
    # 2048 x 2.287 pJ; HBM2's switched-capacitance figure, 2048 x 0.864 pJ; the other presets have
    # none and say so.
    case $preset in
    ddr4_2400) want_out 'I/O apart: 4\.684 nJ \(2\.287 pJ/bit\)'; want_out 'I/O figure +2\.287 pJ/bit: derived' ;;
    hbm2_2000) want_out 'I/O apart: 1\.769 nJ \(0\.864 pJ/bit\)'; want_out 'I/O figure +0\.864 pJ/bit: derived' ;;
    *) want_out 'I/O apart: 0 nJ \(0 pJ/bit\)'; want_out 'I/O figure +0 pJ/bit: none' ;;
    esac
done
run "$SFSIM" mem --trace tests/mem/example.trc --set energy.dram_io_pj_bit=5
want_rc 0; want_out 'I/O apart: 10\.24 nJ \(5 pJ/bit\)'; want_out 'I/O figure +5 pJ/bit: the key energy\.dram_io_pj_bit'
end

begin "mem: bad input: a line of 1 MB (no hang, no crash)"
head -c 1000000 /dev/zero | tr '\0' 'a' >"$T/huge.trc"
run timeout 20 "$SFSIM" mem --trace "$T/huge.trc"
want_rc 1; want_err 'huge\.trc:1: line longer than 4096 bytes'
end

begin "mem: bad input: a folder, a missing file, a device"
run timeout 20 "$SFSIM" mem --trace "$T"
want_rc 1; want_err 'is a directory'
run timeout 20 "$SFSIM" mem --trace "$T/nope.trc"
want_rc 1; want_err 'nope\.trc: cannot open'
run timeout 20 "$SFSIM" mem --trace /dev/zero
want_rc 1; want_err 'not a regular file'
end

begin "mem: a bad mapping or key names it; usage errors"
run "$SFSIM" mem --trace "$T/d4/seq-idle.trc" --mapping ro,ra,ba,co,bg
want_rc 1; want_err 'key dram\.mapping: .* does not name ch'
run "$SFSIM" mem --trace "$T/d4/seq-idle.trc" --set dram.write_high=99
want_rc 1; want_err 'key dram\.write_high'
run "$SFSIM" mem --trace "$T/d4/seq-idle.trc" --set dram.mapping=ro,ro
want_rc 1; want_err 'dram\.mapping'
run "$SFSIM" mem
want_rc 2; want_err 'give the trace'
run "$SFSIM" mem --trace "$T/d4/seq-idle.trc" --format xml
want_rc 1; want_err 'expected dramsim3, sfsim or auto'
end

begin "mem: --help has examples; sfsim help mem is the same"
run "$SFSIM" mem --help
want_rc 0; want_out 'examples:'; want_out 'sfsim mem --trace'
cp "$T/out" "$T/help1"
run "$SFSIM" help mem
cmp -s "$T/out" "$T/help1" || no "sfsim help mem differs from --help"
end

begin "mem: a million requests replay in seconds"
awk 'BEGIN { for (i = 0; i < 1000000; i++) printf "0x%x %s %d\n", (i * 7919 % 1048576) * 64, i % 4 ? "READ" : "WRITE", i * 3 }' >"$T/big.trc"
start=$(date +%s)
run timeout 120 "$SFSIM" mem --trace "$T/big.trc"
want_rc 0; want_out '1000000 \(750000 reads, 250000 writes\)'
[ $(($(date +%s) - start)) -le 60 ] || no "took more than 60 s (about 2 s on an idle 2-core machine)"
end

cli_summary "cli mem"
