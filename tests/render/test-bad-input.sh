#!/bin/sh
# test-bad-input.sh: a corpus of bad scenes and bad command lines for `render`. Each must
# end with exit 2 and a message that names the scene file (with LINE:COLUMN where the
# problem has a position), never with a crash (exit >= 128, or a sanitizer's exit), and
# must leave no output file behind. The one good input here, an empty scene file,
# must render (exit 0).
#   usage: sh tests/render/test-bad-input.sh PROGRAM SCRATCH_DIR
# Starting the program costs a noticeable time (its image libraries: docs/performance.md),
# so the cases run in two halves at once, each in its own directory; their lines are
# printed in order at the end.
. "$(dirname "$0")/lib.sh"

# Every render is tiny, so that a case that wrongly succeeds still ends at once.
small="--size 8x8 --spp 1 --quiet"
# Each case gets this long before it counts as a hang (generous: the sanitizer build is
# several times slower).
case_seconds=120
cases="$scratch/cases"
mkdir -p "$cases"

# refusal_problem PATTERN COMMAND...: runs COMMAND (killed after $case_seconds) with its
# stdout and stderr in $work; prints nothing when it exits 2 with stderr matching PATTERN
# (grep -E), else what went wrong: a hang, a crash (exit >= 128), another exit code or
# another message.
refusal_problem() {
    refusal_pattern=$1
    shift
    timeout -k 5 "$case_seconds" "$@" >"$work/stdout" 2>"$work/stderr"
    got=$?
    message=$(head -c 300 "$work/stderr" | tr '\n' ' ')
    if [ "$got" = 124 ]; then
        echo "hung: killed after $case_seconds s"
    elif [ "$got" -ge 128 ]; then
        echo "crashed (exit $got): $message"
    elif [ "$got" != 2 ]; then
        echo "exit $got, expected 2: $message"
    elif ! grep -qE -e "$refusal_pattern" "$work/stderr"; then
        echo "stderr lacks /$refusal_pattern/: $message"
    fi
}

# expect_bad NAME PATTERN SCENE [OPTIONS...]: renders SCENE to a fresh output and checks
# exit 2, stderr matching PATTERN (grep -E), and that no output file appeared.
expect_bad() {
    name=$1 pattern=$2 scene=$3
    shift 3
    output="$work/out.png"
    rm -f "$output"
    # shellcheck disable=SC2086 # $small is a list of options
    problem=$(refusal_problem "$pattern" "$program" render "$scene" -o "$output" $small "$@")
    if [ -n "$problem" ]; then
        fail "$name" "$problem"
    elif [ -e "$output" ]; then
        fail "$name" "an output file was written"
    else
        pass "$name"
    fi
}

# expect_usage NAME PATTERN ARGUMENTS...: a bad command line: exit 2, a message matching
# PATTERN, no crash.
expect_usage() {
    name=$1 pattern=$2
    shift 2
    problem=$(refusal_problem "$pattern" "$program" "$@")
    if [ -n "$problem" ]; then fail "$name" "$problem"; else pass "$name"; fi
}

# write_case NAME TEXT: writes TEXT (printf format: \NNN octal escapes work) to
# $cases/NAME and prints the path.
write_case() {
    # shellcheck disable=SC2059 # the text is the format on purpose, for its escapes
    printf "$2" >"$cases/$1"
    echo "$cases/$1"
}

# pseudo_random_bytes COUNT SEED: COUNT bytes of deterministic garbage (a linear
# congruential generator in awk, written through printf's octal escapes, so every byte
# value appears and no locale or awk flavour changes them).
pseudo_random_bytes() {
    format=$(awk -v count="$1" -v state="$2" 'BEGIN {
        for (i = 0; i < count; i++) {
            state = (state * 1103515245 + 12345) % 2147483648
            printf "\\%03o", int(state / 65536) % 256
        }
    }')
    # shellcheck disable=SC2059 # the escapes are the point
    printf "$format"
}

material='material m lambertian 0.5 0.5 0.5\n'
position=':[0-9]+:[0-9]+:'

