#!/bin/sh
# test-progress.sh: the progress bar is drawn on stderr when it is a terminal (under
# script(1), which gives the command a pseudo-terminal), never when stderr is a file or
# with --quiet; the one-line summary comes at the end unless --quiet.
#   usage: sh tests/render/test-progress.sh PROGRAM SCRATCH_DIR
set -u
program=$1
scratch=$2
. "$(dirname "$0")/lib.sh"

render="$program render scenes/three-balls.txt --size 64x36 --spp 128"
if ! command -v script >/dev/null 2>&1; then
    fail "progress bar on a terminal" "script(1) (util-linux/bsdutils) is missing"
    finish
    exit
fi
# On a terminal: carriage-return redrawn bars with samples, elapsed time and an ETA,
# then the summary.
script -q -e -c "$render -o $scratch/tty.png" /dev/null >"$scratch/tty.log" 2>&1
if [ "$(tr -cd '\r' <"$scratch/tty.log" | wc -c)" -ge 2 ] && grep -q "samples .* elapsed, ETA" "$scratch/tty.log" &&
   grep -q "64x36, 128 spp in .* samples/s" "$scratch/tty.log"; then
    pass "a terminal gets a progress bar (samples, elapsed, ETA) and the summary"
else
    fail "a terminal gets a progress bar" "$(head -c 300 "$scratch/tty.log" | tr '\r' '|')"
fi
# --quiet on a terminal: nothing at all.
script -q -e -c "$render -o $scratch/quiet.png --quiet" /dev/null >"$scratch/quiet.log" 2>&1
if [ ! -s "$scratch/quiet.log" ]; then pass "--quiet on a terminal prints nothing"
else fail "--quiet on a terminal prints nothing" "$(head -c 300 "$scratch/quiet.log" | tr '\r' '|')"; fi
# stderr a file: no bar, just the summary line.
$render -o "$scratch/file.png" 2>"$scratch/file.log"
if ! grep -q "ETA" "$scratch/file.log" && [ "$(tr -cd '\r' <"$scratch/file.log" | wc -c)" = 0 ] &&
   [ "$(wc -l <"$scratch/file.log")" = 1 ] && grep -q "samples/s" "$scratch/file.log"; then
    pass "stderr to a file: no bar, one summary line"
else
    fail "stderr to a file: no bar, one summary line" "$(head -c 300 "$scratch/file.log")"
fi
finish
