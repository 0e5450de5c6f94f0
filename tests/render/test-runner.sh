#!/bin/sh
# test-runner.sh: tests/run.sh itself, on a fake tree of tests made in the scratch
# directory (so the real run never finds them, and the copy of run.sh there runs only
# them): the counts of the Total line, one line for a passing test and the whole output
# of a failing one, V=1, the SKIP list, running tests by name, an unknown name, a crashed
# unit binary, a bad RTSPHERES_TEST_TIMEOUT, tests at once (TEST_JOBS), and the time-out and a stopped run, which
# must leave no process of the test behind.
#   usage: sh tests/render/test-runner.sh PROGRAM SCRATCH_DIR
# PROGRAM is not used: the fake tests render nothing.
. "$(dirname "$0")/lib.sh"

tree=$scratch/tree
rm -rf "$tree"
mkdir -p "$tree/tests/render" "$tree/build/tests"
cp "$(dirname "$0")/../run.sh" "$tree/tests/run.sh"

# fake NAME TEXT: writes an executable fake test NAME (a path in the tree) running TEXT.
fake() {
    printf '#!/bin/sh\n%s\n' "$2" >"$tree/$1"
    chmod +x "$tree/$1"
}
fake tests/render/test-pass.sh 'echo "PASS first"; echo "PASS second"'
fake tests/render/test-fail.sh 'echo "PASS one"; echo "FAIL two: it went wrong"; exit 1'
# A passing test with a skip, that leaves a process running (run.sh kills it).
fake tests/render/test-skip.sh 'echo "PASS x"; echo "SKIP y: no widget here"; sleep 600 &'
# A test that hangs, with a child ignoring SIGTERM and one in a process group of its own
# (as a test's own timeout(1) makes): run.sh must end all three. It first writes its
# session id (field 6 of /proc/PID/stat, the 4th after the parenthesised name) where this
# script finds it after the run.
fake tests/render/test-hang.sh 'sed "s/.*) //" /proc/$$/stat | cut -d" " -f4 >"$(dirname "$0")/../../session"
sh -c "trap \"\" TERM; sleep 600" &
timeout 600 sleep 600 &
echo "PASS before the hang"
sleep 600'
fake build/tests/test_unit_ok 'echo "[==========] Running 3 test(s)."; echo "[  PASSED  ] 3 test(s)."'
fake build/tests/test_unit_fail 'echo "[  PASSED  ] 1 test(s)."; echo "[  FAILED  ] 2 test(s), listed below:"; exit 2'
fake build/tests/test_unit_crash 'echo "[ RUN      ] about to crash"; kill -TERM $$'
# Not a test: not executable (as the compiler's .d files are not).
printf 'not a test\n' >"$tree/build/tests/test_unit_ok.d"

# run_fake OUTPUT VERBOSE [NAME...]: runs the fake tree's run.sh (time-out 2 s, V=VERBOSE,
# none of the settings of the run this script is part of) into OUTPUT; prints its exit status.
run_fake() {
    fake_output=$1 fake_verbose=$2
    shift 2
    (
        cd "$tree" && unset RTSPHERES_SANITIZER_REPORTS &&
            V=$fake_verbose RTSPHERES_TEST_TIMEOUT=2 sh tests/run.sh build fake-program "$@" >"$fake_output" 2>&1
    )
    echo $?
}

# has NAME FILE LINE: one check: FILE holds the line LINE (whole, fixed string).
has() {
    if grep -qxF -e "$3" "$2"; then pass "$1"
    else fail "$1" "no line '$3' in: $(tr '\n' '|' <"$2" | head -c 600)"; fi
}

# lacks NAME FILE TEXT: one check: no line of FILE contains TEXT (a fixed string).
lacks() {
    if grep -qF -e "$3" "$2"; then fail "$1" "'$3' printed: $(tr '\n' '|' <"$2" | head -c 600)"
    else pass "$1"; fi
}

# left_in_session SID: "PID (name)" of each live process of session SID (none for an
# empty SID); the session is field 6 of /proc/PID/stat, the 4th after the name.
left_in_session() {
    [ -z "$1" ] || cat /proc/[0-9]*/stat 2>/dev/null | awk -v sid="$1" '{
        process = $1 " " substr($0, index($0, "("), index($0, ")") - index($0, "(") + 1)
        sub(/^.*\) /, "")
        if ($4 == sid && $1 != "Z") print process
    }'
}

