#!/bin/sh
# test-stat-diff.sh: the power of the statistical comparison (`rtspheres diff --test z`),
# which these cases define (issue 16; docs/regression.md has the z-scores they reach):
#   - two renders of a scene with different seeds pass: three balls, and every golden
#     scene at the goldens' sizes (the golden suite run with seed 2 against goldens of
#     seed 1);
#   - it fails when one material's albedo changes by 2% (the diffuse ball), when the light
#     moves by 1% of the scene's size, and when the image is shifted by one pixel;
#   - Mitsuba 3's per-pixel rule alone (--scales none) misses the albedo change: why the
#     block tests are there.
# Renders at the goldens' size and samples (160x90, 64 spp). The comparisons use the
# golden suite's block alpha (0.001), so the power shown is the suite's; the default
# (0.01) is more powerful still. Then the command's own behaviour: exit codes, messages,
# --z-out.
#   usage: sh tests/render/test-stat-diff.sh PROGRAM SCRATCH_DIR
here=$(dirname "$0")
. "$here/lib.sh"
scene=scenes/three-balls.txt
render_options="--size 160x90 --spp 64 --variance"
suite_level="--test z --block-alpha 0.001"

# compare NAME EXPECTED A B [OPTIONS]: one check: diff --test z of A and B (the suite's
# level, then OPTIONS) exits EXPECTED (0 pass, 1 fail); the result line is shown.
compare() {
    lib_name=$1 lib_expected=$2 lib_a=$3 lib_b=$4
    shift 4
    # shellcheck disable=SC2086
    "$program" diff "$lib_a" "$lib_b" $suite_level "$@" >"$scratch/diff.out" 2>"$scratch/diff.err"
    lib_code=$?
    lib_result=$(sed -n 's/^result: //p' "$scratch/diff.out")
    if [ "$lib_code" = "$lib_expected" ]; then
        pass "$lib_name ($lib_result)"
    else
        fail "$lib_name" "exit $lib_code, expected $lib_expected: $lib_result $(head -c 300 "$scratch/diff.err")"
    fi
}

render "$scratch/seed1.exr" --seed 1
render "$scratch/seed2.exr" --seed 2
compare "z test: three balls, seeds 2 and 1, pass" 0 "$scratch/seed2.exr" "$scratch/seed1.exr"
compare "z test at its default levels: seeds 2 and 1 pass" 0 "$scratch/seed2.exr" "$scratch/seed1.exr" \
    --block-alpha 0.01

# One material's albedo 2% higher: the diffuse ball, 0.75 0.2 0.15 -> 0.765 0.204 0.153.
sed 's/^material diffuse lambertian 0.75 0.2 0.15$/material diffuse lambertian 0.765 0.204 0.153/' "$scene" \
    >"$scratch/albedo.txt"
if cmp -s "$scene" "$scratch/albedo.txt"; then
    fail "z test: albedo +2%" "the material line of $scene changed; this test's sed no longer applies"
fi
"$program" render "$scratch/albedo.txt" -o "$scratch/albedo.exr" $render_options --seed 2 --quiet
compare "z test: the diffuse ball's albedo 2% higher fails" 1 "$scratch/albedo.exr" "$scratch/seed1.exr"
compare "z test: Mitsuba's per-pixel rule alone (--scales none) misses the 2% albedo" 0 \
    "$scratch/albedo.exr" "$scratch/seed1.exr" --scales none

# The light moved by 1% of the scene's size: the balls and the light sphere span
# x -3.7..1.7, y 0..4.7, z -0.5..3.7 (the ground sphere aside), a diagonal of 8.3; 1% is
# 0.083, along x (light_x -2.5 -> -2.417).
render "$scratch/light.exr" --seed 2 -D light_x=-2.417
compare "z test: the light moved by 1% of the scene's size fails" 1 "$scratch/light.exr" "$scratch/seed1.exr"

# The image shifted by one pixel: two crops of a render one pixel wider, columns 0..159
# and 1..160 (a crop's pixels are the full render's).
"$program" render "$scene" -o "$scratch/left.exr" $render_options --size 161x90 --crop 0,0,160,90 --seed 1 --quiet
"$program" render "$scene" -o "$scratch/right.exr" $render_options --size 161x90 --crop 1,0,161,90 --seed 2 --quiet
"$program" render "$scene" -o "$scratch/left2.exr" $render_options --size 161x90 --crop 0,0,160,90 --seed 2 --quiet
compare "z test: the same crop with another seed passes" 0 "$scratch/left2.exr" "$scratch/left.exr"
compare "z test: the image shifted by one pixel fails" 1 "$scratch/right.exr" "$scratch/left.exr"

