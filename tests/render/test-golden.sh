#!/bin/sh
# test-golden.sh: the golden-image suite, tests/render/golden-scenes.txt, run by
# `rtspheres check` (one process, one GPU context): each case is rendered and compared with
# golden/NAME.exr by the z test (the difference must be within the samples' noise, so a
# device that flips a few paths passes; docs/regression.md). Goldens catch regressions
# only; test-analytic.sh checks correctness. One check per case, from check's line for it.
# Set RTSPHERES_DIFF_DIR=dir to get the HTML report (reference, new image, difference and
# z-score heat map of every case, failures first) in dir.
#   usage: sh tests/render/test-golden.sh PROGRAM SCRATCH_DIR
here=$(dirname "$0")
. "$here/lib.sh"
report=${RTSPHERES_DIFF_DIR:-}
start=$(date +%s)
"$program" check "$here/golden-scenes.txt" --junit "$scratch/golden.xml" ${report:+--report "$report"} \
    >"$scratch/check.out" 2>"$scratch/check.err"
code=$?
seconds=$(($(date +%s) - start))
if [ "$code" != 0 ] && [ "$code" != 1 ]; then
    fail "golden suite" "rtspheres check exited $code: $(head -c 600 "$scratch/check.err")"
fi
# One line per case: "VERDICT NAME (T s): reason".
grep '^case ' "$here/golden-scenes.txt" >"$scratch/cases"
count=$(wc -l <"$scratch/cases" | tr -d ' ')
while read -r _ name _; do
    line=$(grep -E "^(pass|FAIL|ERROR) +$name \(" "$scratch/check.out")
    case $line in
    pass*) pass "golden $name (${line#*: })" ;;
    "") fail "golden $name" "no line for it in the output of rtspheres check: $(head -c 300 "$scratch/check.out")" ;;
    *) fail "golden $name" "${line#* }${report:+ (report: $report/index.html)}" ;;
    esac
done <"$scratch/cases"
if grep -q "^check: $count passed, 0 failed, 0 errors, 0 not run of $count cases" "$scratch/check.out"; then
    pass "golden suite: $(grep '^check: [0-9]* passed' "$scratch/check.out" | sed 's/^check: //') ($seconds s wall)"
else
    fail "golden suite summary" "$(tail -n 2 "$scratch/check.out" | tr '\n' ' ')"
fi
finish