# --- the whole fake suite
all=$scratch/all.out
code=$(run_fake "$all" 0)
if [ "$code" = 1 ]; then pass "run.sh exits 1 when a test failed"; else fail "run.sh exit" "$code, expected 1"; fi
# 3 + 1 (unit) + 2 + 1 + 1 + 1 (render) checks passed; 2 unit + 1 render FAIL lines, a crash
# and a time-out failed; one skip.
has "the Total line counts every check" "$all" "Total: 9 passed, 5 failed, 1 skipped"
if grep -q '^ok   test-pass (2 checks, [0-9]* s)$' "$all"; then pass "a passing test prints one line"
else fail "a passing test prints one line" "$(tr '\n' '|' <"$all" | head -c 600)"; fi
lacks "a passing test's PASS lines are not printed" "$all" "PASS first"
has "a failing test prints its whole output (PASS lines)" "$all" "PASS one"
has "a failing test prints its whole output (FAIL lines)" "$all" "FAIL two: it went wrong"
if grep -q '^FAIL test-fail (1 failed; 2 checks, [0-9]* s)$' "$all"; then pass "a failing test ends with its FAIL line"
else fail "a failing test ends with its FAIL line" "$(grep 'test-fail' "$all" | tr '\n' '|')"; fi
has "skips are listed with their reasons" "$all" "  test-skip: y: no widget here"
if grep -q '^ok   test-skip (1 check, 1 skipped, killed the process it left running, [0-9]* s)$' "$all"; then
    pass "a passing test's skips and left processes are in its line"
else fail "a passing test's skips and left processes are in its line" "$(grep 'test-skip' "$all" | tr '\n' '|')"; fi
if grep -q '^FAIL test_unit_crash (killed by signal 15; 0 checks, [0-9]* s)$' "$all"; then
    pass "a unit binary killed by a signal is a failure"
else fail "a unit binary killed by a signal is a failure" "$(grep 'test_unit_crash' "$all" | tr '\n' '|')"; fi
lacks "a file that is not executable is no test" "$all" "test_unit_ok.d"
has "Failed: names every failed test" "$all" "Failed: test_unit_crash test_unit_fail test-fail test-hang"

# --- the time-out: a FAIL naming it, and no process of the hanging test left
if grep -q '^FAIL test-hang (timed out after 2 s (RTSPHERES_TEST_TIMEOUT), killed; 1 check, killed the [0-9]* processes it left running, [0-9]* s)$' "$all"; then
    pass "a test that runs out of time fails, naming the time-out"
else fail "a test that runs out of time fails, naming the time-out" "$(grep 'test-hang' "$all" | tr '\n' '|')"; fi
session=$(cat "$tree/session" 2>/dev/null || true)
left=$(left_in_session "$session")
if [ -z "$session" ]; then fail "no process of a timed-out test is left" "the hanging test wrote no session id"
elif [ -z "$left" ]; then pass "no process of a timed-out test is left (session $session)"
else fail "no process of a timed-out test is left" "still running: $left"; fi

# --- a run that is itself stopped (SIGTERM) ends the test in flight
rm -f "$tree/session"
(cd "$tree" && unset RTSPHERES_SANITIZER_REPORTS V RTSPHERES_TEST_TIMEOUT &&
    exec sh tests/run.sh build fake-program test-hang >"$scratch/stopped.out" 2>&1) &
runner=$!
tries=0
while [ ! -s "$tree/session" ] && [ "$tries" -lt 100 ]; do
    sleep 0.1
    tries=$((tries + 1))
done
kill -s TERM "$runner"
wait "$runner"
code=$?
session=$(cat "$tree/session" 2>/dev/null || true)
left=$(left_in_session "$session")
if [ "$code" = 130 ] && [ -n "$session" ] && [ -z "$left" ] &&
   grep -qxF "tests/run.sh: interrupted during test-hang, which was ended" "$scratch/stopped.out"; then
    pass "a stopped run ends the test in flight and says so"
else fail "a stopped run ends the test in flight" "exit $code, session '$session', left '$left': $(cat "$scratch/stopped.out")"; fi
# ... and says nothing else, then or a little later: the test's runner (a background
# subshell of run.sh) once went on after the run, reporting into its removed scratch
# directory ("cannot create ...: Directory nonexistent"), after a shell's "Killed".
sleep 0.5
if [ "$(cat "$scratch/stopped.out")" = "tests/run.sh: interrupted during test-hang, which was ended" ]; then
    pass "a stopped run prints that one line"
else fail "a stopped run prints that one line" "$(tr '\n' '|' <"$scratch/stopped.out" | head -c 600)"; fi

# --- V=1, names, unknown names, a bad time-out
verbose=$scratch/verbose.out
code=$(run_fake "$verbose" 1 test-pass)
has "V=1 prints every PASS line" "$verbose" "PASS second"
named=$scratch/named.out
code=$(run_fake "$named" 0 test_unit_ok tests/render/test-pass.sh test-pass)
if [ "$code" = 0 ] && [ "$(grep -c '^ok   ' "$named")" = 2 ] && ! grep -q 'test-fail\|test-hang' "$named"; then
    pass "named tests run alone, each once (a path and .sh are ignored)"
