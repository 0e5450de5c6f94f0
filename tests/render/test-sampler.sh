#!/bin/sh
# test-sampler.sh: the two samplers (glsl/random.glsl) render the same image, and the
# Sobol sampler (the default) with less noise. The sampler's own properties (nets,
# independence across pixels, pairs and dimensions) are checked on the device by
# tests/unit/test_random.c; the analytic tests (test-analytic.sh) run with the default.
#   usage: sh tests/render/test-sampler.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# rms A B: the RMS error `rtspheres diff` reports between two images.
rms() {
    "$program" diff "$1" "$2" 2>/dev/null | sed -n 's/^rms error: //p'
}

# For a lit scene, a sky-lit one and a glossy/glass one: the same expectation (image means
# within 1%, at 48x48 and 256 spp both are within ~0.3% of their limit), and at 64 spp the
# difference between two seeds' renders (which is sqrt(2) times one render's error) is
# smaller with Sobol points by at least a fifth. Seen: Sobol's difference is 0.31 of the
# independent one's for the Cornell box, 0.59 for lights.txt and 0.71 for the three balls
# (whose glass and metal send most of its noise through later bounces, where
# stratification helps less).
for scene in scenes/cornell.txt scenes/three-balls.txt scenes/lights.txt; do
    name=$(basename "$scene" .txt)
    for sampler in sobol independent; do
        for seed in 1 2; do
            "$program" render "$scene" -o "$scratch/$name-$sampler-$seed.exr" --size 48x48 --spp 64 --seed $seed \
                --sampler $sampler --quiet || fail "$name $sampler seed $seed" "render failed"
        done
        "$program" render "$scene" -o "$scratch/$name-$sampler-mean.exr" --size 48x48 --spp 256 --seed 9 \
            --sampler $sampler --quiet || fail "$name $sampler 256 spp" "render failed"
    done
    for channel in R G B; do
        sobol=$(channel_mean "$scratch/$name-sobol-mean.exr" $channel)
        independent=$(channel_mean "$scratch/$name-independent-mean.exr" $channel)
        if within "$sobol" "$independent" 0.01; then
            pass "$name: the samplers agree in mean, channel $channel ($sobol, $independent)"
        else
            fail "$name: the samplers agree in mean, channel $channel" "sobol $sobol, independent $independent"
        fi
    done
    sobol=$(rms "$scratch/$name-sobol-1.exr" "$scratch/$name-sobol-2.exr")
    independent=$(rms "$scratch/$name-independent-1.exr" "$scratch/$name-independent-2.exr")
    if awk -v s="$sobol" -v i="$independent" 'BEGIN { exit !(s != "" && i != "" && s < 0.8 * i) }'; then
        pass "$name: Sobol points are less noisy (seed-to-seed RMS $sobol against $independent)"
    else
        fail "$name: Sobol points are less noisy" "seed-to-seed RMS $sobol, independent $independent"
    fi
done

# The sampler decides the image, so it is part of the scene hash: parts made with
# different samplers do not merge.
a=$(metadata "$scratch/cornell-sobol-1.exr" scene_hash)
b=$(metadata "$scratch/cornell-independent-1.exr" scene_hash)
if [ -n "$a" ] && [ "$a" != "$b" ]; then pass "the sampler is part of the scene hash"
else fail "the sampler is part of the scene hash" "hashes '$a' and '$b'"; fi

expect_refusal "--sampler with an unknown name" "--sampler wants sobol or independent" "$scratch/refused" \
    "$program" render scenes/cornell.txt -o "$scratch/refused/x.exr" --sampler halton
finish
