#!/usr/bin/env bash
# tests/slurm/run.sh -- the sweep's Slurm path against a real Slurm (docs/sweep.md, "Beyond one
# machine"): starts munged, slurmctld and slurmd on localhost as a one-node cluster whose every
# file (slurm.conf, munge key and socket, state, spool, pid files, logs) lives in a fresh temporary
# folder, runs tests/slurm/sweep.ini once locally and once as the array job of `sfsim sweep --emit
# slurm` submitted with sbatch, checks every array task, runs `sfsim merge`, and compares the two
# sweep.csv files (every column but host_seconds) and the points' frames. Then it stops the
# daemons. `make test-slurm` installs the packages (scripts/deps.sh slurm) and builds bin/sfsim.
#
# Must not: write outside its temporary folder (nothing in /etc, no systemd), leave a daemon or a
# job step running, or skip: when Slurm cannot run here the test fails and says why. Exit status:
# 0 when everything matched, 1 on a failure (the reason, and the daemons' logs when they ran),
# 2 when it cannot start at all, 128 + the signal when interrupted.
set -u

cd "$(dirname "$0")/../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
SWEEP=tests/slurm/sweep.ini
TINY=(--set render.width=16 --set render.height=16 --set render.spp=1)
TIMEOUT=${SFSIM_SLURM_TIMEOUT:-300}   # seconds the array job may take (it takes about 10)
START=$SECONDS

T=""
munged_pid="" ctld_pid="" slurmd_pid=""
job=""
cluster_up=0

# A Slurm around this script (CI inside a job) must not leak into the private cluster's commands.
for v in $(compgen -e | grep '^SLURM_'); do unset "$v"; done

logs() {
    [ -n "$T" ] || return
    for f in munged.log munged.stderr slurmctld.log slurmctld.stderr slurmd.log slurmd.stderr; do
        [ -s "$T/$f" ] || continue
        echo "---- $f (last 25 lines)" >&2
        tail -n 25 "$T/$f" >&2
    done
}

fail() {
    echo "slurm: FAILED: $*" >&2
    [ "$cluster_up" -eq 1 ] && logs
    exit 1
}

# stop PID NAME: SIGTERM, up to 15 s for it to end, then SIGKILL. Only our own children.
stop() {
    local pid=$1 i
    [ -n "$pid" ] || return 0
    kill -TERM "$pid" 2>/dev/null || { wait "$pid" 2>/dev/null; return 0; }
    for ((i = 0; i < 150; i++)); do
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    if kill -0 "$pid" 2>/dev/null; then
        echo "slurm: $2 (pid $pid) did not stop on SIGTERM: killed" >&2
        kill -KILL "$pid" 2>/dev/null
    fi
    wait "$pid" 2>/dev/null
    return 0
}

