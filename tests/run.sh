#!/bin/sh
# Runs every test of rtspheres and ends with one line "Total: N passed, N failed, N
# skipped" (skips: checks this machine cannot run, listed with their reasons above it).
#   usage: tests/run.sh BUILD_DIR PROGRAM
# Unit tests: each build/tests/test_* binary (cmocka; its own summary lines are kept).
# Render tests: every tests/render/test-*.sh, each given PROGRAM and a scratch directory;
# each prints "PASS name" / "FAIL name" lines that are counted here.
set -u
build=$1
program=$2
passed=0
failed=0
failures=""
scratch=$(mktemp -d "${TMPDIR:-/tmp}/rtspheres-tests.XXXXXX")
trap 'rm -rf "$scratch"' EXIT

for test in "$build"/tests/test_*; do
    [ -x "$test" ] || continue
    name=$(basename "$test")
    out="$scratch/$name.log"
    if "$test" >"$out" 2>&1; then status=0; else status=$?; fi
    cat "$out"
    n_pass=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$out" | tail -1)
    n_fail=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$out" | tail -1)
    passed=$((passed + ${n_pass:-0}))
    failed=$((failed + ${n_fail:-0}))
    if [ "$status" != 0 ] && [ -z "$n_fail" ]; then
        failed=$((failed + 1)); failures="$failures $name(crashed:$status)"
    elif [ "$status" != 0 ]; then
        failures="$failures $name"
    fi
done

for script in tests/render/test-*.sh; do
    [ -f "$script" ] || continue
    name=$(basename "$script" .sh)
    mkdir -p "$scratch/$name"
    out="$scratch/$name.log"
    start=$(date +%s)
    if sh "$script" "$program" "$scratch/$name" >"$out" 2>&1; then status=0; else status=$?; fi
    cat "$out"
    grep '^SKIP ' "$out" | sed "s/^SKIP /  $name: /" >>"$scratch/skipped"
    n_pass=$(grep -c '^PASS ' "$out")
    n_fail=$(grep -c '^FAIL ' "$out")
    passed=$((passed + n_pass))
    failed=$((failed + n_fail))
    if [ "$status" != 0 ] && [ "$n_fail" = 0 ]; then
        failed=$((failed + 1)); failures="$failures $name(exit:$status)"
    elif [ "$n_fail" != 0 ]; then
        failures="$failures $name"
    fi
    echo "  ($name took $(( $(date +%s) - start )) s)"
done

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
touch "$scratch/skipped"
echo "Total: $passed passed, $failed failed, $(wc -l <"$scratch/skipped" | tr -d ' ') skipped"
[ "$failed" = 0 ]