# Every golden scene at the goldens' size: seed 2 against the goldens (seed 1).
sed -e "s|^root .*|root $(pwd)|" -e 's/^render \(.*\)--seed 1/render \1--seed 2/' "$here/golden-scenes.txt" \
    >"$scratch/seed2-suite.txt"
if ! grep -q '^render .*--seed 2' "$scratch/seed2-suite.txt"; then
    fail "golden scenes with seed 2" "golden-scenes.txt has no 'render ... --seed 1' line to change"
fi
"$program" check "$scratch/seed2-suite.txt" >"$scratch/check.out" 2>"$scratch/check.err"
code=$?
summary=$(grep '^check: [0-9]* passed' "$scratch/check.out")
if [ "$code" = 0 ]; then
    pass "z test: every golden scene rendered with seed 2 passes against its golden (${summary#check: })"
else
    fail "golden scenes with seed 2" "exit $code: $(grep -v '^pass' "$scratch/check.out" | tr '\n' '|') $(head -c 300 "$scratch/check.err")"
fi

# ---- the command -------------------------------------------------------------------------
"$program" render "$scene" -o "$scratch/plain.exr" --size 160x90 --spp 64 --seed 3 --quiet
expect_exit "diff --test z: an image without variance layers is exit 2" 2 \
    "image A has no variance.R/G/B layers, which the statistical test needs of both images; render it with --variance" \
    "$program" diff "$scratch/plain.exr" "$scratch/seed1.exr" --test z
"$program" render "$scene" -o "$scratch/plain.png" --size 160x90 --spp 4 --quiet
expect_exit "diff --test z: an image without a samples channel is exit 2" 2 "has no 'samples' channel" \
    "$program" diff "$scratch/plain.png" "$scratch/seed1.exr" --test z
expect_exit "diff: --alpha with the idiff test is refused" 2 "^rtspheres diff: --alpha is an option of --test z, not of --test idiff$" \
    "$program" diff "$scratch/seed1.exr" "$scratch/seed2.exr" --alpha 0.05
expect_exit "diff: --test with a bad value is refused" 2 "^rtspheres diff: --test wants idiff or z, not 'zz'$" \
    "$program" diff "$scratch/seed1.exr" "$scratch/seed2.exr" --test zz
expect_exit "diff: --z-out needs --test z" 2 "--z-out needs --test z" \
    "$program" diff "$scratch/seed1.exr" "$scratch/seed2.exr" --z-out "$scratch/z.png"
expect_exit "diff: --scales with a block of 1 is refused" 2 "--scales wants block sizes of 2 or more" \
    "$program" diff "$scratch/seed1.exr" "$scratch/seed2.exr" --test z --scales 1,4
"$program" diff "$scratch/albedo.exr" "$scratch/seed1.exr" --test z --z-out "$scratch/z.png" \
    --diff-out "$scratch/d.png" >"$scratch/out" 2>&1
if [ -s "$scratch/z.png" ] && [ -s "$scratch/d.png" ] && grep -q "^z-score image: $scratch/z.png" "$scratch/out"; then
    pass "diff --test z --z-out: a failing comparison writes the heat map and the difference image"
else fail "diff --z-out" "$(tr '\n' '|' <"$scratch/out")"; fi
"$program" diff "$scratch/albedo.exr" "$scratch/seed1.exr" --test z --z-out "$scratch/z.exr" >/dev/null 2>&1
if "$program" stats "$scratch/z.exr" | grep -q '^channel significance:'; then
    pass "diff --test z --z-out FILE.exr keeps z.R/G/B and significance"
else fail "diff --z-out exr" "$("$program" stats "$scratch/z.exr" 2>&1 | head -c 300)"; fi
if grep -q '^16x16 blocks: .*: FAIL$' "$scratch/out" && grep -q '^pixel z-scores: mean' "$scratch/out"; then
    pass "diff --test z prints a line per scale, with its verdict"
else fail "diff --test z lines" "$(tr '\n' '|' <"$scratch/out")"; fi
finish