cleanup() {
    local rc=$? p i
    trap '' INT TERM HUP
    if [ -n "$job" ] && [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
        scancel "$job" 2>/dev/null
        for ((i = 0; i < 100; i++)); do
            [ -z "$(squeue -h -j "$job" -o %i 2>/dev/null)" ] && break
            sleep 0.1
        done
    fi
    stop "$slurmd_pid" slurmd
    stop "$ctld_pid" slurmctld
    stop "$munged_pid" munged
    # The job steps (slurmstepd and the tasks) detach from slurmd: any still running carries this
    # cluster's SLURM_CONF in its environment, which names them, and no other process, exactly.
    if [ -n "$T" ]; then
        export -n SLURM_CONF   # so that the tr and grep below do not carry it
        for p in /proc/[0-9]*; do
            [ "${p#/proc/}" = "$$" ] && continue
            tr '\0' '\n' 2>/dev/null <"$p/environ" | grep -qxF "SLURM_CONF=$T/slurm.conf" || continue
            echo "slurm: a job process was still running (pid ${p#/proc/}): killed" >&2
            kill -KILL "${p#/proc/}" 2>/dev/null
        done
        rm -rf "$T"
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP

# ---- what the test needs ---------------------------------------------------------------------

[ -x "$SFSIM" ] || { echo "slurm: $SFSIM is missing (run make, or make test-slurm)" >&2; exit 2; }
missing=""
for c in munged munge unmunge slurmctld slurmd sbatch squeue sinfo scontrol scancel; do
    command -v "$c" >/dev/null || missing="$missing $c"
done
[ -z "$missing" ] || fail "not installed:$missing (bash scripts/deps.sh slurm installs them)"
# slurmd starts each task as the submitting user, which only root can do.
[ "$(id -u)" -eq 0 ] || fail "slurmd must run as root to start jobs, and this runs as $(id -un)"

# munged insists that every folder above its socket is searchable by all.
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-slurm.XXXXXX") || exit 2
chmod 755 "$T" && mkdir -m 755 "$T/sock" && mkdir -m 700 "$T/munge" "$T/state" "$T/spool" || exit 2

# ---- munge: its own key and socket -----------------------------------------------------------

dd if=/dev/urandom of="$T/munge/munge.key" bs=1024 count=1 status=none && chmod 400 "$T/munge/munge.key" ||
    fail "cannot write a munge key in $T"
SOCK=$T/sock/munge.socket
# munged.log's "Unauthorized credential for client UID=0" lines are harmless: Slurm 22.05's
# slurmstepd checks a credential it may not decode (a check Slurm's NEWS says later versions skip).
cluster_up=1
munged -F --socket="$SOCK" --key-file="$T/munge/munge.key" --pid-file="$T/munge/munged.pid" \
    --log-file="$T/munged.log" --seed-file="$T/munge/munged.seed" >"$T/munged.stderr" 2>&1 &
munged_pid=$!
for ((i = 0; i < 100; i++)); do
    [ -S "$SOCK" ] && break
    kill -0 "$munged_pid" 2>/dev/null || fail "munged exited at start"
    sleep 0.1
done
munge -n -S "$SOCK" 2>"$T/munge.err" | unmunge -S "$SOCK" >/dev/null 2>>"$T/munge.err" ||
    fail "munged does not answer on $SOCK: $(cat "$T/munge.err")"

# ---- slurm.conf: one node, this machine, as slurmd -C describes it ---------------------------

# port_free P: nothing listens on 127.0.0.1:P.
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
port=16817
while ! port_free "$port" || ! port_free $((port + 1)); do
    port=$((port + 2))
    [ "$port" -lt 16917 ] || fail "no two free ports in 16817-16916 for slurmctld and slurmd"
done
node=$(slurmd -C 2>"$T/slurmd-C.err" | head -1 | sed -E 's/ *UpTime=.*//')
case "$node" in
NodeName=*" CPUs="*) ;;
*) fail "slurmd -C does not describe this node: $node $(cat "$T/slurmd-C.err")" ;;
esac
name=$(echo "$node" | sed -E 's/^NodeName=([^ ]+).*/\1/')
: >"$T/plugstack.conf"
cat >"$T/slurm.conf" <<EOF
# Written by tests/slurm/run.sh: a one-node cluster on this machine, every file in $T.
ClusterName=sfsimtest
SlurmctldHost=localhost
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCK
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
PlugStackConfig=$T/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MinJobAge=3600
KillWait=5
SlurmctldDebug=info
SlurmdDebug=info
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=sfsim Nodes=$name Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$T/slurm.conf

# ---- the daemons, in the foreground of their own background jobs -----------------------------

slurmctld -D -i >"$T/slurmctld.stderr" 2>&1 &
ctld_pid=$!
slurmd -D -N "$name" >"$T/slurmd.stderr" 2>&1 &
slurmd_pid=$!
state=""
for ((i = 0; i < 600; i++)); do
    kill -0 "$ctld_pid" 2>/dev/null || fail "slurmctld exited at start"
    kill -0 "$slurmd_pid" 2>/dev/null || fail "slurmd exited at start"
    state=$(sinfo -h -N -n "$name" -o %T 2>/dev/null)
    [ "$state" = idle ] && break
    sleep 0.1
done
[ "$state" = idle ] || fail "node $name is not idle after 60 s (sinfo: ${state:-no answer})"

# ---- the same sweep, locally and as an array job ---------------------------------------------

# The Slurm sweep's folder has a space and a '%' in its name: the #SBATCH --output line must quote
# the one and write the other %% (Slurm expands %x there, and every task failed when it did not).
L=$T/local
S="$T/slurm 100%x"
"$SFSIM" sweep --sweep "$SWEEP" -o "$L" -j 2 "${TINY[@]}" >"$T/local.log" 2>&1 ||
    fail "the local sweep failed: $(tail -3 "$T/local.log")"
"$SFSIM" sweep --sweep "$SWEEP" -o "$S" "${TINY[@]}" --emit slurm >"$T/emit.log" 2>&1 ||
    fail "sfsim sweep --emit slurm failed: $(tail -3 "$T/emit.log")"
npoints=$(($(wc -l <"$L/sweep.csv") - 1))
[ "$npoints" -ge 2 ] || fail "the local sweep.csv has $npoints rows"

job=$(cd "$T" && sbatch --parsable "$S/sweep.slurm" 2>"$T/sbatch.err") ||
    fail "sbatch refused $S/sweep.slurm: $(cat "$T/sbatch.err")"
job=${job%%;*}
[[ "$job" =~ ^[0-9]+$ ]] || fail "sbatch printed no job id: '$job' $(cat "$T/sbatch.err")"
waited=0
while :; do
    left=$(squeue -h -j "$job" -o %i 2>"$T/squeue.err") || fail "squeue failed: $(cat "$T/squeue.err")"
    [ -z "$left" ] && break
    [ "$waited" -lt $((TIMEOUT * 2)) ] || fail "array job $job still has tasks after ${TIMEOUT} s: ${left//$'\n'/ }"
    sleep 0.5
    waited=$((waited + 1))
