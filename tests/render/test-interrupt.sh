#!/bin/sh
# test-interrupt.sh: nothing is lost when a render is interrupted. SIGINT/SIGTERM finish
# the pass in flight and write the samples so far to OUTPUT-base.partial.exr (never over
# the output), --checkpoint writes that file periodically, and --resume continues it to
# the same image as an uninterrupted render.
#   usage: sh tests/render/test-interrupt.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
scene=scenes/materials/lambertian.txt
# About 10.6 million samples, about a second on llvmpipe (docs/performance.md); the tests
# wait for the first checkpoint, written every 0.05 s, before signalling, so most of the
# render is still to come on a faster device too.
spp=8192
options="--size 48x27 --spp $spp --seed 3"

# wait_for_file FILE: waits (at most 60 s) until FILE exists; false on time-out.
wait_for_file() {
    tries=0
    while [ ! -f "$1" ]; do
        tries=$((tries + 1))
        [ "$tries" -le 600 ] || return 1
        sleep 0.1
    done
}

# interrupt_running SIGNAL OUTPUT [OPTIONS...]: starts a render with frequent checkpoints,
# waits until its first checkpoint shows it is really rendering (a cold start can take
# seconds, and a signal before the handlers exist would be lost: a non-interactive shell
# starts background jobs with SIGINT ignored), signals it and waits; prints the exit code.
interrupt_running() {
    signal=$1 output=$2
    shift 2
    # shellcheck disable=SC2086
    "$program" render $scene -o "$output" $options --checkpoint 0.05 "$@" 2>"$scratch/interrupt.err" &
    pid=$!
    wait_for_file "${output%.*}.partial.exr"
    kill -s "$signal" "$pid" 2>/dev/null
    wait "$pid"
    echo $?
}

# SIGINT: exit 1, the partial holds fewer samples than asked, the existing output stays.
printf 'previous image' >"$scratch/out.png"
code=$(interrupt_running INT "$scratch/out.png")
partial="$scratch/out.partial.exr"
if [ "$code" = 1 ] && grep -q "interrupted: wrote" "$scratch/interrupt.err" && [ "$(metadata "$partial" complete)" = 0 ]; then
    pass "SIGINT writes the partial render and exits 1"
else
    fail "SIGINT writes the partial render and exits 1" "exit $code; $(cat "$scratch/interrupt.err")"
fi
if [ "$(cat "$scratch/out.png")" = "previous image" ]; then pass "SIGINT leaves the existing output as it was"
else fail "SIGINT leaves the existing output as it was" "out.png changed"; fi
range=$(channel_range "$partial" samples)
if awk -v r="$range" -v s="$spp" 'BEGIN { split(r, v, " "); exit !(v[1] >= 0 && v[2] <= s && v[1] < s) }'; then
    pass "partial records real per-pixel sample counts ($range)"
else fail "partial sample counts" "samples channel range '$range'"; fi
# Its metadata agree with the channel: samples_finished is the channel's sum.
finished=$(metadata "$partial" samples_finished)
channel_sum=$(awk -v m="$(channel_mean "$partial" samples)" 'BEGIN { printf "%.0f", m * 48 * 27 }')
if [ -n "$finished" ] && [ "$finished" = "$channel_sum" ] && [ "$finished" -lt $((48 * 27 * spp)) ]; then
    pass "the partial's samples_finished ($finished) is the sum of its samples channel"
else fail "the partial's samples_finished" "metadata '$finished', channel sum '$channel_sum'"; fi

# SIGTERM behaves the same.
code=$(interrupt_running TERM "$scratch/term.exr")
if [ "$code" = 1 ] && grep -q "interrupted: wrote" "$scratch/interrupt.err" && [ ! -f "$scratch/term.exr" ]; then
    pass "SIGTERM writes the partial render, not the output"
else fail "SIGTERM" "exit $code, files: $(ls "$scratch" | tr '\n' ' ')"; fi

