#!/bin/sh
# Runs the tests of rtspheres and ends with one line "Total: N passed, N failed, N
# skipped" (checks; skips are checks this machine cannot run, listed with their reasons
# above it).
#   usage: sh tests/run.sh BUILD_DIR PROGRAM [NAME...]
# Unit tests: each BUILD_DIR/tests/test_* binary (cmocka; its summary lines are counted).
# Render tests: every test-*.sh in the render/ folder beside this script, each given
# PROGRAM and a scratch directory of its own; its "PASS name" / "FAIL name" / "SKIP name"
# lines are counted. NAMEs (test_pack, test-frames; a path or .sh is ignored) run just
# those tests; a NAME that is no test is an error that lists the tests.
#
# A passing test prints one line, "ok   NAME (N checks, T s)"; V=1 prints its whole output
# before that line. A failing test prints its whole output, then "FAIL NAME (why)".
#
# Tests run TEST_JOBS at a time (environment; default the number of cores, `nproc`): most
# of a test's time is single-threaded (process start-up, shader compiles, image files,
# the fuzz build), so a second test fills the core the first leaves idle. Their lines
# come out in the list's order whatever order they end in; TEST_JOBS=1 runs one at a time.
#
# Each test has a time-out: RTSPHERES_TEST_TIMEOUT seconds when set, else 120 s for a unit
# binary and 600 s for a render script (four times that in a sanitizer run, which is
# several times slower). A test that runs out of time is sent SIGTERM, then SIGKILL 5 s
# later, with every process it started, and counts as a failure. Whatever a test leaves
# running when it ends is killed too. So that "every process it started" can be found,
# each test runs in a session of its own, without a terminal (stdin is /dev/null): a
# test cannot ask for a password there (`make test-slurm` can, to install Slurm).
set -u
if [ $# -lt 2 ]; then
    echo "usage: sh tests/run.sh BUILD_DIR PROGRAM [NAME...]" >&2
    exit 2
fi
build=$1
program=$2
shift 2
render_dir=$(dirname "$0")/render
verbose=${V:-0}

unit_seconds=120
render_seconds=600
if [ -n "${RTSPHERES_SANITIZER_REPORTS:-}" ]; then
    unit_seconds=480
    render_seconds=2400
fi
if [ -n "${RTSPHERES_TEST_TIMEOUT:-}" ]; then
    case $RTSPHERES_TEST_TIMEOUT in
    *[!0-9]* | 0*)
        echo "tests/run.sh: RTSPHERES_TEST_TIMEOUT wants a whole number of seconds, found '$RTSPHERES_TEST_TIMEOUT'" >&2
        exit 2
        ;;
    esac
    unit_seconds=$RTSPHERES_TEST_TIMEOUT
    render_seconds=$RTSPHERES_TEST_TIMEOUT
fi

passed=0
failed=0
failures=""
session=""
scratch=$(mktemp -d "${TMPDIR:-/tmp}/rtspheres-tests.XXXXXX") || exit 1
: >"$scratch/skipped"

# session_processes SID: the PIDs of the live (not zombie) processes of session SID, from
# /proc (field 6 of /proc/PID/stat, counted after the command name in parentheses).
session_processes() {
    cat /proc/[0-9]*/stat 2>/dev/null |
        awk -v sid="$1" '{ pid = $1; sub(/^.*\) /, ""); if ($4 == sid && $1 != "Z") print pid }'
}

# end_session SID: kills with SIGKILL every process left in a test's session: its process
# group, and the processes that made groups of their own (a test's own `timeout` does),
# and returns once none is left (at most about 5 s). One round is not enough: a process
# killed by PID may have forked after the list was read (a `timeout` starting its
# command), and a killed process is listed until it has died (CI once saw a `sleep` left
# by the interrupted-run check of tests/render/test-runner.sh that way).
end_session() {
    end_tries=0
    while :; do
        kill -KILL "-$1" 2>/dev/null
        left=$(session_processes "$1")
        [ -n "$left" ] || return 0
        # shellcheck disable=SC2086 # a list of PIDs
        kill -KILL $left 2>/dev/null
        end_tries=$((end_tries + 1))
        [ "$end_tries" -lt 50 ] || return 0
        sleep 0.1
    done
}

