#!/bin/sh
# test-time-limit.sh: --time-limit SECONDS: the render ends within about a pass of the
# limit (the one timing check here, with a generous margin: passes last about a second on
# llvmpipe, and the machine may be loaded), writes what it has with per-pixel counts and
# rtspheres:stop_reason time, and --resume continues it to the uninterrupted image.
# About 20 s.
#   usage: sh tests/render/test-time-limit.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

scene=scenes/cornell.txt
now() { date +%s.%N; }

# ---- a render far longer than the limit ends near it (on a loaded machine the first
# pass, with the shader's compile, may take most of the limit: some pixels may have no
# finished sample yet)
start=$(now)
if "$program" render "$scene" -o "$scratch/limited.exr" --size 48x48 --spp 100000 --time-limit 2 --quiet; then
    elapsed=$(awk -v s="$start" -v e="$(now)" 'BEGIN { print e - s }')
    # The limit counts from the command's start; within one pass of it, plus writing.
    if awk -v e="$elapsed" 'BEGIN { exit !(e < 2 + 6) }'; then pass "--time-limit 2 ended after $elapsed s"
    else fail "--time-limit 2 ends within about a pass" "it took $elapsed s"; fi
    stats_of "$scratch/limited.exr"
    samples=$(stat_range samples)
    if [ "$(stat_metadata stop_reason)" = time ] && [ "$(stat_metadata complete)" = 0 ] &&
            [ "${samples#* }" -ge 1 ] && [ "${samples#* }" -lt 100000 ]; then
        pass "a time-limited render says stop_reason time, complete 0, and keeps its counts ($samples)"
    else fail "a time-limited render's metadata and counts" "samples $samples; $(grep -E 'stop_reason|complete' "$scratch/stats" | tr '\n' ' ')"; fi
else
    fail "--time-limit" "render failed"
fi

# ---- resuming a time-limited render continues it to the uninterrupted image (to float
# rounding of mean * n, as --resume of a partial: test-interrupt.sh)
options="--size 32x32 --spp 1024"
if "$program" render "$scene" -o "$scratch/whole.exr" $options --quiet &&
        "$program" render "$scene" -o "$scratch/part.exr" $options --time-limit 1 --quiet; then
    part_samples=$(channel_mean "$scratch/part.exr" samples)
    if "$program" render "$scene" -o "$scratch/resumed.exr" $options --resume "$scratch/part.exr" --quiet; then
        if "$program" diff "$scratch/resumed.exr" "$scratch/whole.exr" --fail 1e-5 --failpercent 0 \
                >"$scratch/diff.txt"; then
            pass "a resumed time-limited render ($part_samples samples per pixel) equals the uninterrupted one"
        else fail "a resumed time-limited render equals the uninterrupted one" "$(tr '\n' ' ' <"$scratch/diff.txt")"; fi
        samples=$(channel_range "$scratch/resumed.exr" samples)
        if [ "$samples" = "1024 1024" ]; then pass "the resumed render has every sample"
        else fail "the resumed render has every sample" "samples $samples"; fi
    else
        fail "resuming a time-limited render" "the resumed render failed"
    fi
else
    fail "resuming a time-limited render" "a render failed"
fi

# ---- with adaptive sampling the limit ends it too, and the metadata say so
if "$program" render "$scene" -o "$scratch/adaptive.exr" --size 48x48 --spp 100000 --noise-threshold 0.0001 \
        --time-limit 1 --quiet && stats_of "$scratch/adaptive.exr" && [ "$(stat_metadata stop_reason)" = time ] &&
        within "$(stat_metadata noise_threshold)" 0.0001 1e-5; then
    pass "an adaptive time-limited render says stop_reason time and its noise threshold"
else fail "an adaptive time-limited render" "$(grep -E 'stop_reason|noise_threshold' "$scratch/stats" | tr '\n' ' ')"; fi

# ---- with frames the limit is per image: each frame is written, each stopped by time
start=$(now)
if "$program" render "$scene" -o "$scratch/frame-%d.exr" --frames 1-2 --size 32x32 --spp 100000 --time-limit 1 \
        --quiet; then
    elapsed=$(awk -v s="$start" -v e="$(now)" 'BEGIN { print e - s }')
    reasons="$(metadata "$scratch/frame-1.exr" stop_reason) $(metadata "$scratch/frame-2.exr" stop_reason)"
    if [ "$reasons" = "time time" ] && awk -v e="$elapsed" 'BEGIN { exit !(e < 2 * (1 + 5)) }'; then
        pass "--time-limit with --frames: each frame stopped by time, $elapsed s for two"
    else fail "--time-limit with --frames" "stop reasons '$reasons', $elapsed s"; fi
else
    fail "--time-limit with --frames" "render failed"
fi

# ---- refusals
for bad in 0 -2 abc inf; do
    expect_refusal "--time-limit $bad is refused" "--time-limit wants a positive number of seconds" \
        "$scratch/refused" "$program" render "$scene" -o "$scratch/refused/x.exr" --time-limit "$bad"
done
finish
