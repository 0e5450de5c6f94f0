# lib.sh: helpers shared by the render test scripts (sourced, POSIX sh).
# Every script runs as `sh tests/render/test-NAME.sh PROGRAM SCRATCH_DIR` and sources this
# file first, which sets $program and $scratch from those two arguments. Each check
# prints "PASS name", "FAIL name: detail" or "SKIP name: reason"; tests/run.sh counts
# those lines. The helpers keep their working values in variables named lib_*, so that
# they never overwrite a script's own.
set -u
if [ $# -lt 2 ]; then
    echo "usage: sh $0 PROGRAM SCRATCH_DIR" >&2
    exit 2
fi
program=$1
scratch=$2
mkdir -p "$scratch" || exit 1

failures=0

pass() { echo "PASS $1"; }
fail() { echo "FAIL $1: $2"; failures=$((failures + 1)); }

# finish: exit status of the script, non-zero when any check failed.
finish() { [ "$failures" = 0 ]; }

# ---- exit codes and messages ---------------------------------------------------------------

# exits_with CODE PATTERN COMMAND...: runs COMMAND with its stdout in $scratch/stdout and
# its stderr in $scratch/stderr; true when it exits CODE and stderr matches PATTERN (grep -E;
# an empty PATTERN matches anything), else false with what went wrong in $problem.
exits_with() {
    lib_code=$1 lib_pattern=$2
    shift 2
    "$@" >"$scratch/stdout" 2>"$scratch/stderr"
    lib_got=$?
    if [ "$lib_got" != "$lib_code" ]; then
        problem="exit $lib_got, expected $lib_code; stderr: $(head -c 300 "$scratch/stderr")"
    elif [ -n "$lib_pattern" ] && ! grep -qE -e "$lib_pattern" "$scratch/stderr"; then
        problem="stderr lacks /$lib_pattern/: $(head -c 300 "$scratch/stderr")"
    else
        return 0
    fi
    return 1
}

# expect_exit NAME CODE PATTERN COMMAND...: one check: COMMAND exits CODE and its stderr
# contains PATTERN (a grep -E expression), as exits_with.
expect_exit() {
    lib_name=$1
    shift
    if exits_with "$@"; then pass "$lib_name"; else fail "$lib_name" "$problem"; fi
}

# expect_refusal NAME PATTERN DIR COMMAND...: one check: COMMAND exits 2, its stderr
# matches PATTERN (grep -E) and it writes nothing into DIR, which is emptied first (point
# the command's outputs there: a refused command must leave no file, not even a temporary).
expect_refusal() {
    lib_name=$1 lib_pattern=$2 lib_dir=$3
    shift 3
    rm -rf "$lib_dir"
    mkdir -p "$lib_dir"
    if ! exits_with 2 "$lib_pattern" "$@"; then
        fail "$lib_name" "$problem"
    elif [ -n "$(ls -A "$lib_dir")" ]; then
        fail "$lib_name" "files were written: $(ls -A "$lib_dir" | tr '\n' ' ')"
    else
        pass "$lib_name"
    fi
}

# ---- rendering and comparing ---------------------------------------------------------------

# render OUTPUT [OPTIONS...]: renders the script's $scene to OUTPUT quietly with the
# script's $render_options, then OPTIONS.
render() {
    lib_output=$1
    shift
    # shellcheck disable=SC2086 # $render_options is a list of options
    "$program" render "$scene" -o "$lib_output" $render_options --quiet "$@"
}

# same NAME A B: one check: A and B have exactly the same pixels (diff --fail 0
# --failpercent 0).
same() {
    if "$program" diff "$2" "$3" --fail 0 --failpercent 0 >"$scratch/diff" 2>&1; then
        pass "$1"
    else
        fail "$1" "$2 and $3 differ: $(tr '\n' ' ' <"$scratch/diff" | head -c 300)"
    fi
}

# merge_problem EXPECTED TOLERANCE SAMPLES MERGED PARTS...: merges PARTS into MERGED and
# prints what is wrong, or nothing: the merge fails, MERGED differs from EXPECTED by more
# than TOLERANCE anywhere (diff --fail TOLERANCE --failpercent 0), or a pixel has other
# than SAMPLES samples. Leaves MERGED's `stats` in $scratch/stats (see stats_of).
merge_problem() {
    lib_expected=$1 lib_tolerance=$2 lib_samples=$3 lib_merged=$4
    shift 4
    rm -f "$lib_merged"
    if ! "$program" merge "$@" -o "$lib_merged" --quiet 2>"$scratch/stderr"; then
        echo "merge failed: $(head -c 300 "$scratch/stderr")"
    elif ! "$program" diff "$lib_merged" "$lib_expected" --fail "$lib_tolerance" --failpercent 0 \
            >"$scratch/diff" 2>&1; then
        echo "merged parts differ from $lib_expected: $(tr '\n' ' ' <"$scratch/diff" | head -c 300)"
    elif ! stats_of "$lib_merged" || [ "$(stat_range samples)" != "$lib_samples $lib_samples" ]; then
        echo "samples channel min/max is '$(stat_range samples)', expected '$lib_samples $lib_samples'"
    fi
}

# render_split_scene: the render that test-merge.sh and test-splits.sh split into parts:
# sets $scene, $size and $render_options (see render) to the test scene at 48x27 and
# 16 spp, and renders it whole to $full ($scratch/full.exr); false, after a failed check
# "full render", when that render fails.
render_split_scene() {
    scene=scenes/materials/metal.txt
    size="--size 48x27"
    render_options="$size --spp 16"
    full=$scratch/full.exr
    if render "$full"; then
        return 0
    fi
    fail "full render" "rtspheres render failed"
    return 1
}

# ---- what `stats` prints -------------------------------------------------------------------

# stats_of FILE [--crop C]: runs `stats` once and keeps its output in $scratch/stats, which
# channels_of FILE: the channel names of FILE, sorted, on one line.
channels_of() {
    "$program" stats "$1" | sed -n 's/^channel \([^:]*\):.*/\1/p' | sort | tr '\n' ' ' | sed 's/ $//'
}

# stat_mean, stat_range and stat_metadata read (each `stats` run costs an OpenImageIO
# start-up, so a check that needs several values runs it once).
stats_of() {
    "$program" stats "$@" >"$scratch/stats" 2>&1
}

# stat_mean CHANNEL [STATS]: the mean of CHANNEL (R, G, B, samples, ...) in a kept `stats`
# output: the file STATS, $scratch/stats by default, - for standard input.
stat_mean() {
    sed -n "s/^channel $1: mean \([^ ]*\) .*/\1/p" "${2:-$scratch/stats}"
}

# stat_range CHANNEL [STATS]: "min max" of CHANNEL in a kept `stats` output, as stat_mean.
stat_range() {
    sed -n "s/^channel $1: mean [^ ]* min \([^ ]*\) max \([^ ]*\)/\1 \2/p" "${2:-$scratch/stats}"
}

# stat_metadata NAME [STATS]: the rtspheres:NAME metadata value in a kept `stats` output.
stat_metadata() {
    sed -n "s/^metadata rtspheres:$1: //p" "${2:-$scratch/stats}"
}

# channel_mean FILE CHANNEL [CROP]: the mean of one channel, from a `stats` run of its own.
channel_mean() {
    "$program" stats "$1" ${3:+--crop "$3"} | stat_mean "$2" -
}

# channel_range FILE CHANNEL [CROP]: "min max" of one channel, from a `stats` run of its own.
channel_range() {
    "$program" stats "$1" ${3:+--crop "$3"} | stat_range "$2" -
}

# metadata FILE NAME: one rtspheres:NAME metadata value of an EXR.
metadata() {
    "$program" stats "$1" | stat_metadata "$2" -
}

# ---- numbers and files ---------------------------------------------------------------------

# within VALUE EXPECTED RELATIVE: true when |VALUE - EXPECTED| <= RELATIVE * |EXPECTED|.
within() {
    awk -v v="$1" -v e="$2" -v r="$3" 'BEGIN { d = v - e; if (d < 0) d = -d; a = e < 0 ? -e : e; exit !(v != "" && d <= r * a) }'
}

# files_are NAME DIR EXPECTED: passes when the names in DIR, sorted and space-separated,
# are EXPECTED (no other file, no temporary left behind).
files_are() {
    lib_got=$(ls -A "$2" | sort | tr '\n' ' ' | sed 's/ $//')
    if [ "$lib_got" = "$3" ]; then pass "$1"
    else fail "$1" "files '$lib_got', expected '$3'"; fi
}
