#!/bin/sh
# test-valgrind.sh: runs the commands under valgrind's memcheck and fails on any invalid
# read or write, use of uninitialised memory, or definite leak that is not the OpenGL
# stack's own (tests/sanitizers/valgrind.supp): a tiny render (8x8, 1 spp), a render
# of a bad scene, `diff` and `stats`.
#   usage: sh tests/render/test-valgrind.sh PROGRAM SCRATCH_DIR
# The render under valgrind takes most of the time (llvmpipe compiling the tracer shader,
# slowed down some 50 times), so it runs in the background while the other commands run
# one after the other on the second core.
. "$(dirname "$0")/lib.sh"

if ! command -v valgrind >/dev/null 2>&1; then
    fail "valgrind is installed" "valgrind not found; it is listed in .ci/debian-packages: run make deps"
    finish
    exit
fi
# An AddressSanitizer binary (make test SAN=1) reserves terabytes of shadow memory and
# replaces malloc itself: valgrind cannot run it, and ASan checks the same things.
if grep -q __asan_init "$program" 2>/dev/null; then
    echo "SKIP test-valgrind: $program is built with AddressSanitizer (SAN=1), which valgrind cannot run"
    exit 0
fi
# valgrind runs only the instructions the CPUID of the machine lists. Some virtual
# machines execute one they do not list (seen 2026-12-02: rdtscp, in the start-up code of
# libhwy, which OpenImageIO's image libraries load): valgrind then stops every program
# linked with that library with SIGILL before main, ours included. That is the machine,
# not our code, so SKIP, naming the library; a SIGILL in rtspheres' own code still fails
# (the probe only excuses a frame outside $program).
valgrind --tool=none --log-file="$scratch/probe.valgrind" "$program" --version >/dev/null 2>&1
if [ $? = 132 ] && grep -q "Illegal opcode" "$scratch/probe.valgrind"; then
    illegal_in=$(awk '/Illegal opcode/ { getline; sub(/^==[0-9]+== +at [^:]*: */, ""); print; exit }' \
        "$scratch/probe.valgrind")
    case $illegal_in in
    *"$(basename "$program")"*) ;;
    *)
        echo "SKIP test-valgrind: valgrind cannot run programs that load a library of this machine:" \
            "an instruction its CPUID does not list, at $illegal_in ($(valgrind --version))"
        exit 0
        ;;
    esac
fi

# Unloaded drivers keep their names only with --keep-debuginfo (see valgrind.supp).
# Definite leaks are errors; possible and reachable ones are not (a driver's caches).
# Callers stay at valgrind's default of 12: each one more slows every malloc down.
memcheck="valgrind --tool=memcheck --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite
    --keep-debuginfo=yes --suppressions=tests/sanitizers/valgrind.supp"

# run_memcheck NAME COMMAND...: runs PROGRAM COMMAND... under memcheck; keeps its exit
# status in NAME.status and valgrind's report in NAME.valgrind.
run_memcheck() {
    name=$1
    shift
    # shellcheck disable=SC2086 # $memcheck is a command line
    $memcheck --log-file="$scratch/$name.valgrind" "$program" "$@" >"$scratch/$name.stdout" 2>"$scratch/$name.stderr"
    echo $? >"$scratch/$name.status"
}

# check_memcheck NAME EXPECTED_EXIT: PASS when the command exited as expected and
# memcheck found nothing; otherwise FAIL with the first error valgrind reported.
check_memcheck() {
    name=$1 expected=$2
    got=$(cat "$scratch/$name.status" 2>/dev/null || echo none)
    first_error=$(awk '/^==[0-9]+== (Invalid|Conditional|Use of|Syscall|Mismatched|Source and|Argument|.*definitely lost)/ { n = 8 }
                       n > 0 { sub(/^==[0-9]+== */, ""); printf "%s | ", $0; n-- }' "$scratch/$name.valgrind" | head -c 1200)
    if [ "$got" = 99 ]; then
        fail "valgrind $name" "memcheck errors: $first_error"
    elif [ "$got" != "$expected" ]; then
        fail "valgrind $name" "exit $got, expected $expected: $(head -c 300 "$scratch/$name.stderr")"
    elif ! grep -q "ERROR SUMMARY: 0 errors" "$scratch/$name.valgrind"; then
        fail "valgrind $name" "memcheck did not finish cleanly: $(tail -n 3 "$scratch/$name.valgrind")"
    else
        pass "valgrind $name"
    fi
}

printf 'render size 8 8 spp 1 depth 3 seed 3\ncamera from 0 0 1 at 0 0 0\n' >"$scratch/tiny.txt"
printf 'material red lambertian 0.8 0.2 0.1\nmaterial mirror metal 0.9 0.9 0.9 fuzz 0.2\n' >>"$scratch/tiny.txt"
printf 'sphere 0 0 -1 0.5 red\nsphere 0 -100.5 -1 100 mirror\n' >>"$scratch/tiny.txt"
printf 'material m lambertian 1 1 1\nsphere 0 0 0 -1 m\n' >"$scratch/bad.txt"

# llvmpipe: no optimisation passes in LLVM and no rasteriser threads (valgrind runs one
# thread at a time anyway): the same code paths of ours, in half the time.
GALLIVM_PERF=nopt LP_NUM_THREADS=0 run_memcheck render render "$scratch/tiny.txt" -o "$scratch/tiny.exr" --quiet &
render_job=$!

# Images for diff and stats, rendered without valgrind: two seeds, so that diff fails
# and writes its difference image.
"$program" render "$scratch/tiny.txt" -o "$scratch/seed1.exr" --seed 1 --quiet &&
"$program" render "$scratch/tiny.txt" -o "$scratch/seed2.exr" --seed 2 --quiet ||
    fail "native renders for diff and stats" "$program render failed"
run_memcheck diff diff "$scratch/seed1.exr" "$scratch/seed2.exr" --fail 0 --failpercent 0 --diff-out "$scratch/d.png"
check_memcheck diff 1
run_memcheck stats stats "$scratch/seed1.exr" --crop 0,0,4,4
check_memcheck stats 0
run_memcheck bad-scene render "$scratch/bad.txt" -o "$scratch/bad.png" --quiet
check_memcheck bad-scene 2

wait "$render_job"
check_memcheck render 0
if [ -s "$scratch/tiny.exr" ]; then pass "valgrind render wrote its image"
else fail "valgrind render wrote its image" "no $scratch/tiny.exr"; fi

# An adaptive render resumed from its state (render.h, adaptive.h adaptive_resume) and
# stopped again after checks and compacted passes, which writes the state anew: a partial
# made without valgrind first (stopped after two checks: 4 and 8 samples).
adaptive="--spp 64 --noise-threshold 0.2 --min-spp 4 --pass-budget 400"
# shellcheck disable=SC2086 # $adaptive is a list of options
if RTSPHERES_TEST_STOP_AFTER_PASSES=5 "$program" render "$scratch/tiny.txt" -o "$scratch/adaptive.exr" $adaptive \
        --quiet; then
    # shellcheck disable=SC2086
    RTSPHERES_TEST_STOP_AFTER_PASSES=3 GALLIVM_PERF=nopt LP_NUM_THREADS=0 run_memcheck adaptive-resume render \
        "$scratch/tiny.txt" -o "$scratch/adaptive-resumed.exr" $adaptive --resume "$scratch/adaptive.exr" --quiet
    check_memcheck adaptive-resume 0
else fail "valgrind adaptive-resume" "the partial render without valgrind failed"; fi

finish