else fail "named tests run alone" "exit $code: $(tr '\n' '|' <"$named" | head -c 600)"; fi
has "the Total line of named tests" "$named" "Total: 5 passed, 0 failed, 0 skipped"
unknown=$scratch/unknown.out
code=$(run_fake "$unknown" 0 test-pass test-nonesuch)
if [ "$code" = 2 ] && grep -qF "there is no test named 'test-nonesuch'" "$unknown" && grep -qx '  test-hang' "$unknown" &&
   grep -qx '  test_unit_ok' "$unknown" && ! grep -q '^ok ' "$unknown"; then
    pass "an unknown name is an error that lists the tests, and nothing runs"
else fail "an unknown name is an error" "exit $code: $(tr '\n' '|' <"$unknown" | head -c 600)"; fi

# --- tests at once (TEST_JOBS): two fake tests that each wait for the other to start pass
# only when both run together; the first ends after the second, yet prints first.
together=$scratch/together
rm -rf "$together"
mkdir -p "$together/tests/render" "$together/build/tests"
cp "$(dirname "$0")/../run.sh" "$together/tests/run.sh"
# meet SELF OTHER DELAY: a fake test that marks itself started, waits up to 5 s for OTHER,
# then sleeps DELAY seconds before its verdict.
meet() {
    printf '#!/bin/sh
d=$(dirname "$0")
: >"$d/%s.started"
i=0
while [ ! -f "$d/%s.started" ] && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
sleep %s
if [ -f "$d/%s.started" ]; then echo "PASS %s met %s"; else echo "FAIL %s: %s never started"; fi
' \
        "$1" "$2" "$3" "$2" "$1" "$2" "$1" "$2" >"$together/tests/render/test-$1.sh"
}
meet a b 1
meet b a 0
# run_together OUTPUT JOBS: the tree's run.sh with TEST_JOBS=JOBS; prints its exit status.
run_together() {
    rm -f "$together"/tests/render/*.started
    (cd "$together" && unset RTSPHERES_SANITIZER_REPORTS V &&
        TEST_JOBS=$2 RTSPHERES_TEST_TIMEOUT=20 sh tests/run.sh build fake-program >"$1" 2>&1)
    echo $?
}
code=$(run_together "$scratch/jobs2.out" 2)
if [ "$code" = 0 ] && grep -qx "Total: 2 passed, 0 failed, 0 skipped" "$scratch/jobs2.out"; then
    pass "TEST_JOBS=2 runs two tests at once"
else fail "TEST_JOBS=2 runs two tests at once" "exit $code: $(tr '\n' '|' <"$scratch/jobs2.out" | head -c 600)"; fi
if [ "$(grep -o '^ok   test-[ab]' "$scratch/jobs2.out" | tr '\n' ' ')" = "ok   test-a ok   test-b " ]; then
    pass "lines keep the list's order when a later test ends first"
else fail "lines keep the list's order" "$(tr '\n' '|' <"$scratch/jobs2.out" | head -c 600)"; fi
code=$(run_together "$scratch/jobs1.out" 1)
if [ "$code" = 1 ] && grep -qF "FAIL a: b never started" "$scratch/jobs1.out"; then
    pass "TEST_JOBS=1 runs one test at a time"
else fail "TEST_JOBS=1 runs one test at a time" "exit $code: $(tr '\n' '|' <"$scratch/jobs1.out" | head -c 600)"; fi
if (cd "$tree" && TEST_JOBS=two sh tests/run.sh build fake-program test-pass >"$scratch/badjobs.out" 2>&1); then
    fail "TEST_JOBS=two is refused" "it ran: $(cat "$scratch/badjobs.out")"
else has "TEST_JOBS=two is refused" "$scratch/badjobs.out" \
    "tests/run.sh: TEST_JOBS wants a whole number of tests at a time, found 'two'"; fi

if (cd "$tree" && RTSPHERES_TEST_TIMEOUT=10s sh tests/run.sh build fake-program test-pass >"$scratch/bad.out" 2>&1); then
    fail "RTSPHERES_TEST_TIMEOUT=10s is refused" "it ran: $(cat "$scratch/bad.out")"
else has "RTSPHERES_TEST_TIMEOUT=10s is refused" "$scratch/bad.out" \
    "tests/run.sh: RTSPHERES_TEST_TIMEOUT wants a whole number of seconds, found '10s'"; fi

finish
