#!/bin/sh
# test-adaptive.sh: adaptive sampling (--noise-threshold, --min-spp; core/adaptive.h):
# unbiased where it has converged (an analytic scene, and statistical agreement with a
# fixed-spp render), samples spent where the noise is (the samples channel), tiles that
# merge exactly into the full render, its metadata, and its refusals. About 10 s.
#   usage: sh tests/render/test-adaptive.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# ---- the white furnace: the sphere's pixels are exactly the albedo (test-analytic.sh), so
# their noise is 0 and they stop at --min-spp with exactly the albedo; the silhouette,
# between sphere and sky, is noisy and takes more.
out="$scratch/furnace.exr"
if "$program" render scenes/furnace.txt -o "$out" --size 64x64 --spp 256 --noise-threshold 0.01 --min-spp 8 \
        --samples-map "$scratch/furnace-map.exr" --quiet; then
    stats_of "$out" --crop 20,20,44,44
    range=$(stat_range G)
    if within "${range% *}" 0.5 0.001 && within "${range#* }" 0.5 0.001; then
        pass "adaptive furnace: every pixel inside the sphere is the albedo 0.5 (min/max $range)"
    else fail "adaptive furnace: pixels inside the sphere" "min/max $range, expected 0.5"; fi
    samples=$(stat_range samples)
    if [ "$samples" = "8 8" ]; then pass "adaptive furnace: the noiseless pixels stop at --min-spp 8"
    else fail "adaptive furnace: the noiseless pixels stop at --min-spp" "samples min/max $samples, expected 8 8"; fi
    stats_of "$out"
    most=$(stat_range samples)
    if [ "${most#* }" -gt 64 ]; then pass "adaptive furnace: the silhouette takes more samples (at most ${most#* })"
    else fail "adaptive furnace: the silhouette takes more samples" "samples min/max $most"; fi
    if [ "$(stat_metadata stop_reason)" = noise ] && [ "$(stat_metadata complete)" = 1 ] &&
            [ "$(stat_metadata min_spp)" = 8 ] && within "$(stat_metadata noise_threshold)" 0.01 1e-6; then
        pass "adaptive furnace: metadata stop_reason noise, complete 1, min_spp 8, noise_threshold 0.01"
    else fail "adaptive furnace: metadata" "$(grep -E 'stop_reason|complete|min_spp|noise_threshold' "$scratch/stats" | tr '\n' ' ')"; fi
else
    fail "adaptive furnace" "render failed"
fi

# ---- the samples map (--samples-map): a heat map, one colour where the counts are one (the
# sphere's pixels, all at --min-spp), brighter where there are more (inferno's colours
# brighten along the map), and inferno's yellow at --spp (a fixed render: every pixel; R and G
# near 1, B under half of them)
if stats_of "$scratch/furnace-map.exr" --crop 20,20,44,44; then
    inside=$(stat_range G) inside_red=$(stat_range R)
    stats_of "$scratch/furnace-map.exr"
    whole=$(stat_range G)
    if [ "${inside% *}" = "${inside#* }" ] && [ "${inside_red% *}" = "${inside_red#* }" ] &&
            awk -v i="${inside#* }" -v w="${whole#* }" 'BEGIN { exit !(w > i + 0.05) }'; then
        pass "the samples map is one colour over the sphere's pixels (G $inside) and brighter at the silhouette (G up to ${whole#* })"
    else fail "the samples map of the adaptive furnace" "inside G $inside, R $inside_red; whole image G $whole"; fi
else fail "the samples map" "no map written"; fi
if "$program" render scenes/furnace.txt -o "$scratch/fixed-map-render.exr" --size 16x16 --spp 4 \
        --samples-map "$scratch/fixed-map.exr" --quiet && stats_of "$scratch/fixed-map.exr" &&
        awk -v r="$(stat_range R)" -v g="$(stat_range G)" -v b="$(stat_range B)" 'BEGIN {
            split(r, R, " "); split(g, G, " "); split(b, B, " ")
            exit !(R[1] == R[2] && G[1] == G[2] && B[1] == B[2] && R[1] > 0.9 && G[1] > 0.9 && B[1] < 0.5 * R[1]) }'; then
    pass "a render whose pixels all took --spp has the map's yellow everywhere (R $(stat_range R))"
else fail "the samples map at --spp" "R $(stat_range R), G $(stat_range G), B $(stat_range B)"; fi

