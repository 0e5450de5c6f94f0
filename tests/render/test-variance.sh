#!/bin/sh
# test-variance.sh: `render --variance` on the command line: the layers it adds (exactly
# variance.R/G/B, beside --aovs' variance.Y), that it changes no colour, and its refusals
# (8-bit outputs, --resume). What the layers hold is tests/unit/test_render_variance.c's.
#   usage: sh tests/render/test-variance.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
scene=scenes/three-balls.txt
render_options="--size 32x18 --spp 8 --seed 1"

render "$scratch/plain.exr"
render "$scratch/variance.exr" --variance
render "$scratch/both.exr" --variance --aovs
got=$(channels_of "$scratch/variance.exr")
if [ "$got" = "B G R samples variance.B variance.G variance.R" ]; then
    pass "--variance adds exactly variance.R/G/B"
else fail "--variance layers" "channels '$got'"; fi
got=$(channels_of "$scratch/both.exr")
expected="B G R albedo.B albedo.G albedo.R depth.Z emission.B emission.G emission.R normal.X normal.Y normal.Z samples variance.B variance.G variance.R variance.Y"
if [ "$got" = "$expected" ]; then pass "--variance with --aovs: the AOVs, variance.Y and variance.R/G/B"
else fail "--variance --aovs layers" "channels '$got'"; fi
same "--variance changes no colour" "$scratch/variance.exr" "$scratch/plain.exr"
range=$(channel_range "$scratch/variance.exr" variance.G)
if awk -v r="$range" 'BEGIN { split(r, v, " "); exit !(v[1] >= 0 && v[2] > 0) }'; then
    pass "--variance: never negative, positive somewhere on a noisy 8-spp render ($range)"
else fail "--variance range" "'$range'"; fi
expect_refusal "--variance with a PNG output is refused" "--variance writes extra layers, which only .exr keeps" \
    "$scratch/out" "$program" render "$scene" -o "$scratch/out/a.png" $render_options --variance
expect_refusal "--variance with --resume is refused" "--variance needs the squares of every sample" \
    "$scratch/out" "$program" render "$scene" -o "$scratch/out/a.exr" $render_options --variance \
    --resume "$scratch/plain.exr"
finish