# --resume gives the image of an uninterrupted render (to float rounding of mean * n),
# and removes the partial once the output is complete.
"$program" render $scene -o "$scratch/reference.exr" $options --quiet
# shellcheck disable=SC2086
if "$program" render $scene -o "$scratch/out.exr" $options --resume "$partial" --quiet; then
    if "$program" diff "$scratch/out.exr" "$scratch/reference.exr" --fail 1e-5 --failpercent 0 >"$scratch/diff.txt"; then
        pass "resumed render equals the uninterrupted one"
    else fail "resumed render equals the uninterrupted one" "$(tr '\n' ' ' <"$scratch/diff.txt")"; fi
    samples=$(channel_range "$scratch/out.exr" samples)
    if [ "$samples" = "$spp $spp" ]; then pass "resumed render has every sample"
    else fail "resumed render has every sample" "samples $samples"; fi
else
    fail "resume" "the resumed render failed"
fi
if [ ! -f "$scratch/out.partial.exr" ]; then pass "the partial is removed when the render completes"
else fail "the partial is removed when the render completes" "it is still there"; fi

# An interrupted render whose output is post-processed (here blurred, to a PNG) still
# writes the raw means and sample counts to its partial, as a checkpoint does: --resume
# adds samples to them, so processed colour there would be processed twice.
code=$(interrupt_running INT "$scratch/blur.png" --blur 2)
if [ "$code" = 1 ] && [ "$(metadata "$scratch/blur.partial.exr" complete)" = 0 ]; then
    pass "SIGINT during a --blur render to a PNG writes its partial"
else fail "SIGINT during a --blur render to a PNG writes its partial" "exit $code; $(cat "$scratch/interrupt.err")"; fi
# Its pixels are the raw means: resumed without post-processing, they give the plain
# render (reference.exr above), as a checkpoint's partial does.
# shellcheck disable=SC2086
if "$program" render $scene -o "$scratch/blur-raw.exr" $options --resume "$scratch/blur.partial.exr" --quiet &&
   "$program" diff "$scratch/blur-raw.exr" "$scratch/reference.exr" --fail 1e-5 --failpercent 0 >"$scratch/diff.txt"; then
    pass "the partial of a --blur render holds the raw means, not the blurred colour"
else fail "the partial of a --blur render holds the raw means" "$(tr '\n' ' ' <"$scratch/diff.txt")"; fi
# Resumed with the same options it gives the uninterrupted blurred PNG, but for 8-bit
# rounding (the colours before the blur agree within 1e-5; one level is 1/255).
# shellcheck disable=SC2086
"$program" render $scene -o "$scratch/blur-reference.png" $options --blur 2 --quiet
# shellcheck disable=SC2086
if "$program" render $scene -o "$scratch/blur.png" $options --blur 2 --resume "$scratch/blur.partial.exr" --quiet &&
   "$program" diff "$scratch/blur.png" "$scratch/blur-reference.png" --fail 0.004 --failpercent 0 >"$scratch/diff.txt"; then
    pass "a resumed --blur render to a PNG equals the uninterrupted one"
else fail "a resumed --blur render to a PNG equals the uninterrupted one" "$(tr '\n' ' ' <"$scratch/diff.txt")"; fi

# A partial of another render is refused: different seed, different size.
code=$(interrupt_running INT "$scratch/other.exr")
# shellcheck disable=SC2086
"$program" render $scene -o "$scratch/x.exr" --size 48x27 --spp $spp --seed 4 --resume "$scratch/other.partial.exr" \
    2>"$scratch/err" >/dev/null
code=$?
if [ "$code" = 2 ] && grep -q "seed" "$scratch/err"; then pass "resume refuses another seed"
else fail "resume refuses another seed" "exit $code: $(cat "$scratch/err")"; fi
"$program" render $scene -o "$scratch/x.exr" --size 32x18 --spp $spp --seed 3 --resume "$scratch/other.partial.exr" \
    2>"$scratch/err" >/dev/null
code=$?
if [ "$code" = 2 ]; then pass "resume refuses another size"
else fail "resume refuses another size" "exit $code: $(cat "$scratch/err")"; fi

# --checkpoint writes the partial while the render runs. A render that cannot finish
# before it is killed (one with $options once finished and removed its partial between
# the file's appearance and the checks below; docs/performance.md has its time).
"$program" render $scene -o "$scratch/cp.exr" --size 48x27 --spp 1000000 --seed 3 --checkpoint 0.3 --quiet &
pid=$!
if wait_for_file "$scratch/cp.partial.exr" && kill -0 "$pid" 2>/dev/null &&
   [ "$(metadata "$scratch/cp.partial.exr" complete)" = 0 ]; then
    pass "--checkpoint writes the partial during the render"
