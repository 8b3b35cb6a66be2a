#!/usr/bin/env bash
# tests/cli/cases/chip.sh -- `sfsim run` on a chip (docs/chip.md): the chip's report (per-core
# busy + stall + idle = cores x cycles, the memory sections, stalls by level) and `--mem-trace`
# (one line per request the scene caches sent below, the count the report gives, replayable by
# `sfsim mem`), sampled mode on a chip against its detailed run, and the misuses: --mem-trace
# outside detailed mode, a chip in `sfsim trace`, an L2 that does not divide into sets.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-chip.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

small=(--set render.width=64 --set render.height=64 --set render.spp=1 --set stream.rays=1024)

# A value of report.json: json FILE python-expression-on-j
json() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print($2)" "$1"; }

begin "chip: 4 cores with an L2 and DDR4 account for every core-cycle, and trace their misses"
run "$SFSIM" run -c configs/chip16-ddr4.ini --set chip.cores=4 "${small[@]}" --mem-trace "$T/c4.trc" -o "$T/c4"
want_rc 0
want_out "wrote .*report.json.*; $T/c4.trc"
[ "$(json "$T/c4/report.json" "sum(c['busy'] + c['stall'] + c['idle'] for c in j['cores']) == 4 * j['cycles']")" = True ] ||
    no "busy + stall + idle over the cores is not 4 x cycles"
[ "$(json "$T/c4/report.json" "j['chip']['cores']")" = 4 ] || no "chip.cores is not 4"
[ "$(json "$T/c4/report.json" "sum(j['scene_memory_stalls'].values()) == j['stalls']['scene_memory']")" = True ] ||
    no "the scene-memory stalls by level do not add up to scene_memory's"
grep -q '^memory ' "$T/c4/report.txt" && grep -q '^l2 ' "$T/c4/report.txt" && grep -q '^dram ' "$T/c4/report.txt" ||
    no "report.txt lacks the memory, l2 or dram line"
lines=$(($(wc -l <"$T/c4.trc") - 1))
want=$(json "$T/c4/report.json" "j['memory']['reads'] + j['memory']['writes']")
[ "$lines" = "$want" ] || no "the trace has $lines requests, the report $want"
head -1 "$T/c4.trc" | grep -q '^sfsim-memtrace 1 clock_mhz=500$' || no "no sfsim-memtrace header"
end

begin "chip: sfsim mem replays a run's trace"
run "$SFSIM" mem --trace "$T/c4.trc"
want_rc 0
want_out "^total"
end

begin "chip: one core on its bus traces as many lines as its cache missed and wrote back, and reports as ever"
run "$SFSIM" run "${small[@]}" --mem-trace "$T/c1.trc" -o "$T/c1"
want_rc 0
lines=$(($(wc -l <"$T/c1.trc") - 1))
want=$(json "$T/c1/report.json" "j['units']['scene_memory']['misses'] + j['units']['scene_memory']['writebacks']")
[ "$lines" = "$want" ] || no "the trace has $lines requests, the cache $want misses and write-backs"
[ "$(json "$T/c1/report.json" "'chip' in j")" = False ] || no "the paper's machine reports a chip"
end

begin "chip: --mem-trace outside detailed mode is a usage error"
run "$SFSIM" run --mode functional "${small[@]}" --mem-trace "$T/x.trc" -o "$T/x"
want_rc 2
want_err "--mem-trace"
[ ! -e "$T/x.trc" ] || no "a trace was written"
end

begin "chip: sampled mode on 4 cores with an L2 and DDR4 estimates the makespan with an interval"
sm=(--set render.width=128 --set render.height=128 --set render.spp=4 --set stream.rays=1024)
run "$SFSIM" run --mode sampled --sample 0.5 -c configs/chip16-ddr4.ini --set chip.cores=4 "${sm[@]}" -o "$T/s"
want_rc 0
want_out "wrote .*report.json"
grep -q '^chip sample ' "$T/s/report.txt" || no "report.txt lacks the chip sample line"
[ "$(json "$T/s/report.json" "j['cycles_ci95'][0] <= j['cycles'] <= j['cycles_ci95'][1]")" = True ] ||
    no "the estimate is not inside its interval"
[ "$(json "$T/s/report.json" "j['sample']['chip']['opening_units'] >= 4 and j['sample']['chip']['waves'] == 4")" = True ] ||
    no "no opening of 4 units or not 4 waves"
[ "$(json "$T/s/report.json" "j['energy']['total_j']")" = 0 ] || no "energy is given though not estimated"
grep -q '^energy .*total j -' "$T/s/report.txt" || no "report.txt gives an energy it did not estimate"
run "$SFSIM" run --mode detailed -c configs/chip16-ddr4.ini --set chip.cores=4 "${sm[@]}" -o "$T/d"
want_rc 0
[ "$(python3 -c "import json; s=json.load(open('$T/s/report.json')); d=json.load(open('$T/d/report.json')); print(abs(s['cycles'] / d['cycles'] - 1) < 0.03)")" = True ] ||
    no "the sampled makespan is more than 3 % from the detailed one"