done

# Every task ran, ended COMPLETED with exit code 0, marked its point done and logged no error.
scontrol -o show job "$job" >"$T/tasks" 2>&1 || fail "scontrol show job $job: $(cat "$T/tasks")"
ntasks=$(grep -c "ArrayJobId=$job " "$T/tasks")
[ "$ntasks" -eq "$npoints" ] || fail "array job $job has $ntasks tasks, the sweep $npoints points"
bad=$(grep -v 'JobState=COMPLETED .*ExitCode=0:0 ' "$T/tasks" | grep -oE 'ArrayTaskId=[0-9]+|JobState=[A-Z_]+|ExitCode=[0-9:]+' | tr '\n' ' ')
[ -z "$bad" ] || fail "array tasks did not all complete with exit code 0: $bad"
for ((k = 0; k < npoints; k++)); do
    out="$S/points/slurm-${job}_$k.out"
    [ -f "$out" ] || fail "task $k wrote no $out"
    grep -qiE 'error|fail' "$out" && fail "task $k's log says: $(grep -iE 'error|fail' "$out" | head -3)"
    grep -q "point $k done" "$out" || fail "task $k's log does not say it ran point $k: $(tail -3 "$out")"
    dir=$(printf '%s/points/%03d' "$S" "$k")
    [ -f "$dir/done" ] || fail "point $k has no done marker after its task"
    # frame.exr carries its capture date, so its pixels are compared, not its bytes.
    "$SFSIM" compare "$dir/frame.exr" "$(printf '%s/points/%03d/frame.exr' "$L" "$k")" >"$T/compare" 2>&1 &&
        grep -qE '^ *max diff +0$' "$T/compare" || fail "point $k: frame.exr differs from the local run's: $(cat "$T/compare")"
done

# ---- merge, and the CSV against the local one ------------------------------------------------

"$SFSIM" merge "$S" >"$T/merge.log" 2>&1 || fail "sfsim merge exited $?: $(tail -3 "$T/merge.log")"
grep -q "$npoints done, 0 failed, 0 unfinished" "$T/merge.log" || fail "merge says: $(head -1 "$T/merge.log")"

# Fields are split as CSV (quotes around a field holding commas or quotes, doubled quotes inside);
# host_seconds, the run's wall time, is the one column that may differ (docs/sweep.md, sweep.csv).
diff=$(awk -v skip=host_seconds '
function split_csv(line, f,    n, i, c, q, cur) {
    n = 0; cur = ""; q = 0
    for (i = 1; i <= length(line); i++) {
        c = substr(line, i, 1)
        if (q) {
            if (c == "\"" && substr(line, i + 1, 1) == "\"") { cur = cur c; i++ }
            else if (c == "\"") q = 0
            else cur = cur c
        } else if (c == "\"") q = 1
        else if (c == ",") { f[++n] = cur; cur = "" }
        else cur = cur c
    }
    f[++n] = cur
    return n
}
FNR == NR { local[FNR] = $0; nlocal = FNR; next }
{
    nslurm = FNR
    if (FNR > nlocal) { print "the Slurm sweep.csv has more rows than the local one (" nlocal - 1 ")"; found = 1; exit }
    nl = split_csv(local[FNR], a); ns = split_csv($0, b)
    if (FNR == 1 && $0 != local[1]) { print "the headers differ: local " local[1] ", Slurm " $0; found = 1; exit }
    if (FNR == 1) { for (i = 1; i <= nl; i++) name[i] = a[i] }
    if (nl != ns) { print "row " FNR - 1 ": " nl " columns locally, " ns " from Slurm"; found = 1; exit }
    for (i = 1; i <= nl; i++) {
        if (name[i] == skip || a[i] == b[i]) continue
        print "row " FNR - 1 " (point " a[1] "), column " name[i] ": local \"" a[i] "\", Slurm \"" b[i] "\""
        found = 1
        exit
    }
}
END { if (!found && nslurm < nlocal) print "the Slurm sweep.csv has " nslurm - 1 " rows, the local one " nlocal - 1 }
' "$L/sweep.csv" "$S/sweep.csv" 2>&1) || fail "cannot compare the two sweep.csv files: $diff"
[ -z "$diff" ] || fail "sweep.csv differs: $diff"
head -1 "$L/sweep.csv" | tr , '\n' | grep -qx host_seconds || fail "sweep.csv has no host_seconds column to leave aside"

echo "slurm: $npoints points, array job $job on a one-node Slurm: every task completed, merge's sweep.csv" \
    "equals the local run's (host_seconds aside), frames identical, ok ($((SECONDS - START)) s)"
