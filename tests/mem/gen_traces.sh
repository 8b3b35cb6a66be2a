#!/usr/bin/env bash
# tests/mem/gen_traces.sh PRESET DIR -- writes the four trace shapes of docs/validation.md (DRAM
# section) at an idle and a saturating rate, in DRAMsim3's format, for PRESET (ddr4_2400 or
# ddr5_4800: the field positions of its mapping ro,ra,ba,co,bg,ch), into DIR:
#   seq-idle.trc  seq-sat.trc      consecutive 64-byte bursts
#   rand-idle.trc rand-sat.trc     random bursts (MINSTD: x = 48271 x mod (2^31 - 1), exact in awk)
#   row-idle.trc  row-sat.trc      the columns of one row of one bank, in turn (all row hits)
#   conf-idle.trc conf-sat.trc     a new row of one bank every request (all row conflicts)
# idle: one read every 200 DRAM cycles (1000 reads); saturating: one read every cycle (10000 reads).
set -eu
preset=$1 dir=$2
case $preset in
    ddr4_2400) co_shift=8 co_n=128 ro_shift=17 ;;
    ddr5_4800) co_shift=10 co_n=64 ro_shift=18 ;;
    *) echo "gen_traces.sh: unknown preset $preset" >&2; exit 2 ;;
esac
mkdir -p "$dir"
for rate in idle sat; do
    if [ $rate = idle ]; then n=1000 gap=200; else n=10000 gap=1; fi
    for shape in seq rand row conf; do
        awk -v n=$n -v gap=$gap -v shape=$shape -v cs=$co_shift -v cn=$co_n -v rs=$ro_shift 'BEGIN {
            x = 12345
            for (i = 0; i < n; i++) {
                if (shape == "seq") a = i * 64
                else if (shape == "rand") { x = (x * 48271) % 2147483647; a = (x % 134217728) * 64 }
                else if (shape == "row") a = (i % cn) * 2 ^ cs
                else a = (i + 1) * 2 ^ rs
                printf "0x%x%08x READ %d\n", int(a / 4294967296), a % 4294967296, i * gap
            }
        }' > "$dir/$shape-$rate.trc"
    done
done
