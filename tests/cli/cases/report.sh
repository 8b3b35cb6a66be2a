#!/usr/bin/env bash
# tests/cli/cases/report.sh -- what a run's report says about the run (docs/report.md): stats.txt
# in gem5's form beside report.json in every mode of `sfsim run`, and report.json's "run" object
# (version, commit, the command line as typed, its folder, date, host, threads) with report.txt's
# header block. Tiny renders (8 x 8, 1 spp) of the shipped Cornell box: seconds.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-report.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

version=$(tr -d ' \n\r\t' < VERSION)
TINY=(-s scenes/cornell/scene.ini --set render.width=8 --set render.height=8 --set render.spp=1 --no-progress)

# stats_txt_ok DIR MODE: stats.txt is gem5's form, its numbers are report.json's, value for value.
stats_txt_ok() {
    local f=$1/stats.txt
    [ -s "$f" ] || { no "$2: no stats.txt"; return; }
    head -1 "$f" | grep -qE "^# sfsim $version \(commit ([0-9a-f]{12}(-dirty)?|unknown)\), mode $2;" \
        || no "$2: stats.txt does not open with the version: $(head -1 "$f")"
    grep -qx -- '---------- Begin Simulation Statistics ----------' "$f" || no "$2: no Begin line"
    grep -qx -- '---------- End Simulation Statistics   ----------' "$f" || no "$2: no End line"
    grep -qE '^rays\.total +[0-9]+ +# primary \+ shadow \+ indirect \(rays\)$' "$f" || no "$2: no rays.total line"
    # every line between the markers: name, a number, "# description (unit)"
    local bad
    bad=$(sed -n '/^---------- Begin/,/^---------- End/p' "$f" | grep -vE '^(-{10} (Begin|End) .*|)$' \
          | grep -vE '^[a-z_0-9.:]+ +-?[0-9][0-9.e+-]* +# .* \(.+\)$' | head -3)
    [ -z "$bad" ] || no "$2: lines not in gem5's form: $bad"
    # the same numbers as report.json: each stats.txt value (but the ::totals) is the one at its path
    python3 - "$1" >"$T/cmp" 2>&1 <<'PY' || no "$2: $(head -c 600 "$T/cmp")"
import json, sys
d = sys.argv[1]
rep = json.load(open(d + "/report.json"))
n = 0
for line in open(d + "/stats.txt"):
    p = line.split()
    if len(p) < 3 or p[2] != "#" or p[0].endswith("::total"):
        continue
    v = rep
    for k in p[0].replace("::", ".").split("."):
        v = v[int(k)] if isinstance(v, list) and k.isdigit() else v[{"lo": 0, "hi": 1}[k]] if isinstance(v, list) else v[k]
    v = float(v)   # (a flag: true is 1)
    assert v == float(p[1]), "%s: %s in stats.txt, %r in report.json" % (p[0], p[1], v)
    n += 1
assert n > 5, "only %d statistics" % n
PY
}

for mode in reference functional detailed sampled; do
    begin "sfsim run --mode $mode writes stats.txt beside report.json, the same numbers"
    run "$SFSIM" run --mode "$mode" "${TINY[@]}" -o "$T/$mode" -j 1
    want_rc 0
    stats_txt_ok "$T/$mode" "$mode"
    case $mode in
        detailed|sampled)
            grep -qE '^cycles +[0-9]+ +# simulated cycles' "$T/$mode/stats.txt" || no "no cycles line"
            grep -qE '^stalls::data_dependency +[0-9]+ ' "$T/$mode/stats.txt" || no "no stalls::data_dependency line"
            grep -qE '^stalls::total +[0-9]+ ' "$T/$mode/stats.txt" || no "no stalls::total line" ;;
        *)
            grep -qE '^cycles ' "$T/$mode/stats.txt" && no "a cycles line in $mode mode (report.json: null)" ;;
    esac
    end
done

begin "sampled mode: the interval's bounds are cycles_ci95::lo and ::hi"
grep -qE '^cycles_ci95::lo +[0-9]+ ' "$T/sampled/stats.txt" && grep -qE '^cycles_ci95::hi +[0-9]+ ' "$T/sampled/stats.txt" \
    || no "no cycles_ci95::lo and ::hi"
end

# Arguments a shell must have quoted: a space, a single quote, a dollar sign.
odir="$T/it's a \$dir"
begin "report.json's run object: version, commit, the command line as typed, folder, date, host, threads"
run "$SFSIM" run --mode functional "${TINY[@]}" -o "$odir" -j 2 --set 'render.seed=7'
want_rc 0
python3 - "$odir/report.json" "$PWD" "$(uname -n)" "$version" "$SFSIM" run --mode functional "${TINY[@]}" \
    -o "$odir" -j 2 --set 'render.seed=7' >"$T/cmp" 2>&1 <<'PY' || no "$(head -c 800 "$T/cmp")"
import json, re, shlex, sys
path, cwd, host, version, typed = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:]
r = json.load(open(path))["run"]
assert r["version"] == version, r["version"]
assert re.fullmatch(r"[0-9a-f]{12}(-dirty)?|unknown", r["commit"]), r["commit"]
assert r["argv"] == typed, (r["argv"], typed)
assert shlex.split(r["command"]) == typed, "the command does not paste back: " + r["command"]
assert r["cwd"] == cwd, r["cwd"]
assert r["host"] == host, r["host"]
assert r["threads"] == 2, r["threads"]
assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d[+-]\d\d:\d\d", r["date"]), r["date"]
PY
end

begin "report.txt opens with the same: version, commit, date, host, threads, the command line, the folder"
txt="$odir/report.txt"
sed -n 2p "$txt" | grep -qE "^run +sfsim $version \(commit [^)]+\), started [0-9T:+-]+ on $(uname -n), 2 host threads$" \
    || no "no run line: $(sed -n 2p "$txt")"
cmd=$(sed -n 's/^command      //p' "$txt")
eval "set -- $cmd"
[ "$*" = "$SFSIM run --mode functional ${TINY[*]} -o $odir -j 2 --set render.seed=7" ] && [ "$5" = "-s" ] \
    && [ "${15}" = "$odir" ] || no "the command line does not paste back: $cmd"
sed -n 4p "$txt" | grep -qxF "             in $PWD" || no "no folder line: $(sed -n 4p "$txt")"
end

begin "a kernel failure's report.json says what made the run, and no stats.txt is left"
cp "$T/functional/stats.txt" "$T/detailed/" || no "no stats.txt to leave"
# a kernel that loads from outside scene memory in every tile (tests/cli/run.sh's trap, unconditional)
printf '.include "abi.inc"\nstart: li r1, 0x7FFFFFF0\n ld r2, r1, 0\n halt\n' >"$T/trap.s"
mkdir -p "$T/lib" && cp kernels/lib/abi.inc "$T/lib/"
run "$SFSIM" run --mode functional "${TINY[@]}" -o "$T/detailed" --kernel "$T/trap.s" -j 1
want_rc 3
grep -qE '"status":[[:space:]]+"failed"' "$T/detailed/report.json" 2>/dev/null || no "report.json not marked failed"
grep -qE '"command":[[:space:]]+"[^"]*trap\.s -j 1"' "$T/detailed/report.json" 2>/dev/null || no "the failed report has no command"
[ ! -e "$T/detailed/stats.txt" ] || no "an earlier run's stats.txt is left beside a failed run's report"
end

cli_summary "cli report"