# An interrupted run (Ctrl-C, a job killed) ends the tests in flight too: each runs in a
# session of its own, so the terminal's signals do not reach it. Their runners (run_one
# below, background subshells, which ignore SIGINT as every background job of a
# non-interactive shell does) are ended first, so that none goes on after the run to
# report into the scratch directory this removes.
trap 'for file in "$scratch"/*.runner; do [ ! -f "$file" ] || kill -KILL "$(cat "$file")" 2>/dev/null; done
ended=""; sessions=""
for file in "$scratch"/*.log.session; do
    [ -f "$file" ] || continue
    test_name=$(basename "$file" .log.session); ended="${ended:+$ended, }$test_name"
    sessions="$sessions $(cat "$file")"
done
case $ended in *,*) ended=" during $ended, which were ended" ;; ?*) ended=" during $ended, which was ended" ;; esac
echo "tests/run.sh: interrupted$ended" >&2
for sid in $sessions; do end_session "$sid"; done; rm -rf "$scratch"; exit 130' INT TERM HUP
trap 'rm -rf "$scratch"' EXIT

# run_test SECONDS LOG COMMAND...: runs COMMAND as a test (see the top) with its output in
# LOG; sets $status (its exit status, 124 when it ran out of time), $seconds (how long it
# took) and $stray (how many processes it left running, which were killed).
run_test() {
    limit=$1 log=$2
    shift 2
    start=$(date +%s)
    # A background job of a non-interactive shell is never a process group leader, so
    # setsid does not fork: $! is the session (and process group) of the test.
    setsid timeout -k 5 "$limit" "$@" </dev/null >"$log" 2>&1 &
    session=$!
    echo "$session" >"$log.session"
    wait "$session"
    status=$?
    seconds=$(($(date +%s) - start))
    # timeout(1) says 124 for a time-out, or 137 when the test needed the SIGKILL.
    [ "$status" != 137 ] || [ "$seconds" -lt "$limit" ] || status=124
    stray=$(session_processes "$session" | wc -l | tr -d ' ')
    end_session "$session"
    rm -f "$log.session"
    session=""
}

# report NAME N_PASS N_FAIL N_SKIP: adds a test's checks to the totals and prints its line,
# with its log before it when it failed or V=1. A test that ended badly (a time-out, a
# crash, an exit status but no failed check) counts as one failure more, and its line
# says why.
report() {
    name=$1 n_pass=$2 n_fail=$3 n_skip=$4
    checks="$((n_pass + n_fail)) checks"
    [ "$checks" != "1 checks" ] || checks="1 check"
    [ "$n_skip" = 0 ] || checks="$checks, $n_skip skipped"
    case $stray in
    0) ;;
    1) checks="$checks, killed the process it left running" ;;
    *) checks="$checks, killed the $stray processes it left running" ;;
    esac
    why=""
    if [ "$status" = 124 ]; then
        why="timed out after $limit s (RTSPHERES_TEST_TIMEOUT), killed"
    elif [ "$status" != 0 ] && [ "$n_fail" = 0 ]; then
        why="exit $status with no failed check"
        [ "$status" -lt 128 ] || why="killed by signal $((status - 128))"
    fi
    [ -z "$why" ] || n_fail=$((n_fail + 1))
    passed=$((passed + n_pass))
    failed=$((failed + n_fail))
    if [ "$n_fail" != 0 ]; then
        cat "$log"
        echo "FAIL $name (${why:-$n_fail failed}; $checks, $seconds s)"
        failures="$failures $name"
    else
        [ "$verbose" != 1 ] || cat "$log"
        echo "ok   $name ($checks, $seconds s)"
    fi
}

# Every test there is, unit binaries first, as "unit NAME" and "render NAME" lines.
for test in "$build"/tests/test_*; do
    [ -f "$test" ] && [ -x "$test" ] && echo "unit $(basename "$test")"
done >"$scratch/all"
for script in "$render_dir"/test-*.sh; do
    [ -f "$script" ] && echo "render $(basename "$script" .sh)"
done >>"$scratch/all"

# The NAMEs asked for, or every test.
if [ $# = 0 ]; then
    cp "$scratch/all" "$scratch/chosen"
else
    : >"$scratch/chosen"
    for wanted in "$@"; do
        wanted=$(basename "$wanted" .sh)
        line=$(awk -v name="$wanted" '$2 == name' "$scratch/all")
        if [ -z "$line" ]; then
            echo "tests/run.sh: there is no test named '$wanted'; the tests are:" >&2
            sed 's/^[a-z]* /  /' "$scratch/all" >&2
            exit 2
        fi
        grep -qxF "$line" "$scratch/chosen" || echo "$line" >>"$scratch/chosen"
    done
fi

jobs=${TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}
case $jobs in
'' | *[!0-9]* | 0*)
    echo "tests/run.sh: TEST_JOBS wants a whole number of tests at a time, found '$jobs'" >&2
    exit 2
    ;;
esac

# run_one KIND NAME: runs one test (in the background: see start) and leaves what report
# needs in $scratch/NAME.result: status, seconds, stray, passes, failures, skips.
run_one() {
    kind=$1 name=$2
    log="$scratch/$name.log"
    if [ "$kind" = unit ]; then
        # Unit tests make their scratch directories under TMPDIR: here, so that a test
        # killed before its teardown leaves nothing behind either.
        mkdir -p "$scratch/$name.tmp"
        run_test "$unit_seconds" "$log" env TMPDIR="$scratch/$name.tmp" "$build/tests/$name"
        n_pass=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -1)
        n_fail=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -1)
        n_pass=${n_pass:-0} n_fail=${n_fail:-0}
    else
        mkdir -p "$scratch/$name"
        run_test "$render_seconds" "$log" sh "$render_dir/$name.sh" "$program" "$scratch/$name"
        n_pass=$(grep -c '^PASS ' "$log")
        n_fail=$(grep -c '^FAIL ' "$log")
    fi
    # A unit test that skips prints the same "SKIP name: reason" line before cmocka's skip()
    # (tests/unit/support.h, skip_because).
    grep '^SKIP ' "$log" | sed "s/^SKIP /  $name: /" >"$scratch/$name.skipped"
    n_skip=$(grep -c '^SKIP ' "$log")
    # Written whole, then renamed: the main loop takes the file as the sign it is done.
    echo "$status $seconds $stray $n_pass $n_fail $n_skip $limit" >"$scratch/$name.result.tmp"
    mv "$scratch/$name.result.tmp" "$scratch/$name.result"
}

# The tests in order, one "KIND NAME" line each. started counts the tests begun, reported
# those printed (always the first ones of the list, so the lines keep the list's order),
# finished those done but not yet printed (their .result files): a test that ends ahead
# of the next one to print frees its slot at once.
total=$(wc -l <"$scratch/chosen" | tr -d ' ')
started=0
reported=0
while [ "$reported" -lt "$total" ]; do
    finished=$(find "$scratch" -maxdepth 1 -name '*.result' | wc -l)
    while [ "$started" -lt "$total" ] && [ $((started - reported - finished)) -lt "$jobs" ]; do
        started=$((started + 1))
        line=$(sed -n "${started}p" "$scratch/chosen")
        # shellcheck disable=SC2086 # the line is "KIND NAME"
        (run_one $line) &
        echo $! >"$scratch/${line#* }.runner"
    done
    name=$(sed -n "$((reported + 1))p" "$scratch/chosen" | cut -d' ' -f2)
    if [ ! -f "$scratch/$name.result" ]; then
        # POSIX sh has no `wait -n`: look again shortly.
        sleep 0.2
        continue
    fi
    read -r status seconds stray n_pass n_fail n_skip limit <"$scratch/$name.result"
    rm -f "$scratch/$name.result" "$scratch/$name.runner"
    log="$scratch/$name.log"
    [ ! -f "$scratch/$name.skipped" ] || cat "$scratch/$name.skipped" >>"$scratch/skipped"
    report "$name" "$n_pass" "$n_fail" "$n_skip"
    reported=$((reported + 1))
done
wait

# The sanitizer run (make test SAN=1) has the sanitizers write every report to a file in
# $RTSPHERES_SANITIZER_REPORTS: each one fails the run, even when the test that ran the
# command looked only at its output.
if [ -n "${RTSPHERES_SANITIZER_REPORTS:-}" ]; then
    for report in "$RTSPHERES_SANITIZER_REPORTS"/*; do
        [ -f "$report" ] || continue
        echo "FAIL sanitizer report $report:"
        head -n 40 "$report" | sed 's/^/    /'
        failed=$((failed + 1)); failures="$failures sanitizer($(basename "$report"))"
    done
fi

if [ "$passed" = 0 ] && [ "$failed" = 0 ]; then
    echo "tests/run.sh: no tests were found" >&2
    exit 1
fi
[ -z "$failures" ] || echo "Failed:$failures"
# Skips are checks this machine cannot run (no pseudo-terminals, no cgroups, ...): listed
# with their reasons, never counted as passed.
if [ -s "$scratch/skipped" ]; then
    echo "Skipped (the environment cannot run them):"
    cat "$scratch/skipped"
fi
echo "Total: $passed passed, $failed failed, $(wc -l <"$scratch/skipped" | tr -d ' ') skipped"
[ "$failed" = 0 ]