else fail "--checkpoint writes the partial during the render" "no cp.partial.exr while rendering"; fi
kill -s KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null

# An adaptive render (--noise-threshold; about 1.5 s here) interrupted by SIGINT, and one
# killed after a checkpoint: each partial keeps the adaptive state (render.h: the sums at
# the last check, or before the first), and --resume continues it to the uninterrupted
# image bit for bit, with the same sample counts (tests/render/test-adaptive.sh stops
# renders at chosen passes).
adaptive="--noise-threshold 0.003"
# shellcheck disable=SC2086
"$program" render $scene -o "$scratch/adaptive-reference.exr" $options $adaptive --quiet
"$program" stats "$scratch/adaptive-reference.exr" | grep "^channel samples" >"$scratch/reference.samples"
# resumes_exactly NAME PARTIAL: one check: PARTIAL has the adaptive state and resumes to
# the reference's pixels and counts.
resumes_exactly() {
    # shellcheck disable=SC2086
    if [ -n "$(channel_mean "$2" adaptive.samples)" ] &&
            "$program" render $scene -o "$scratch/adaptive-resumed.exr" $options $adaptive --resume "$2" --quiet &&
            "$program" diff "$scratch/adaptive-resumed.exr" "$scratch/adaptive-reference.exr" --fail 0 --failpercent 0 \
                >"$scratch/diff.txt" 2>&1; then
        "$program" stats "$scratch/adaptive-resumed.exr" | grep "^channel samples" >"$scratch/resumed.samples"
        if cmp -s "$scratch/resumed.samples" "$scratch/reference.samples"; then
            pass "$1 (its state $(channel_mean "$2" adaptive.samples) samples a pixel)"
        else fail "$1" "samples $(cat "$scratch/resumed.samples") against $(cat "$scratch/reference.samples")"; fi
    else fail "$1" "no adaptive state in $2, or the resume failed or differs: $(tr '\n' ' ' <"$scratch/diff.txt")"; fi
}
# shellcheck disable=SC2086
code=$(interrupt_running INT "$scratch/adaptive.exr" $adaptive)
if [ "$code" = 1 ]; then resumes_exactly "an interrupted adaptive render resumes bit for bit" "$scratch/adaptive.partial.exr"
else fail "an interrupted adaptive render" "exit $code; $(cat "$scratch/interrupt.err")"; fi
# shellcheck disable=SC2086
"$program" render $scene -o "$scratch/adaptive-cp.exr" $options $adaptive --checkpoint 0.05 --quiet &
pid=$!
wait_for_file "$scratch/adaptive-cp.partial.exr"
sleep 0.4
kill -s KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
if [ -f "$scratch/adaptive-cp.partial.exr" ]; then
    resumes_exactly "an adaptive render's checkpoint resumes bit for bit" "$scratch/adaptive-cp.partial.exr"
else echo "SKIP an adaptive render's checkpoint resumes: the render finished before it was killed (a fast device)"; fi

# A second signal ends the render at once (the default action): death by SIGINT.
# shellcheck disable=SC2086
# Long passes (the largest budget the device allows, over a 1280x720 image: about 0.45 s
# a pass on llvmpipe; at 640x360 a pass had come down to about 0.25 s, not always longer
# than the 0.2 s the signals were apart): the first signal must still be waiting for its
# pass to end when the second one comes, 0.1 s later.
"$program" render $scene -o "$scratch/twice.exr" --size 1280x720 --spp 100000 --checkpoint 0.2 --pass-budget 50000 --quiet &
pid=$!
wait_for_file "$scratch/twice.partial.exr"
kill -s INT "$pid"
sleep 0.1
kill -s INT "$pid"
wait "$pid"
code=$?
# 130 = 128 + SIGINT: the process died of the signal instead of finishing its pass.
if [ "$code" = 130 ]; then pass "a second SIGINT stops at once (exit $code)"
else fail "a second SIGINT stops at once" "exit $code, expected 130 (killed by SIGINT)"; fi
finish
