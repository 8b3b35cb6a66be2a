#!/usr/bin/env bash
# tests/cli/cases/timeline.sh -- `--timeline FILE` (docs/timeline.md): `sfsim run` writes a Chrome
# trace whose issue spans add up to the report's counts, `sfsim exec` a pipeline trace with one
# slice per instruction; and the misuses: a window without a file, a bad window, outside detailed
# mode, a folder where the file belongs (refused before any work, nothing written).
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
SFASM=${SFASM:-bin/sfasm}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-timeline.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

small=(--set render.width=64 --set render.height=64 --set render.spp=1 --set stream.rays=1024)

# busy and stall spans of core 0's issue thread against report.json's busy_cycles and stalls
sums() {
    python3 - "$1" "$2" <<'PY'
import collections, json, sys
tl = json.load(open(sys.argv[1])); rep = json.load(open(sys.argv[2]))
s = collections.Counter()
for e in tl["traceEvents"]:
    if e["ph"] == "X" and e["pid"] == 1 and e["tid"] == 0:
        name = e["name"].replace("stall: ", "").split(" (")[0]
        s[name] += e["dur"]
ok = s["busy"] == rep["busy_cycles"] and all(s[c] == v for c, v in rep["stalls"].items())
print("ok" if ok else "busy %d/%d stalls %s/%s" % (s["busy"], rep["busy_cycles"], dict(s), rep["stalls"]))
PY
}

begin "timeline: a run's busy and stall spans add up to its report"
run "$SFSIM" run "${small[@]}" --timeline "$T/tl.json" --timeline-window 0:100000000 -o "$T/r"
want_rc 0
want_out "wrote .*; $T/tl.json"
want_out "the timeline holds cycles 0 to 100000000"
[ "$(sums "$T/tl.json" "$T/r/report.json")" = ok ] || no "$(sums "$T/tl.json" "$T/r/report.json")"
end

begin "timeline: exec's pipeline trace has a slice per instruction"
run "$SFASM" -D CLASS=2 kernels/bench/chains.s -o "$T/chains.sfo"
want_rc 0
run "$SFSIM" exec "$T/chains.sfo" --timeline "$T/ex.json" -q
want_rc 0
want_out "wrote $T/ex.json"
n=$(grep -c '"ph":"b".*"cat":"pipeline"' "$T/ex.json")
[ "$n" = 10 ] || no "$n pipeline slices, the program runs 10 instructions"
python3 -c "import json,sys; json.load(open(sys.argv[1]))" "$T/ex.json" || no "not JSON"
end

begin "timeline: --timeline-window without --timeline is a usage error"
run "$SFSIM" run "${small[@]}" --timeline-window 0:10 -o "$T/x"
want_rc 2
want_err "--timeline-window"
end

begin "timeline: a window that is not FROM:TO is refused"
run "$SFSIM" run "${small[@]}" --timeline "$T/w.json" --timeline-window 10:5 -o "$T/x"
want_rc 1
want_err "the window is empty"
[ ! -e "$T/w.json" ] || no "a timeline was written"
end

begin "timeline: outside detailed mode is a usage error"
run "$SFSIM" run --mode functional "${small[@]}" --timeline "$T/f.json" -o "$T/x"
want_rc 2
want_err "--timeline"
[ ! -e "$T/f.json" ] || no "a timeline was written"
end

begin "timeline: a folder where the file belongs is refused before the run"
mkdir -p "$T/dir"
run "$SFSIM" run "${small[@]}" --timeline "$T/dir" -o "$T/x"
want_rc 4
want_err "$T/dir"
[ ! -e "$T/x/report.json" ] || no "the run went ahead"
end
cli_summary "timeline"
