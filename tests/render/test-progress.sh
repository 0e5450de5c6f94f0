#!/bin/sh
# test-progress.sh: the progress bar is drawn on stderr when it is a terminal (under
# script(1), which gives the command a pseudo-terminal), never when stderr is a file (it
# gets progress lines instead, every --progress-interval seconds) or with --quiet; the
# one-line summary comes at the end unless --quiet.
#   usage: sh tests/render/test-progress.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

render="$program render scenes/three-balls.txt --size 64x36 --spp 128"
# A pseudo-terminal needs script(1) (bsdutils, on every Debian) and /dev/pts; a bare
# chroot may have no pseudo-terminals: then the terminal cases are skipped, said why.
if ! command -v script >/dev/null 2>&1; then
    echo "SKIP progress bar on a terminal: script(1) is missing"
elif ! script -q -e -c true /dev/null >"$scratch/pty.log" 2>&1; then
    echo "SKIP progress bar on a terminal: no pseudo-terminal here ($(head -c 200 "$scratch/pty.log" | tr '\n' ' '))"
else
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
fi
# stderr a file: no bar, the summary line, and before it at most progress lines (one every
# --progress-interval seconds, 5 by default: a loaded machine may take that long;
# tests/render/test-farm.sh checks the lines themselves).
$render -o "$scratch/file.png" 2>"$scratch/file.log"
if ! grep -q "\[#*\.*\]" "$scratch/file.log" && [ "$(tr -cd '\r' <"$scratch/file.log" | wc -c)" = 0 ] &&
   [ "$(grep -vc '^rtspheres: progress ' "$scratch/file.log")" = 1 ] && tail -1 "$scratch/file.log" | grep -q "samples/s"; then
    pass "stderr to a file: no bar, the summary line (after progress lines, if any)"
else
    fail "stderr to a file: no bar, the summary line" "$(head -c 300 "$scratch/file.log")"
fi
finish
