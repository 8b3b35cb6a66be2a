# tests/cli/lib.sh -- the harness the CLI test scripts share (run.sh, sweep.sh, standalone.sh):
# begin NAME / run CMD... / want_* / no REASON / end, then cli_summary. Sourced after the script
# has set $T (its temporary folder). A case passes when nothing called `no`.

pass=0
fail=0
name=""
failed=0
reasons=""
cmdline=""
rc=0

begin() { name=$1; failed=0; reasons=""; cmdline=""; : >"$T/out"; : >"$T/err"; }

# run CMD ARGS...: stdout to $T/out, stderr to $T/err, status in $rc.
run() {
    cmdline="$*"
    "$@" >"$T/out" 2>"$T/err"
    rc=$?
}

no() { failed=1; reasons="$reasons    - $*"$'\n'; }

want_rc() { [ "$rc" -eq "$1" ] || no "exit status $rc, expected $1"; }
want_out() { grep -qiE -- "$1" "$T/out" || no "stdout does not match /$1/"; }
want_err() { grep -qiE -- "$1" "$T/err" || no "stderr does not match /$1/"; }
want_any() { cat "$T/out" "$T/err" | grep -qiE -- "$1" || no "output does not match /$1/"; }
want_no_err() { [ ! -s "$T/err" ] || no "unexpected stderr"; }

end() {
    if [ "$failed" -eq 0 ]; then
        pass=$((pass + 1))
    else
        fail=$((fail + 1))
        echo "FAIL: $name"
        printf '%s' "$reasons"
        [ -n "$cmdline" ] && echo "    command: $cmdline"
        [ -s "$T/out" ] && sed -n '1,15s/^/    stdout| /p' "$T/out"
        [ -s "$T/err" ] && sed -n '1,15s/^/    stderr| /p' "$T/err"
    fi
}

# cli_summary SUITE: the summary line; the exit status is 0 when every case passed.
cli_summary() {
    echo "$1: $pass passed, $fail failed"
    [ "$fail" -eq 0 ]
}