end

begin "chip: sampled mode says when the makespan's interval is wider than --target-error"
# (16 cores, 4 tiles a core: the tail's units cannot bring the makespan's interval within 0.2 %)
run "$SFSIM" run --mode sampled --target-error 0.002 -c configs/chip16-ddr4.ini \
    --set render.width=256 --set render.height=256 --set render.spp=4 --set stream.rays=1024 -o "$T/w"
want_rc 0
want_err "warning: the makespan's 95 % interval is \+-[0-9.]+ %, wider than --target-error 0.2 %"
[ "$(json "$T/w/report.json" "(j['cycles_ci95'][1] - j['cycles_ci95'][0]) / 2 / j['cycles'] > 0.002")" = True ] ||
    no "the warning came with an interval within 0.2 %"
[ "$(json "$T/w/report.json" "j['sample']['chip']['tail_units'] <= 2 * (j['sample']['units_sampled'] - j['sample']['chip']['tail_units'])")" = True ] ||
    no "the tail timed more than twice the sample's units"
run "$SFSIM" run --mode sampled --target-error 0.01 -c configs/chip16-ddr4.ini --set chip.cores=64 \
    --set render.width=256 --set render.height=256 --set render.spp=8 --set stream.rays=1024 -o "$T/t"
want_rc 0
[ "$(json "$T/t/report.json" "(j['cycles_ci95'][1] - j['cycles_ci95'][0]) / 2 / j['cycles'] <= 0.01 and j['sample']['chip']['tail_units'] > 0")" = True ] ||
    no "at 1 tile a core the tail did not bring the makespan's interval within 1 %"
grep -q "warning: the makespan" "$T/err" && no "a warning though the interval is within the target"
end

begin "chip: sampled mode with --no-image above 8 spp estimates the makespan but not the memory figures, and says so"
# (the L2's warming record then holds one pass in ceil(spp / 8): DRAM's traffic would read high)
cs=(-s scenes/cornell/scene.ini -c configs/chip16-ddr4.ini --set render.width=128 --set render.height=128
    --set render.spp=16 --set stream.rays=1024 --target-error 0.02 --no-progress)
run "$SFSIM" run --mode sampled --no-image "${cs[@]}" -o "$T/ni"
want_rc 0
want_err "warning: with --no-image above 8 samples per pixel the L2's warming record holds one pass in 2 of each tile"
[ "$(json "$T/ni/report.json" "j['sample']['chip']['record_step'] == 2 and j['cycles'] > 0")" = True ] ||
    no "report.json: not a record of one pass in 2 with a makespan"
grep -qE '^dram +bandwidth gbs -$' "$T/ni/report.txt" || no "report.txt gives DRAM's bandwidth from a partial record"
run "$SFSIM" run --mode sampled "${cs[@]}" -o "$T/wi"
want_rc 0
grep -q "warming record" "$T/err" && no "a warning about the record though the image was made"
[ "$(json "$T/wi/report.json" "j['sample']['chip']['record_step'] == 1 and j['dram']['bandwidth_gbs'] > 0")" = True ] ||
    no "with the image: not the whole record, or no DRAM bandwidth"
end

begin "chip: sfsim trace on 4 cores with an L2 and DDR4 gives functional mode's hits"
awk 'BEGIN { print "# ox oy oz dx dy dz"; for (i = 0; i < 9000; i++) printf "278 273 -800 %.4f %.4f 1\n", (i % 97) / 200.0 - 0.24, int(i / 97) / 200.0 - 0.24 }' \
    >"$T/rays.txt"
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits-f.txt" --mode functional
want_rc 0
run "$SFSIM" trace -s scenes/cornell/scene.ini --rays "$T/rays.txt" -o "$T/hits-c.txt" --mode detailed \
    -c configs/chip16-ddr4.ini --set chip.cores=4
want_rc 0
want_out "9000 rays"
want_out "chip: 4 cores, 3 with a batch, makespan [0-9]+ cycles"
cmp -s "$T/hits-f.txt" "$T/hits-c.txt" || no "the chip's hits differ from functional mode's"
end

begin "chip: an L2 that does not divide into sets names its keys"
run "$SFSIM" run --set chip.memory=shared --set l2.size_kb=100 "${small[@]}" -o "$T/b"
want_rc 1
want_err "l2.size_kb = 100"
end

begin "chip: --mem-trace into a folder fails with exit 4 and keeps the run's other outputs"
mkdir -p "$T/dir.trc"
run "$SFSIM" run "${small[@]}" --mem-trace "$T/dir.trc" -o "$T/d"
want_rc 4
[ -e "$T/d/report.json" ] || no "the run's report was not kept"
end

cli_summary "cli chip"
