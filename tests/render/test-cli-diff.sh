#!/bin/sh
# Tests of `rtspheres diff`: exit codes, the result line, the difference image, errors.
#   usage: sh tests/render/test-cli-diff.sh PROGRAM SCRATCH_DIR
# The test images are tiny binary PPMs (P6) written with printf, so that nothing beyond
# a POSIX shell is needed. Prints "PASS name" or "FAIL name: detail" per check; exits 1
# when any check failed.
. "$(dirname "$0")/lib.sh"

# Writes a WIDTH x HEIGHT P6 image filled with R G B (0-255), except that the pixel at
# (X, Y), when given, is R2 G2 B2.
#   make_ppm FILE WIDTH HEIGHT R G B [X Y R2 G2 B2]
make_ppm() {
    file=$1 width=$2 height=$3 r=$4 g=$5 b=$6
    odd_x=${7:--1} odd_y=${8:--1} r2=${9:-0} g2=${10:-0} b2=${11:-0}
    fill=$(printf '\\%03o\\%03o\\%03o' "$r" "$g" "$b")
    odd=$(printf '\\%03o\\%03o\\%03o' "$r2" "$g2" "$b2")
    {
        printf 'P6\n%d %d\n255\n' "$width" "$height"
        y=0
        while [ "$y" -lt "$height" ]; do
            x=0
            while [ "$x" -lt "$width" ]; do
                if [ "$x" = "$odd_x" ] && [ "$y" = "$odd_y" ]; then
                    printf "$odd"
                else
                    printf "$fill"
                fi
                x=$((x + 1))
            done
            y=$((y + 1))
        done
    } >"$file"
}

# Runs PROGRAM diff with the given arguments; leaves the exit code in $status and the
# output in $scratch/out and $scratch/err.
run_diff() {
    if "$program" diff "$@" >"$scratch/out" 2>"$scratch/err"; then status=0; else status=$?; fi
}

# check_exit NAME EXPECTED: the last run_diff exited with EXPECTED.
check_exit() {
    if [ "$status" = "$2" ]; then
        return 0
    fi
    fail "$1" "exit $status, expected $2; stdout: $(tr '\n' '|' <"$scratch/out") stderr: $(tr '\n' '|' <"$scratch/err")"
    return 1
}

# has STREAM TEXT: the last run's stdout/stderr contains TEXT (a fixed string).
has() {
    grep -F -q -- "$2" "$scratch/$1"
}

a=$scratch/a.ppm
make_ppm "$a" 4 4 100 150 200
make_ppm "$scratch/a-copy.ppm" 4 4 100 150 200
# One pixel of 16 (6.25%) differs in red by 155/255: max error 0.607843 at (2, 1).
make_ppm "$scratch/b.ppm" 4 4 100 150 200 2 1 255 150 200
# One pixel differs by 2/255 = 0.0078, under the default threshold 0.016.
make_ppm "$scratch/close.ppm" 4 4 100 150 200 3 3 102 150 200
make_ppm "$scratch/small.ppm" 2 2 100 150 200
printf 'this is not an image\n' >"$scratch/text.ppm"

name=identical-pass
run_diff "$a" "$scratch/a-copy.ppm" --diff-out "$scratch/not-written.png"
if check_exit "$name" 0; then
    if ! has out "result: PASS"; then fail "$name" "no 'result: PASS' in: $(cat "$scratch/out")"
    elif ! has out "psnr: inf dB"; then fail "$name" "no 'psnr: inf dB' in: $(cat "$scratch/out")"
    elif [ -e "$scratch/not-written.png" ]; then fail "$name" "--diff-out written although the images match"
    else pass "$name"; fi
fi

name=differ-fail-writes-diff-image
run_diff "$a" "$scratch/b.ppm" --diff-out "$scratch/diff.png"
if check_exit "$name" 1; then
    if ! has out "result: FAIL"; then fail "$name" "no 'result: FAIL' in: $(cat "$scratch/out")"
    elif ! has out "max error: 0.607843 at (2, 1)"; then fail "$name" "wrong max error line in: $(cat "$scratch/out")"
    elif ! has out "pixels over 0.016: 1 of 16 (6.25%)"; then fail "$name" "wrong failing pixel line in: $(cat "$scratch/out")"
    elif [ ! -s "$scratch/diff.png" ]; then fail "$name" "no difference image at $scratch/diff.png"
    else pass "$name"; fi
