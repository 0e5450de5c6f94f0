#!/bin/sh
# test-golden.sh: renders each golden scene small and compares it with golden/NAME.exr
# using `rtspheres diff` at Blender's render-test tolerance (a pixel fails above 0.016,
# the test fails when more than 1% of pixels fail). Goldens catch regressions only;
# test-analytic.sh checks correctness. On failure the amplified difference image is
# kept as golden-diff-NAME.png in the directory given by RTSPHERES_DIFF_DIR (default: the
# scratch directory, which is removed; set it to keep the images).
#   usage: sh tests/render/test-golden.sh PROGRAM SCRATCH_DIR
here=$(dirname "$0")
. "$here/lib.sh"
. "$here/golden-options.sh"
diff_dir=${RTSPHERES_DIFF_DIR:-$scratch}
mkdir -p "$diff_dir"
grep -v '^#' "$here/golden-scenes.txt" | {
    while read -r name scene extra; do
        [ -n "$name" ] || continue
        out="$scratch/$name.exr"
        if [ ! -f "golden/$name.exr" ]; then
            fail "golden $name" "golden/$name.exr is missing (make golden)"
            continue
        fi
        # shellcheck disable=SC2086
        if ! "$program" render "$scene" -o "$out" $golden_render_options $extra; then
            fail "golden $name" "render of $scene failed"
            continue
        fi
        if "$program" diff "$out" "golden/$name.exr" --fail 0.016 --failpercent 1 \
            --diff-out "$diff_dir/golden-diff-$name.png" >"$scratch/$name.diff" 2>&1; then
            pass "golden $name ($(grep '^pixels over' "$scratch/$name.diff"))"
        else
            cat "$scratch/$name.diff"
            fail "golden $name" "differs from golden/$name.exr; difference image: $diff_dir/golden-diff-$name.png"
        fi
    done
    finish
}
