#!/bin/sh
# test-check.sh: `rtspheres check SUITE`: its exit codes (0 all pass, 1 some fail, 2 a bad
# suite), the case lines and summary, bad suite files (each a message naming
# file:line:column, exit 2, nothing rendered), a missing golden (a failure of that case,
# not of the run), includes and defaults, the JUnit XML (parsed: elements, counts,
# attributes), --update and --update-all on a copy of goldens, --jobs 2 giving the same
# verdicts. Small renders (64x36, 16 spp) of scenes/materials/lambertian.txt.
#   usage: sh tests/render/test-check.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
root=$(pwd)
case $program in /*) ;; *) program=$root/$program ;; esac   # the checks run in $work
work=$scratch/suite
rm -rf "$work"
mkdir -p "$work/golden" "$work/more"
cp scenes/materials/lambertian.txt "$work/scene.txt"
# The red ball 10% brighter: at this size and noise a change the z test must see.
sed 's/^material red lambertian 0.8 0.25 0.2/material red lambertian 0.88 0.275 0.22/' "$work/scene.txt" \
    >"$work/brighter.txt"
small="--size 64x36 --spp 16"
# shellcheck disable=SC2086
"$program" render "$work/scene.txt" -o "$work/golden/base.exr" $small --seed 1 --variance --quiet

# run_check NAME SUITE [OPTIONS...]: runs check in $work with stdout/stderr in
# $scratch/out and $scratch/err, its exit code in $code.
run_check() {
    lib_suite=$1
    shift
    (cd "$work" && "$program" check "$lib_suite" "$@") >"$scratch/out" 2>"$scratch/err"
    code=$?
}

# ---- a suite that passes, with an include, defaults and both tests ------------------------
cat >"$work/good.txt" <<EOF
# a suite: cases at 64x36, 16 spp
render $small --seed 1
case same scene.txt golden/base.exr
case other-seed "scene.txt" golden/base.exr --seed 2   # a comment after the case
case exact scene.txt golden/base.exr compare --test idiff --fail 0 --failpercent 0
include "more/inner.txt"
EOF
cat >"$work/more/inner.txt" <<EOF
root ..
case from-include scene.txt golden/base.exr
EOF
run_check good.txt --junit "$scratch/good.xml"
if [ "$code" = 0 ] && grep -q '^check: 4 passed, 0 failed, 0 errors, 0 not run of 4 cases' "$scratch/out" \
    && [ "$(grep -c '^pass ' "$scratch/out")" = 4 ]; then
    pass "check: four passing cases (same seed, another seed, idiff exactness, an included file's): exit 0"
else
    fail "check of a passing suite" "exit $code: $(tr '\n' '|' <"$scratch/out") $(head -c 300 "$scratch/err")"
fi
if grep -q '^pass  exact (.*idiff: 0.00% of pixels over 0' "$scratch/out"; then
    pass "check: a case's compare part picks the idiff test with its own thresholds"
else fail "check: compare --test idiff" "$(grep exact "$scratch/out")"; fi

# ---- failures: a changed scene, a missing golden, a render error ---------------------------
cat >"$work/failing.txt" <<EOF
render $small --seed 1
case same scene.txt golden/base.exr
case brighter brighter.txt golden/base.exr
case missing scene.txt golden/missing.exr
case broken no-such-scene.txt golden/base.exr
EOF
run_check failing.txt --junit "$scratch/failing.xml"
if [ "$code" = 1 ] && grep -q '^check: 1 passed, 2 failed, 1 errors, 0 not run of 4 cases' "$scratch/out"; then
    pass "check: a changed scene and a missing golden fail, a missing scene is an error, the rest passes: exit 1"
else
    fail "check of a failing suite" "exit $code: $(tr '\n' '|' <"$scratch/out") $(head -c 300 "$scratch/err")"
fi
if grep -q "^FAIL  missing (.*the golden 'golden/missing.exr' is missing (\`rtspheres check --update\` writes it)" \
    "$scratch/out"; then
    pass "check: a missing golden is that case's failure, saying what writes it"
else fail "check: missing golden message" "$(grep missing "$scratch/out")"; fi
if grep -q "^ERROR broken (.*the render failed: SCENE: cannot read 'no-such-scene.txt'" "$scratch/out"; then
    pass "check: a scene that cannot be read is that case's error, with the parser's message"
else fail "check: render error message" "$(grep broken "$scratch/out")"; fi
if grep -q '^FAIL  brighter (.*z: .* over |z|' "$scratch/out"; then
    pass "check: the changed scene fails the z test, with the failing scale in its line"
else fail "check: changed scene" "$(grep brighter "$scratch/out")"; fi

# ---- the JUnit file, parsed ----------------------------------------------------------------
# junit_problem FILE TESTS FAILURES ERRORS SKIPPED NAME:KIND...: prints what is wrong with the
# JUnit file, or nothing: <testsuites> holding one <testsuite> with those counts, both with
# a time; one <testcase name classname file line time> per NAME in order, with a <failure>
# or <error> (with a message and a type) or neither (KIND failure, error or pass).
junit_problem() {
    python3 - "$@" <<'PYTHON'
import sys, xml.etree.ElementTree as ET
path, tests, failures, errors, skipped = sys.argv[1:6]
cases = [item.split(':') for item in sys.argv[6:]]
try:
    root = ET.parse(path).getroot()
except Exception as e:
    print('does not parse: %s' % e); sys.exit()
counts = {'tests': tests, 'failures': failures, 'errors': errors, 'skipped': skipped}
problems = []
if root.tag != 'testsuites':
    problems.append('root is <%s>' % root.tag)
suites = root.findall('testsuite')
if len(suites) != 1:
    problems.append('%d <testsuite> elements' % len(suites))
for element in [root] + suites:
    for key, value in counts.items():
        if element.get(key) != value:
            problems.append('<%s> %s="%s", expected %s' % (element.tag, key, element.get(key), value))
    try:
        float(element.get('time'))
    except (TypeError, ValueError):
        problems.append('<%s> has no time' % element.tag)
testcases = suites[0].findall('testcase') if suites else []
if [c.get('name') for c in testcases] != [name for name, _ in cases]:
    problems.append('test cases %s' % [c.get('name') for c in testcases])
for case, (name, kind) in zip(testcases, cases):
    for key in ('classname', 'file', 'line', 'time'):
        if not case.get(key):
            problems.append('%s lacks %s' % (name, key))
    found = [child.tag for child in case if child.tag in ('failure', 'error', 'skipped')]
    expected = [] if kind == 'pass' else [kind]
    if found != expected:
        problems.append('%s has %s, expected %s' % (name, found, expected))
    for child in case:
        if child.tag in ('failure', 'error') and not (child.get('message') and child.get('type')):
            problems.append('%s: <%s> without message or type' % (name, child.tag))
if suites and not suites[0].get('timestamp'):
    problems.append('no timestamp')
print('; '.join(problems))
PYTHON
}
if ! command -v python3 >/dev/null 2>&1; then
    echo "SKIP check: JUnit structure: python3 is not installed (make deps installs it)"
else
    problem=$(junit_problem "$scratch/good.xml" 4 0 0 0 same:pass other-seed:pass exact:pass from-include:pass)
    if [ -z "$problem" ]; then pass "check --junit: a passing run's JUnit XML has the elements, counts and attributes"
    else fail "check --junit (passing)" "$problem"; fi
    problem=$(junit_problem "$scratch/failing.xml" 4 2 1 0 same:pass brighter:failure missing:failure broken:error)
    if [ -z "$problem" ]; then pass "check --junit: failures and errors are <failure> and <error> with message and type"
    else fail "check --junit (failing)" "$problem"; fi
    if python3 -c "import sys, xml.etree.ElementTree as ET
f = ET.parse(sys.argv[1]).getroot().find('testsuite/testcase[@name=\"brighter\"]/failure')
sys.exit(0 if 'blocks' in f.get('message') and 'pixel z-scores' in f.text and 'golden:' in f.text else 1)" \
        "$scratch/failing.xml"; then
        pass "check --junit: a failure's message is the reason, its text the metrics"
    else fail "check --junit failure text" "$(grep -A3 'name="brighter"' "$scratch/failing.xml" | head -c 400)"; fi
fi

# ---- --jobs 2: the same verdicts ----------------------------------------------------------
run_check failing.txt --jobs 2 --junit "$scratch/jobs.xml"
if [ "$code" = 1 ] && grep -q '^check: 1 passed, 2 failed, 1 errors, 0 not run of 4 cases' "$scratch/out" \
    && grep -q '4 cases, 2 jobs' "$scratch/out"; then
    pass "check --jobs 2: the same verdicts from two worker processes"
else fail "check --jobs 2" "exit $code: $(tr '\n' '|' <"$scratch/out")"; fi

# ---- bad suites: exit 2 with file:line:column, nothing rendered ---------------------------
# bad_suite NAME PATTERN TEXT: a suite of TEXT is refused with a message matching PATTERN.
bad_suite() {
    printf '%s\n' "$3" >"$work/bad.txt"
    rm -rf "$work/report"
    run_check bad.txt --report report
    if [ "$code" != 2 ]; then
        fail "check refuses $1" "exit $code, expected 2: $(tr '\n' '|' <"$scratch/out") $(cat "$scratch/err")"
    elif ! grep -qE -e "$2" "$scratch/err"; then
        fail "check refuses $1" "stderr lacks /$2/: $(cat "$scratch/err")"
    elif [ -d "$work/report/cases" ]; then
        fail "check refuses $1" "it went on to render"
    else
        pass "check refuses $1 ($(head -c 120 "$scratch/err"))"
    fi
}
bad_suite "a duplicate name" "^bad.txt:2:6: case 'a' is already defined at bad.txt:1$" \
    "case a scene.txt golden/base.exr
case a scene.txt golden/other.exr"
bad_suite "an unknown render option" "^bad.txt:1:34: unknown render option '--bogus'$" \
    "case a scene.txt golden/base.exr --bogus 3"
bad_suite "a bad render option value" "^bad.txt:1:41: --size wants WIDTHxHEIGHT.*not '3x'$" \
    "case a scene.txt golden/base.exr --size 3x"
bad_suite "a render option without its value" "^bad.txt:1:34: --spp needs a value$" \
    "case a scene.txt golden/base.exr --spp"
bad_suite "an unknown comparison option" "^bad.txt:1:42: unknown comparison option '--bogus'$" \
    "case a scene.txt golden/base.exr compare --bogus 1"
bad_suite "an idiff option with the z test" "^bad.txt:2:42: --fail is an option of --test idiff, not of --test z$" \
    "compare --test z
case a scene.txt golden/base.exr compare --fail 0.1"
bad_suite "an output option" "^bad.txt:1:34: -o: a case's output is chosen by check" \
    "case a scene.txt golden/base.exr -o x.exr"
bad_suite "a case without a golden" "^bad.txt:1:17: expected the case's golden image after the scene file$" \
    "case a scene.txt"
bad_suite "a name that is no file name" "^bad.txt:1:6: a case's name is 1 to 127 letters.*not 'a/b'$" \
    "case a/b scene.txt golden/base.exr"
bad_suite "an unknown statement" "^bad.txt:1:1: unknown statement 'cases' \(expected case, render, compare, root or include\)$" \
    "cases a scene.txt golden/base.exr"
bad_suite "an include cycle" "^bad.txt:1:1: include cycle: bad.txt -> bad.txt$" 'include "bad.txt"'
bad_suite "a missing include" "^bad.txt:2:1: cannot read included file 'nope.txt'" \
    'case a scene.txt golden/base.exr
include "nope.txt"'
bad_suite "an unterminated quote" "^bad.txt:1:8: unterminated string" 'case a "scene.txt golden/base.exr'
bad_suite "a suite without cases" "^rtspheres check: SUITE: 'bad.txt' has no case" "# nothing here"
bad_suite "a job rule (--shard-by without --shard)" "^bad.txt:1: case 'a': --shard-by tiles does nothing without --shard I/N$" \
    "case a scene.txt golden/base.exr --shard-by tiles"
bad_suite "a denoised case under the z test" "^bad.txt:1: case 'a': --denoise and --blur change the noise" \
    "case a scene.txt golden/base.exr --denoise"
expect_exit "check: a suite file that does not exist is exit 2" 2 "^rtspheres check: SUITE: cannot read 'no-such.txt'" \
    "$program" check no-such.txt
expect_exit "check: two suites are a usage error" 2 "expected one suite file, got 2" "$program" check a b
expect_exit "check: --jobs 0 is refused" 2 "--jobs wants a whole number from 1 to 64, not '0'" \
    "$program" check "$work/good.txt" --jobs 0
expect_exit "check: --update with --update-all is refused" 2 "give one" \
    "$program" check "$work/good.txt" --update --update-all

# ---- --update and --update-all on a copy of the goldens ------------------------------------
mkdir -p "$work/copy"
cp "$work/golden/base.exr" "$work/copy/a.exr"
cp "$work/golden/base.exr" "$work/copy/b.exr"
cat >"$work/update.txt" <<EOF
render $small --seed 1
case a scene.txt copy/a.exr
case b brighter.txt copy/b.exr
case c scene.txt copy/c.exr
EOF
before_a=$(cksum <"$work/copy/a.exr")
run_check update.txt --update
if [ "$code" = 0 ] && grep -q '^updated b: copy/b.exr$' "$scratch/out" && grep -q '^updated c: copy/c.exr$' "$scratch/out" \
    && grep -q '^check: rewrote 2 goldens$' "$scratch/out" && [ "$(cksum <"$work/copy/a.exr")" = "$before_a" ]; then
    pass "check --update: rewrites the failing and the missing golden, says which, leaves the passing one"
else fail "check --update" "exit $code: $(tr '\n' '|' <"$scratch/out") $(head -c 300 "$scratch/err")"; fi
run_check update.txt
if [ "$code" = 0 ]; then pass "check after --update: every case passes"
else fail "check after --update" "exit $code: $(tr '\n' '|' <"$scratch/out")"; fi
if "$program" stats "$work/copy/c.exr" | grep -q '^channel variance.R:'; then
    pass "check --update: a new golden has the variance layers"
else fail "check --update variance layers" "$("$program" stats "$work/copy/c.exr" | head -c 300)"; fi
run_check update.txt --update-all
if [ "$code" = 0 ] && grep -q '^check: rewrote 3 goldens$' "$scratch/out"; then
    pass "check --update-all: rewrites every golden"
else fail "check --update-all" "exit $code: $(tr '\n' '|' <"$scratch/out")"; fi
ls -A "$work/copy" | grep -v '\.exr$' >"$scratch/left"
if [ -s "$scratch/left" ]; then fail "check --update leaves no temporary file" "$(cat "$scratch/left")"
else pass "check --update leaves no temporary file beside the goldens"; fi
# ---- a stop: SIGINT ends the render in flight, the rest is not run ------------------------
{
    echo "render --size 160x90 --spp 128"
    for i in 1 2 3 4 5 6; do echo "case slow-$i $root/scenes/weekend.txt golden/none.exr"; done
} >"$work/slow.txt"
(cd "$work" && exec "$program" check slow.txt --junit "$scratch/slow.xml") >"$scratch/slow.out" 2>&1 &
checker=$!
waited=0
while ! grep -q '^FAIL  slow-1 ' "$scratch/slow.out" && [ "$waited" -lt 600 ]; do
    sleep 0.1
    waited=$((waited + 1))
done
kill -INT "$checker"
wait "$checker"
code=$?
not_run=$(sed -n 's/^check: .* errors, \([0-9]*\) not run of 6 cases.*/\1/p' "$scratch/slow.out")
skipped=$(grep -c '<skipped ' "$scratch/slow.xml" 2>/dev/null)
if [ "$code" = 1 ] && [ "${not_run:-0}" -ge 1 ] && [ "$skipped" = "$not_run" ] \
    && grep -q '^ERROR slow-2 (.*interrupted: the run was stopped during this render' "$scratch/slow.out"; then
    pass "check: SIGINT stops the render in flight (an error), leaves $not_run cases not run (<skipped/> in JUnit), exit 1"
else fail "check interrupted" "exit $code, skipped $skipped: $(tr '\n' '|' <"$scratch/slow.out")"; fi
cd "$root" || exit 1
finish