fi

# The difference image must be a readable image: it compares equal to itself.
name=diff-image-readable
run_diff "$scratch/diff.png" "$scratch/diff.png"
check_exit "$name" 0 && pass "$name"

name=within-tolerance-pass
run_diff "$a" "$scratch/close.ppm"
check_exit "$name" 0 && { has out "result: PASS" && pass "$name" || fail "$name" "no 'result: PASS'"; }

name=failpercent-allows
run_diff "$a" "$scratch/b.ppm" --failpercent 10
check_exit "$name" 0 && pass "$name"

name=hardfail-fails
run_diff "$a" "$scratch/b.ppm" --failpercent 10 --hardfail 0.5
check_exit "$name" 1 && { has out "hardfail" && pass "$name" || fail "$name" "the result line does not name --hardfail"; }

name=fail-zero-is-exact
run_diff "$a" "$scratch/close.ppm" --fail 0 --failpercent 0
check_exit "$name" 1 && pass "$name"

name=diff-always-writes
run_diff "$a" "$scratch/a-copy.ppm" --diff-out "$scratch/always.exr" --diff-always
check_exit "$name" 0 && { [ -s "$scratch/always.exr" ] && pass "$name" || fail "$name" "no $scratch/always.exr"; }

name=quiet-silent-on-match
run_diff "$a" "$scratch/a-copy.ppm" --quiet --diff-out "$scratch/quiet.png" --diff-always
check_exit "$name" 0 && { [ ! -s "$scratch/out" ] && pass "$name" || fail "$name" "printed: $(cat "$scratch/out")"; }

name=quiet-reports-failure
run_diff "$a" "$scratch/b.ppm" --quiet
check_exit "$name" 1 && { has out "result: FAIL" && pass "$name" || fail "$name" "no 'result: FAIL' in: $(cat "$scratch/out")"; }

name=sizes-differ-fail
run_diff "$a" "$scratch/small.ppm"
check_exit "$name" 1 && { has out "result: FAIL (sizes differ: 4x4 vs 2x2)" && pass "$name" ||
    fail "$name" "no sizes message in: $(cat "$scratch/out")"; }

name=missing-file-error
run_diff "$a" "$scratch/does-not-exist.ppm"
check_exit "$name" 2 && { has err "$scratch/does-not-exist.ppm" && pass "$name" ||
    fail "$name" "stderr does not name the file: $(cat "$scratch/err")"; }

name=not-an-image-error
run_diff "$scratch/text.ppm" "$a"
check_exit "$name" 2 && { has err "$scratch/text.ppm" && pass "$name" ||
    fail "$name" "stderr does not name the file: $(cat "$scratch/err")"; }

name=bad-fail-value
run_diff "$a" "$scratch/a-copy.ppm" --fail abc
check_exit "$name" 2 && { has err "'abc'" && pass "$name" || fail "$name" "stderr: $(cat "$scratch/err")"; }

name=bad-failpercent-value
run_diff "$a" "$scratch/a-copy.ppm" --failpercent 101
check_exit "$name" 2 && pass "$name"

name=bad-scale-value
run_diff "$a" "$scratch/a-copy.ppm" --scale 2x
check_exit "$name" 2 && pass "$name"

name=missing-option-value
run_diff "$a" "$scratch/a-copy.ppm" --fail
check_exit "$name" 2 && { has err "--fail" && pass "$name" || fail "$name" "stderr: $(cat "$scratch/err")"; }

name=unknown-option
run_diff "$a" "$scratch/a-copy.ppm" --no-such-option
check_exit "$name" 2 && { has err "--no-such-option" && pass "$name" || fail "$name" "stderr: $(cat "$scratch/err")"; }

name=one-image-error
run_diff "$a"
check_exit "$name" 2 && pass "$name"

name=unwritable-diff-out-error
run_diff "$a" "$scratch/b.ppm" --diff-out "$scratch/no-such-dir/diff.png"
check_exit "$name" 2 && { has err "$scratch/no-such-dir/diff.png" && pass "$name" ||
    fail "$name" "stderr does not name the file: $(cat "$scratch/err")"; }

name=help
run_diff --help
check_exit "$name" 0 && { has out "usage: rtspheres diff" && pass "$name" || fail "$name" "no usage line"; }

finish