# The first half: damaged files, numbers and render settings.
bad_scene_content() {
    # --- damaged files
    head -c "$(( $(grep -b -o -m1 lambertian scenes/three-balls.txt | cut -d: -f1) + 5 ))" scenes/three-balls.txt \
        >"$cases/truncated.txt"
    expect_bad "truncated mid-token" "truncated.txt$position .*'lambe'" "$cases/truncated.txt"
    pseudo_random_bytes 4096 20240601 >"$cases/garbage.bin"
    expect_bad "4 KB of binary garbage" "garbage.bin$position" "$cases/garbage.bin"
    expect_bad "NUL byte" "nul.txt:2:11: .*0x00" "$(write_case nul.txt "$material"'sphere 0 0\0000 1 m\n')"
    expect_bad "non-UTF-8 byte" "latin1.txt:1:13: .*UTF-8" "$(write_case latin1.txt 'material caf\351 lambertian 1 1 1\n')"
    expect_bad "truncated UTF-8 sequence at the end" "cut-utf8.txt:1:3:" "$(write_case cut-utf8.txt '# \342\202')"

    # --- numbers
    expect_bad "1e999" "huge.txt:2:8: .*out of range" "$(write_case huge.txt "$material"'sphere 1e999 0 0 1 m\n')"
    expect_bad "99999999999999999999 samples" "huge-spp.txt:1:12:" "$(write_case huge-spp.txt 'render spp 99999999999999999999\n')"
    expect_bad "radius beyond float range" "float-range.txt:2:14:" "$(write_case float-range.txt "$material"'sphere 0 0 0 1e300 m\n')"
    expect_bad "nan literal" "nan.txt:2:8: .*NaN" "$(write_case nan.txt "$material"'sphere nan 0 0 1 m\n')"
    expect_bad "inf literal" "inf.txt:2:10: .*infinity" "$(write_case inf.txt "$material"'sphere 0 inf 0 1 m\n')"
    expect_bad "-Infinity literal" "neg-inf.txt:2:12:" "$(write_case neg-inf.txt "$material"'sphere 0 0 -Infinity 1 m\n')"
    expect_bad "0/0 expression" "zero-by-zero.txt:2:10: .*division by zero" \
        "$(write_case zero-by-zero.txt "$material"'sphere (0/0) 0 0 1 m\n')"
    expect_bad "overflowing expression" "overflow.txt:1:12: .*infinite" "$(write_case overflow.txt 'set x 1e308*10\n')"
    expect_bad "expression nested 10000 deep" "nested.txt$position .*nested too deeply" \
        "$(write_case nested.txt "sphere $(awk 'BEGIN { for (i = 0; i < 10000; i++) printf "(" }') 0 0 1 m\n")"

    # --- absurd render settings
    expect_bad "render size 0 0" "size-0.txt:1:13: .*width" "$(write_case size-0.txt 'render size 0 0\n')"
    expect_bad "render size 100000 100000" "size-huge.txt:1:13:" "$(write_case size-huge.txt 'render size 100000 100000\n')"
    expect_bad "render spp 0" "spp-0.txt:1:12:" "$(write_case spp-0.txt 'render spp 0\n')"
    expect_bad "render spp 2^40" "spp-huge.txt:1:12:" "$(write_case spp-huge.txt 'render spp 1099511627776\n')"
    expect_bad "render depth 1.5" "depth-fraction.txt:1:14: .*whole number" \
        "$(write_case depth-fraction.txt 'render depth 1.5\n')"
}