# ---- a plane under a uniform sky with a glass ball (tests/render/scenes/adaptive-glass-ball.txt)
scene=tests/render/scenes/adaptive-glass-ball.txt
render_options=
adaptive=$scratch/adaptive.exr
fixed=$scratch/fixed.exr
coarse=$scratch/coarse.exr
if render "$adaptive" --noise-threshold 0.02 && render "$fixed" --seed 4 && render "$coarse" --spp 32; then
    # Where the samples went: the flat plane in the top right corner, far from the ball,
    # stops at the minimum; the ball and its foot (the middle of the image) go on.
    flat=$(channel_mean "$adaptive" samples 48,0,64,12)
    ball=$(channel_mean "$adaptive" samples 24,16,40,32)
    if awk -v f="$flat" -v b="$ball" 'BEGIN { exit !(f < 20 && b > 8 * f) }'; then
        pass "adaptive: the flat plane takes $flat samples per pixel, the glass ball $ball"
    else fail "adaptive: samples where the noise is" "flat plane $flat, glass ball $ball samples per pixel"; fi
    # Unbiased: the mean of the image and of the ball agree with an independent fixed
    # 256-spp render (seed 4) within noise (measured: 0.01% and 0.2%)...
    for crop in 0,0,64,48 24,16,40,32; do
        a=$(channel_mean "$adaptive" G "$crop")
        f=$(channel_mean "$fixed" G "$crop")
        if within "$a" "$f" 0.01; then pass "adaptive agrees with a fixed-spp render over $crop (G $a and $f)"
        else fail "adaptive agrees with a fixed-spp render over $crop" "G $a, fixed 256 spp $f: over 1% apart"; fi
    done
    # ... and per pixel its error is that of well sampled pixels: its RMS difference from
    # the independent render is under that of a fixed 32-spp render (measured: 0.0055
    # and 0.011), at a mean of about 57 samples per pixel.
    rms_adaptive=$("$program" diff "$adaptive" "$fixed" | sed -n 's/^rms error: //p')
    rms_coarse=$("$program" diff "$coarse" "$fixed" | sed -n 's/^rms error: //p')
    if awk -v a="$rms_adaptive" -v c="$rms_coarse" 'BEGIN { exit !(a != "" && a < c) }'; then
        pass "adaptive: RMS difference $rms_adaptive from a fixed 256-spp render, under 32 spp's $rms_coarse"
    else fail "adaptive: per-pixel error" "RMS $rms_adaptive, fixed 32 spp $rms_coarse"; fi
    stats_of "$fixed"
    if [ "$(stat_metadata stop_reason)" = spp ] && [ "$(stat_metadata noise_threshold)" = 0 ] &&
            [ "$(stat_metadata min_spp)" = 0 ]; then
        pass "fixed spp: metadata stop_reason spp, noise_threshold 0, min_spp 0"
    else fail "fixed spp: metadata" "$(grep -E 'stop_reason|min_spp|noise_threshold' "$scratch/stats" | tr '\n' ' ')"; fi
else
    fail "adaptive glass ball" "a render failed"
fi

# ---- tiles and crops rendered adaptively are exactly the full render's pixels and counts
# (the render traces the pixels whose decisions reach into the region, core/render.h)
if [ -f "$adaptive" ] && render "$scratch/tile0.exr" --noise-threshold 0.02 --tile 0/3 &&
        render "$scratch/tile1.exr" --noise-threshold 0.02 --tile 1/3 &&
        render "$scratch/tile2.exr" --noise-threshold 0.02 --tile 2/3 &&
        "$program" merge "$scratch/tile0.exr" "$scratch/tile1.exr" "$scratch/tile2.exr" -o "$scratch/merged.exr" \
            --quiet; then
    same "adaptive tiles merge into the adaptive full render exactly" "$scratch/merged.exr" "$adaptive"
    same_counts=yes
    for crop in 0,0,64,48 0,14,64,18 20,30,44,34 0,0,1,48; do
        if [ "$("$program" stats "$scratch/merged.exr" --crop $crop | grep '^channel')" != \
             "$("$program" stats "$adaptive" --crop $crop | grep '^channel')" ]; then same_counts="no, over $crop"; fi
    done
    if [ "$same_counts" = yes ]; then pass "adaptive tiles merge with the full render's sample counts"
    else fail "adaptive tiles merge with the full render's sample counts" "$same_counts"; fi
else
    fail "adaptive tiles" "a tile render or the merge failed"
