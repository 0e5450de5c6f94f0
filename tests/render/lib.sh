# lib.sh: helpers shared by the render test scripts (sourced, POSIX sh).
# Each check prints "PASS name" or "FAIL name: detail"; tests/run.sh counts those lines.

failures=0

pass() { echo "PASS $1"; }
fail() { echo "FAIL $1: $2"; failures=$((failures + 1)); }

# finish: exit status of the script, non-zero when any check failed.
finish() { [ "$failures" = 0 ]; }

# channel_mean FILE CHANNEL [CROP]: the mean of one channel (R, G, B, samples) by `stats`.
channel_mean() {
    if [ -n "${3:-}" ]; then
        "$program" stats "$1" --crop "$3" | sed -n "s/^channel $2: mean \([^ ]*\) .*/\1/p"
    else
        "$program" stats "$1" | sed -n "s/^channel $2: mean \([^ ]*\) .*/\1/p"
    fi
}

# channel_range FILE CHANNEL [CROP]: "min max" of one channel.
channel_range() {
    if [ -n "${3:-}" ]; then
        "$program" stats "$1" --crop "$3" | sed -n "s/^channel $2: mean [^ ]* min \([^ ]*\) max \([^ ]*\)/\1 \2/p"
    else
        "$program" stats "$1" | sed -n "s/^channel $2: mean [^ ]* min \([^ ]*\) max \([^ ]*\)/\1 \2/p"
    fi
}

# metadata FILE NAME: one rtspheres:NAME metadata value of an EXR.
metadata() {
    "$program" stats "$1" | sed -n "s/^metadata rtspheres:$2: //p"
}

# within VALUE EXPECTED RELATIVE: true when |VALUE - EXPECTED| <= RELATIVE * |EXPECTED|.
within() {
    awk -v v="$1" -v e="$2" -v r="$3" 'BEGIN { d = v - e; if (d < 0) d = -d; a = e < 0 ? -e : e; exit !(v != "" && d <= r * a) }'
}

# files_are NAME DIR EXPECTED: passes when the names in DIR, sorted and space-separated,
# are EXPECTED (no other file, no temporary left behind).
files_are() {
    got=$(ls -A "$2" | sort | tr '\n' ' ' | sed 's/ $//')
    if [ "$got" = "$3" ]; then pass "$1"
    else fail "$1" "files '$got', expected '$3'"; fi
}
