#!/bin/sh
# test-fuzz-smoke.sh: a short fuzzing run in every test run. Builds the libFuzzer
# harnesses of tests/fuzz/ (make fuzz-build: clang, into build-fuzz/), replays every
# input that once crashed one (tests/fuzz/regressions/), then fuzzes each harness for
# 10 s from the seed corpus plus fresh mutations; any crash, sanitizer report, hang or
# broken contract fails. `make fuzz` is the long run (FUZZ_SECONDS per harness).
#   usage: sh tests/render/test-fuzz-smoke.sh PROGRAM SCRATCH_DIR
# PROGRAM is unused: the harnesses call the core library directly.
. "$(dirname "$0")/lib.sh"

fuzz_cc=${FUZZ_CC:-clang}
seconds=${FUZZ_SMOKE_SECONDS:-10}

# The toolchain is a dependency like any other (CI installs it from .ci/debian-packages):
# missing, it is a failure that says what to install, never a silent skip.
if ! command -v "$fuzz_cc" >/dev/null 2>&1; then
    fail "fuzz toolchain" "$fuzz_cc not found: install clang and libclang-rt-14-dev (listed in .ci/debian-packages; run make deps)"
    finish
    exit
fi
printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' >"$scratch/probe.c"
if ! "$fuzz_cc" -fsanitize=fuzzer,address,undefined "$scratch/probe.c" -o "$scratch/probe" 2>"$scratch/probe.log"; then
    fail "fuzz toolchain" "$fuzz_cc cannot link a libFuzzer program (is libclang-rt-14-dev installed? it is listed in .ci/debian-packages; run make deps): $(head -c 300 "$scratch/probe.log")"
    finish
    exit
fi
pass "fuzz toolchain"

if make --no-print-directory -s fuzz-build FUZZ_CC="$fuzz_cc" >"$scratch/build.log" 2>&1; then
    pass "fuzz harnesses build"
else
    fail "fuzz harnesses build" "$(tail -c 600 "$scratch/build.log")"
    finish
    exit
fi

sh tests/fuzz/run.sh build-fuzz "$seconds" "$scratch" >"$scratch/run.log" 2>&1
cat "$scratch/run.log"
grep -q '^FAIL ' "$scratch/run.log" && failures=$((failures + 1))
# The scratch directory goes away after the tests: keep what crashed where it stays.
if ls "$scratch"/artifacts/*/* >/dev/null 2>&1; then
    mkdir -p build-fuzz/crashes
    cp "$scratch"/artifacts/*/* build-fuzz/crashes/
    echo "fuzz-smoke: the crashing inputs are kept in build-fuzz/crashes/"
fi

finish
