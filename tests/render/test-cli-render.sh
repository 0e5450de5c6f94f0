#!/bin/sh
# test-cli-render.sh: the render command from a user's side: options, -D, determinism,
# and failures that must give a clear message and exit code while losing nothing.
#   usage: sh tests/render/test-cli-render.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

small="--size 16x12 --spp 2 --quiet"
scene=scenes/materials/lambertian.txt

# Usage errors: exit 2 with a message that says what is wrong.
expect_exit "no arguments" 2 "usage" "$program"
expect_exit "unknown command" 2 "unknown command" "$program" paint
expect_exit "unknown option" 2 "" "$program" render $scene -o "$scratch/a.exr" --bogus
expect_exit "missing output" 2 "no output file" "$program" render $scene
expect_exit "missing scene" 2 "which scene" "$program" render -o "$scratch/a.exr"
expect_exit "unknown output extension" 2 "cannot tell the format" "$program" render $scene -o "$scratch/a.bmpx"
expect_exit "bad --spp" 2 "--spp wants" "$program" render $scene -o "$scratch/a.exr" --spp 0
expect_exit "bad --size" 2 "--size wants" "$program" render $scene -o "$scratch/a.exr" --size 0x0
expect_exit "bad --size text" 2 "--size wants" "$program" render $scene -o "$scratch/a.exr" --size big
expect_exit "bad -D" 2 "-D wants NAME=VALUE" "$program" render $scene -o "$scratch/a.exr" -D novalue
expect_exit "output directory missing" 2 "directory does not exist" \
    "$program" render $scene -o "$scratch/no/such/dir/a.exr" $small

# Bad scenes: exit 2 with file:line:column.
expect_exit "scene file missing" 2 "no-such-scene.txt" "$program" render "$scratch/no-such-scene.txt" -o "$scratch/a.exr"
printf 'camera from 0 0 1 at 0 0 0\nsphere 0 0 0 -1 nothing\n' >"$scratch/bad.txt"
expect_exit "bad scene names file:line:column" 2 "bad.txt:2:[0-9]+:" "$program" render "$scratch/bad.txt" -o "$scratch/a.exr"
expect_exit "-D of an unknown variable" 2 "nosuchvariable" \
    "$program" render scenes/furnace.txt -o "$scratch/a.exr" -D nosuchvariable=1 $small

# Nothing the user had is lost: a failed render leaves an existing output as it was, and
# the scene file is never the output.
printf 'precious' >"$scratch/keep.png"
"$program" render "$scratch/bad.txt" -o "$scratch/keep.png" 2>/dev/null
if [ "$(cat "$scratch/keep.png")" = precious ]; then pass "failed render keeps the existing output"
else fail "failed render keeps the existing output" "keep.png was changed"; fi
cp scenes/furnace.txt "$scratch/scene.exr"
expect_exit "output is the scene file" 2 "refusing to overwrite" "$program" render "$scratch/scene.exr" -o "$scratch/scene.exr"
if cmp -s scenes/furnace.txt "$scratch/scene.exr"; then pass "scene file untouched"
else fail "scene file untouched" "it changed"; fi
leftovers=$(find "$scratch" -name '*.tmp*' | head -3)
if [ -z "$leftovers" ]; then pass "no temporary files left behind"
else fail "no temporary files left behind" "$leftovers"; fi

# Determinism: the same command gives the same image; another seed gives another.
"$program" render $scene -o "$scratch/seed1a.exr" $small --seed 1 &&
"$program" render $scene -o "$scratch/seed1b.exr" $small --seed 1 &&
"$program" render $scene -o "$scratch/seed2.exr" $small --seed 2
if "$program" diff "$scratch/seed1a.exr" "$scratch/seed1b.exr" --fail 0 --failpercent 0 --quiet >/dev/null; then
    pass "same seed, same image"
else fail "same seed, same image" "two renders with --seed 1 differ"; fi
if "$program" diff "$scratch/seed1a.exr" "$scratch/seed2.exr" --fail 0 --failpercent 0 --quiet >/dev/null; then
    fail "other seed, other image" "--seed 1 and --seed 2 rendered the same image"
else pass "other seed, other image"; fi

# Options reach the render: size, spp and max depth land in the EXR.
"$program" render $scene -o "$scratch/opts.exr" --size 20x10 --spp 3 --max-depth 5 --quiet
size=$("$program" stats "$scratch/opts.exr" | sed -n 's/^size: //p')
if [ "$size" = 20x10 ] && [ "$(metadata "$scratch/opts.exr" spp)" = 3 ] && [ "$(metadata "$scratch/opts.exr" max_depth)" = 5 ] &&
   [ "$(channel_mean "$scratch/opts.exr" samples)" = 3 ]; then
    pass "--size, --spp and --max-depth are applied"
else fail "--size, --spp and --max-depth are applied" "size $size, metadata spp $(metadata "$scratch/opts.exr" spp)"; fi

# -D reaches the scene: the furnace's albedo variable changes the image.
"$program" render scenes/furnace.txt -o "$scratch/d03.exr" -D albedo=0.3 --size 32x32 --spp 2 --quiet
mean=$(channel_mean "$scratch/d03.exr" G 12,12,20,20)
if within "$mean" 0.3 0.001; then pass "-D albedo=0.3 changes the scene (centre $mean)"
else fail "-D albedo=0.3" "centre mean $mean, expected 0.3"; fi

# 8-bit output: a PNG with three channels of the same size.
if "$program" render $scene -o "$scratch/out.png" $small && [ "$("$program" stats "$scratch/out.png" | sed -n 's/^channels: //p')" = 3 ]; then
    pass "PNG output"
else fail "PNG output" "no 3-channel PNG written"; fi

expect_exit "info runs" 0 "" "$program" info

# --verbose says how a point's light to sample is picked (render.h render_light_choice).
light_choice() {
    "$program" render "$@" --size 8x8 --spp 1 -o "$scratch/choice.png" --verbose 2>&1 |
        sed -n 's/^rtspheres: scene: .* instances, \([^;]*\);.*/\1/p'
}
for case in "scenes/many-lights.txt|70 lights (chosen by a light tree 7 levels deep)" \
            "scenes/many-lights.txt --light-tree off|70 lights (chosen by power)" \
            "scenes/lights.txt|4 lights (chosen by the point)" \
            "scenes/lights.txt --integrator whitted|4 lights (each sampled at every point)" \
            "scenes/lights.txt --light-sampling off|4 lights (not sampled)" \
            "scenes/cornell.txt|1 lights"; do
    arguments=${case%%|*} expected=${case#*|}
    # shellcheck disable=SC2086
    said=$(light_choice $arguments)
    if [ "$said" = "$expected" ]; then pass "--verbose: $arguments: $said"
    else fail "--verbose: $arguments" "said '$said', expected '$expected'"; fi
done
finish