# The second half: sizes, includes, what is not a scene file, and bad command lines.
bad_structure_and_command_lines() {
    # --- sizes and structure
    head -c 1048576 /dev/zero | tr '\0' 'a' >"$cases/long-line.txt"
    expect_bad "1 MB single line" "long-line.txt:1:1: .*unknown statement" "$cases/long-line.txt"
    { printf 'sphere 0 0 0 1 m'; head -c 1048576 /dev/zero | tr '\0' ' '; printf 'extra\n'; } >"$cases/long-gap.txt"
    expect_bad "1 MB of spaces inside a statement" "long-gap.txt:1:" "$cases/long-gap.txt"
    mkdir -p "$cases/chain"
    for i in $(seq 1 40); do
        printf 'include "chain-%d.txt"\n' $((i + 1)) >"$cases/chain/chain-$i.txt"
    done
    printf '%s' "$material" >"$cases/chain/chain-41.txt"
    expect_bad "include chain 40 deep" "chain-[0-9]+.txt$position .*nested too deeply" "$cases/chain/chain-1.txt"
    printf 'include "cycle-b.txt"\n' >"$cases/cycle-a.txt"
    printf '\n\ninclude "cycle-a.txt"\n' >"$cases/cycle-b.txt"
    expect_bad "include cycle" "cycle-b.txt:3:1: include cycle" "$cases/cycle-a.txt"
    expect_bad "include of a missing file" "missing-include.txt:1:1: .*no-such-file.txt" \
        "$(write_case missing-include.txt 'include "no-such-file.txt"\n')"
    expect_bad "include of an endless device" "devzero.txt:1:1: .*/dev/zero.*too large" \
        "$(write_case devzero.txt 'include "/dev/zero"\n')"
    mkdir -p "$cases/a-directory"
    expect_bad "a directory as the scene" "a-directory.*(directory|Is a)" "$cases/a-directory"
    expect_bad "a missing scene" "no-such-scene.txt" "$cases/no-such-scene.txt"
    expect_bad "include of a directory" "include-directory.txt:1:1: .*a-directory" \
        "$(write_case include-directory.txt 'include "a-directory"\n')"

    # --- the empty file is a valid scene: the default camera and sky, nothing else.
    : >"$cases/empty.txt"
    rm -f "$work/empty.png"
    # shellcheck disable=SC2086 # $small is a list of options
    "$program" render "$cases/empty.txt" -o "$work/empty.png" $small 2>"$work/stderr"
    got=$?
    if [ "$got" = 0 ] && [ -s "$work/empty.png" ]; then pass "empty scene renders"
    else fail "empty scene renders" "exit $got: $(head -c 300 "$work/stderr")"; fi

    # --- bad command lines
    scene=scenes/materials/lambertian.txt
    expect_usage "unknown long option" "unrecognized option|unknown option" render "$scene" -o "$work/a.png" --no-such-option
    expect_usage "unknown short option" "invalid option|unknown option" render "$scene" -o "$work/a.png" -Z
    expect_usage "--spp without its value" "requires an argument" render "$scene" -o "$work/a.png" --spp
    expect_usage "-o without its value" "requires an argument" render "$scene" -o
    expect_usage "-D without its value" "requires an argument" render "$scene" -o "$work/a.png" -D
    expect_usage "--light-tree maybe" "--light-tree wants on or off" render "$scene" -o "$work/a.png" --light-tree maybe
    expect_usage "--size without its value" "requires an argument" render "$scene" -o "$work/a.png" --size
    expect_usage "--spp 2^40" "spp" render "$scene" -o "$work/a.png" --spp 1099511627776
    expect_usage "--size 100000x100000" "size" render "$scene" -o "$work/a.png" --size 100000x100000
    expect_usage "output in /proc" "cannot write '/proc/foo.png'" render "$scene" -o /proc/foo.png $small
    if [ -e /proc/foo.png ]; then fail "nothing written to /proc" "/proc/foo.png exists"; else pass "nothing written to /proc"; fi
    expect_usage "output in a missing directory" "cannot write" render "$scene" -o "$work/no/such/dir/a.png" $small
    expect_usage "output through a regular file" "cannot write" render "$scene" -o "$cases/empty.txt/a.png" $small
    # A scene larger than the device holds: no real test scene reaches llvmpipe's 134M
    # texels, so the test lowers the limit the device reports (gpu.c).
    RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE=1000
    export RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE
    expect_bad "scene too large for the device" "GL_MAX_TEXTURE_BUFFER_SIZE 1000\): [0-9]+ texels too many" \
        scenes/weekend.txt
    unset RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE
}

mkdir -p "$scratch/half1" "$scratch/half2"
(work="$scratch/half1"; bad_scene_content) >"$scratch/half1.log" 2>&1 &
first_half=$!
(work="$scratch/half2"; bad_structure_and_command_lines) >"$scratch/half2.log" 2>&1
wait "$first_half"
cat "$scratch/half1.log" "$scratch/half2.log"
failures=$(cat "$scratch/half1.log" "$scratch/half2.log" | grep -c '^FAIL ')

leftovers=$(find "$scratch" "$cases" -name '*.tmp*' -o -name '.rtspheres-probe-*' | head -3)
if [ -z "$leftovers" ]; then pass "bad inputs leave no temporary files"
else fail "bad inputs leave no temporary files" "$leftovers"; fi

finish