fi
if [ -f "$adaptive" ] && render "$scratch/crop.exr" --noise-threshold 0.02 --crop 20,10,50,30; then
    "$program" stats "$scratch/crop.exr" | grep '^channel' >"$scratch/crop-stats"
    "$program" stats "$adaptive" --crop 20,10,50,30 | grep '^channel' >"$scratch/full-crop-stats"
    if cmp -s "$scratch/crop-stats" "$scratch/full-crop-stats"; then
        pass "an adaptive crop has the full render's pixels and sample counts there"
    else fail "an adaptive crop" "$(tr '\n' ' ' <"$scratch/crop-stats") vs $(tr '\n' ' ' <"$scratch/full-crop-stats")"; fi
else
    fail "adaptive crop" "render failed"
fi

# ---- compacted passes (core/gpu_compact.c: only the pixels still going, packed densely,
# each pixel's samples in runs traced side by side) trace the samples that passes over the
# whole image trace: the same sample counts, and the same sums but for float rounding
# (each run is summed from zero and the runs added in order, where a full pass adds sample
# after sample: 1e-4 is about 20 times the largest difference seen, 4.8e-6 on a Cornell
# box pixel of 15); with light group layers too (added at the pixel itself, in one run,
# so their statistics are equal to the last digit), and the Cornell box's scattered pixels
compact=$scratch/compact.exr
full=$scratch/full-passes.exr
if render "$compact" --noise-threshold 0.02 --light-groups &&
        RTSPHERES_TEST_FULL_PASSES=1 render "$full" --noise-threshold 0.02 --light-groups &&
        "$program" render scenes/cornell.txt -o "$scratch/cornell-compact.exr" --size 48x48 --spp 256 \
            --noise-threshold 0.1 --quiet &&
        RTSPHERES_TEST_FULL_PASSES=1 "$program" render scenes/cornell.txt -o "$scratch/cornell-full.exr" \
            --size 48x48 --spp 256 --noise-threshold 0.1 --quiet; then
    for pair in "$compact $full" "$scratch/cornell-compact.exr $scratch/cornell-full.exr"; do
        a=${pair%% *} b=${pair#* }
        # RGB within rounding; every other channel (samples, the light group layers) by its
        # statistics
        "$program" stats "$a" | grep "^channel" | grep -v "^channel [RGB]:" >"$scratch/compact.stats"
        "$program" stats "$b" | grep "^channel" | grep -v "^channel [RGB]:" >"$scratch/full.stats"
        if "$program" diff "$a" "$b" --fail 1e-4 --failpercent 0 >"$scratch/compact.diff" 2>&1 &&
                cmp -s "$scratch/compact.stats" "$scratch/full.stats"; then
            pass "compacted passes give the samples of full passes ($(basename "$a"), $(grep "^max error" "$scratch/compact.diff"), $(wc -l <"$scratch/full.stats") other channels equal)"
        else fail "compacted passes give the samples of full passes ($(basename "$a"))" \
            "$(tr '\n' ' ' <"$scratch/compact.diff") $(diff "$scratch/compact.stats" "$scratch/full.stats" | tr '\n' ' ')"; fi
    done
else fail "compacted passes" "a render failed"; fi

# ---- runs that do not all fit in the slots go in rounds (core/gpu_compact.c), whose sums
# add up as one round's do: the same image bit for bit with room for 64 slots a round
if "$program" render scenes/cornell.txt -o "$scratch/cornell-rounds.exr" --size 48x48 --spp 256 \
        --noise-threshold 0.1 --quiet && RTSPHERES_TEST_COMPACT_SLOTS=64 "$program" render scenes/cornell.txt \
        -o "$scratch/cornell-rounds-64.exr" --size 48x48 --spp 256 --noise-threshold 0.1 --quiet; then
    same "compacted runs in rounds of 64 slots give the image of one round bit for bit" \
        "$scratch/cornell-rounds-64.exr" "$scratch/cornell-rounds.exr"
else fail "compacted runs in rounds" "a render failed"; fi

# ---- a stopped adaptive render resumes to the uninterrupted image bit for bit, sample
# counts too: its partial keeps the adaptive state (render.h: the sums at its last check,
# or before its first, whose samples are each pixel's first ones), from which the resumed
# render makes the same checks (adaptive.h adaptive_resume). Stopped (as --time-limit
# stops, RTSPHERES_TEST_STOP_AFTER_PASSES) before the first check (3 passes of 200 units),
# just after it (45) and between later checks (80: some pixels have stopped, and the
# samples traced since the last check, in R, G, B and samples, are traced again); a
# render resumed from the last stopped again before its first check, and resumed again.
# The reference is cornell-rounds.exr above (the same options; the budget changes nothing).
options="--size 48x48 --spp 256 --noise-threshold 0.1"
"$program" stats "$scratch/cornell-rounds.exr" | grep "^channel samples" >"$scratch/whole.samples"
for passes in 3 45 80; do
    part=$scratch/stopped-$passes.exr resumed=$scratch/resumed-$passes.exr
    # shellcheck disable=SC2086 # $options is a list of options
    if RTSPHERES_TEST_STOP_AFTER_PASSES=$passes "$program" render scenes/cornell.txt -o "$part" $options \
            --pass-budget 200 --quiet && [ "$(metadata "$part" stop_reason)" = time ] &&
            "$program" render scenes/cornell.txt -o "$resumed" $options --resume "$part" --quiet; then
        state=$(channel_mean "$part" adaptive.samples) traced=$(channel_mean "$part" samples)
        "$program" stats "$resumed" | grep "^channel samples" >"$scratch/resumed.samples"
        if "$program" diff "$resumed" "$scratch/cornell-rounds.exr" --fail 0 --failpercent 0 >"$scratch/diff" 2>&1 &&
                cmp -s "$scratch/resumed.samples" "$scratch/whole.samples"; then
            pass "an adaptive render stopped after $passes passes (state $state of $traced samples a pixel) resumes bit for bit"
        else fail "an adaptive render stopped after $passes passes resumes bit for bit" \
            "$(tr '\n' ' ' <"$scratch/diff") $(cat "$scratch/resumed.samples") against $(cat "$scratch/whole.samples")"; fi
    else fail "an adaptive render stopped after $passes passes resumes" "a render failed, or no stop_reason time"; fi
done
state=$(channel_mean "$scratch/stopped-80.exr" adaptive.samples) traced=$(channel_mean "$scratch/stopped-80.exr" samples)
if awk -v s="$state" -v t="$traced" 'BEGIN { exit !(s > 16 && s < t) }'; then
    pass "the render stopped after 80 passes had made checks and traced past the last ($state < $traced)"
else fail "the render stopped after 80 passes is between checks" "state $state, traced $traced samples a pixel"; fi
# shellcheck disable=SC2086
if RTSPHERES_TEST_STOP_AFTER_PASSES=2 "$program" render scenes/cornell.txt -o "$scratch/stopped-twice.exr" $options \
        --pass-budget 200 --resume "$scratch/stopped-80.exr" --quiet &&
        "$program" render scenes/cornell.txt -o "$scratch/resumed-twice.exr" $options \
        --resume "$scratch/stopped-twice.exr" --quiet; then
    same "an adaptive render resumed, stopped again and resumed again equals the uninterrupted one bit for bit" \
        "$scratch/resumed-twice.exr" "$scratch/cornell-rounds.exr"
else fail "an adaptive render resumed twice" "a render failed"; fi
# With --aovs a resumed render leaves out the emission sums (a partial keeps none): another
# tracer program, whose sums round differently, so the image is the same to float rounding.
# shellcheck disable=SC2086
if "$program" render scenes/cornell.txt -o "$scratch/aovs-whole.exr" $options --aovs --quiet &&
        RTSPHERES_TEST_STOP_AFTER_PASSES=60 "$program" render scenes/cornell.txt -o "$scratch/aovs-part.exr" $options \
        --aovs --pass-budget 200 --quiet &&
        "$program" render scenes/cornell.txt -o "$scratch/aovs-resumed.exr" $options --aovs \
        --resume "$scratch/aovs-part.exr" --quiet &&
        "$program" diff "$scratch/aovs-resumed.exr" "$scratch/aovs-whole.exr" --fail 1e-5 --failpercent 0 \
        >"$scratch/diff" 2>&1; then
    pass "an adaptive render with --aovs resumes to float rounding ($(grep "^max error" "$scratch/diff"))"
else fail "an adaptive render with --aovs resumes" "$(tr '\n' ' ' <"$scratch/diff")"; fi
# Without --noise-threshold the same partial continues as a fixed render, from the state
# (each pixel's first samples; R, G, B and samples hold others too): the fixed render's
# image to float rounding (its sums were added in runs), every pixel with every sample.
if "$program" render scenes/cornell.txt -o "$scratch/cornell-fixed.exr" --size 48x48 --spp 256 --quiet &&
        "$program" render scenes/cornell.txt -o "$scratch/fixed-resumed.exr" --size 48x48 --spp 256 \
        --resume "$scratch/stopped-80.exr" --quiet &&
        "$program" diff "$scratch/fixed-resumed.exr" "$scratch/cornell-fixed.exr" --fail 1e-5 --failpercent 0 \
        >"$scratch/diff" 2>&1 && [ "$(channel_range "$scratch/fixed-resumed.exr" samples)" = "256 256" ]; then
    pass "an adaptive partial resumed without --noise-threshold gives the fixed render ($(grep "^max error" "$scratch/diff"))"
else fail "an adaptive partial resumed without --noise-threshold" "$(tr '\n' ' ' <"$scratch/diff")"; fi
# Another --min-spp has other checks (20, 40, 60, ...): the state does not fit them.
# shellcheck disable=SC2086
expect_refusal "resuming an adaptive partial with another --min-spp is refused" \
    "of this render's schedule .--min-spp 20, --spp 256" "$scratch/refused" \
    "$program" render scenes/cornell.txt -o "$scratch/refused/x.exr" $options --min-spp 20 \
    --resume "$scratch/stopped-80.exr"

# ---- where the slots lie changes no pixel: on llvmpipe with two or more rasteriser threads
# a compacted pass deals its blocks of slots to 64-wide tile columns (core/gpu_compact.c
# balanced_tile_columns), elsewhere along whole rows; 136x64 has room for two columns, and
# all but the last list take them
if RTSPHERES_TEST_TILE_COLUMNS=0 "$program" render scenes/cornell.txt -o "$scratch/cornell-rows.exr" --size 136x64 \
        --spp 256 --noise-threshold 0.1 --quiet && RTSPHERES_TEST_TILE_COLUMNS=2 "$program" render \
        scenes/cornell.txt -o "$scratch/cornell-columns.exr" --size 136x64 --spp 256 --noise-threshold 0.1 --quiet; then
    same "compacted slots in two tile columns give the image of slots along the rows bit for bit" \
        "$scratch/cornell-columns.exr" "$scratch/cornell-rows.exr"
else fail "compacted slots in tile columns" "a render failed"; fi

# ---- AOVs come with adaptive sampling as without it
if render "$scratch/aovs.exr" --noise-threshold 0.05 --aovs && stats_of "$scratch/aovs.exr" &&
        [ -n "$(stat_mean variance.Y)" ] && [ -n "$(stat_mean depth.Z)" ]; then
    pass "adaptive sampling with --aovs writes the AOV layers"
else fail "adaptive sampling with --aovs" "$(head -c 300 "$scratch/stats")"; fi

# ---- refusals: exit 2, a clear message, nothing written
dir=$scratch/refused
expect_refusal "--noise-threshold with --shard-by samples is refused" \
    "cannot be combined with --shard-by samples: each part would stop its pixels on its own samples" "$dir" \
    "$program" render "$scene" -o "$dir/x.exr" --noise-threshold 0.05 --shard 0/2 --shard-by samples
expect_refusal "--noise-threshold with --shard (by samples, the default for one image) is refused" \
    "cannot be combined with --shard-by samples" "$dir" \
    "$program" render "$scene" -o "$dir/x.exr" --noise-threshold 0.05 --shard 1/2
expect_refusal "--noise-threshold with --samples is refused" "cannot be combined with --samples" "$dir" \
    "$program" render "$scene" -o "$dir/x.exr" --noise-threshold 0.05 --samples 0:16
expect_refusal "--noise-threshold resuming a partial without the adaptive state is refused" \
    "resumes from the adaptive state a partial file of one keeps .adaptive.sum.R, ...., and this partial has none" \
    "$dir" "$program" render "$scene" -o "$dir/x.exr" --noise-threshold 0.05 --spp 32 --resume "$coarse"
expect_refusal "--noise-threshold resuming part of an image is refused" \
    "cannot --resume part of an image .--crop, --tile, --shard-by tiles." "$dir" \
    "$program" render "$scene" -o "$dir/x.exr" --noise-threshold 0.05 --crop 0,0,16,16 --resume "$adaptive"
expect_refusal "--min-spp without --noise-threshold is refused" "--min-spp does nothing without --noise-threshold" \
    "$dir" "$program" render "$scene" -o "$dir/x.exr" --min-spp 8
for bad in 0 -1 abc nan; do
    expect_refusal "--noise-threshold $bad is refused" "--noise-threshold wants a positive number" "$dir" \
        "$program" render "$scene" -o "$dir/x.exr" --noise-threshold "$bad"
done
expect_refusal "--min-spp 1 is refused" "--min-spp wants a whole number from 2" "$dir" \
    "$program" render "$scene" -o "$dir/x.exr" --noise-threshold 0.05 --min-spp 1
finish
