#!/bin/sh
# test-pass-budget.sh: the per-pass work bound. llvmpipe silently ends every loop of a
# shader invocation after 65,535 iterations in total, so a renderer that runs a long path
# in one invocation renders a wrong image with no error. These scenes need far more than
# that per sample; the shader counts the segments it traced, and the image must not
# depend on how the work is split into passes.
#   usage: sh tests/render/test-pass-budget.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# Every sample in the mirror cell runs exactly depth = 20000 segments (see the scene).
for budget in adaptive 7 5000; do
    out="$scratch/mirror-cell-$budget.exr"
    option=""
    [ "$budget" = adaptive ] || option="--pass-budget $budget"
    # shellcheck disable=SC2086
    if "$program" render tests/render/scenes/mirror-cell.txt -o "$out" --quiet $option; then
        segments=$(metadata "$out" path_segments)
        samples=$(metadata "$out" samples_finished)
        if [ "$segments" = 1280000 ] && [ "$samples" = 64 ]; then
            pass "mirror cell, pass budget $budget: all 64 samples ran all 20000 segments"
        else
            fail "mirror cell, pass budget $budget" "$samples samples, $segments segments; expected 64 and 1280000"
        fi
    else
        fail "mirror cell, pass budget $budget" "render failed"
    fi
done

# Long random paths between mirrors and diffuse balls: the same image however the work
# is split (one pass per few segments, or as much as the budget allows).
reference="$scratch/deep-adaptive.exr"
if "$program" render scenes/deep-mirrors.txt -o "$reference" --size 16x16 --spp 2 --quiet; then
    segments=$(metadata "$reference" path_segments)
    if awk -v s="$segments" 'BEGIN { exit !(s / (16 * 16 * 2) > 300) }'; then
        pass "deep mirrors: $segments segments, over 300 per sample"
    else
        fail "deep mirrors" "only $segments segments; the scene no longer stresses the bound"
    fi
    for budget in 64 50000; do
        out="$scratch/deep-$budget.exr"
        if "$program" render scenes/deep-mirrors.txt -o "$out" --size 16x16 --spp 2 --pass-budget $budget --quiet; then
            if "$program" diff "$out" "$reference" --fail 0 --failpercent 0 --quiet >/dev/null; then
                pass "deep mirrors: pass budget $budget gives the same image"
            else
                fail "deep mirrors: pass budget $budget" "image differs from the adaptive render"
            fi
        else
            fail "deep mirrors, pass budget $budget" "render failed"
        fi
    done
else
    fail "deep mirrors" "render failed"
fi

# same_at_budgets NAME SCENE [OPTIONS...]: one check: SCENE rendered with OPTIONS at the
# smallest pass budget (300) and the largest (50000) gives the same image, bit for bit,
# and every channel the same mean, minimum and maximum (the sums held in registers
# through a pass, glsl/direct_emission.glsl and glsl/light_groups.glsl, among them).
same_at_budgets() {
    name=$1 scene=$2
    shift 2
    stem=$(printf '%s' "$name" | tr -c 'a-z0-9' '-')
    for budget in 300 50000; do
        if ! "$program" render "$scene" -o "$scratch/$stem-$budget.exr" --pass-budget $budget --quiet "$@" \
            2>"$scratch/$stem-$budget.log"; then
            fail "$name, pass budget $budget" "render failed: $(tr '\n' ' ' <"$scratch/$stem-$budget.log")"
            return
        fi
    done
    for budget in 300 50000; do
        "$program" stats "$scratch/$stem-$budget.exr" | grep '^channel' >"$scratch/$stem-$budget.channels"
    done
    if "$program" diff "$scratch/$stem-50000.exr" "$scratch/$stem-300.exr" --fail 0 --failpercent 0 \
        >"$scratch/$stem.diff" 2>&1 && cmp -s "$scratch/$stem-50000.channels" "$scratch/$stem-300.channels"; then
        pass "$name: the largest pass budget renders the image of the smallest"
    else
        fail "$name" "$(tr '\n' ' ' <"$scratch/$stem.diff") $(diff "$scratch/$stem-50000.channels" \
            "$scratch/$stem-300.channels" | head -n 4 | tr '\n' ' ')"
    fi
}

# Every loop the tracer has, in every segment (see the scene): the smallest budget (a
# segment or so per pass) and the largest the device allows (50000 asks for the most;
# it is clamped to `rtspheres info`'s bound) must give the same image, for both
# integrators and for the whole tracer. A loop missing from the shader's work count
# shows here: llvmpipe cuts a large pass short, silently, and the image changes.
for variant in path whitted full; do
    case $variant in
        path) options="" ;;
        whitted) options="--integrator whitted" ;;
        full) options="--full-tracer" ;;
    esac
    # shellcheck disable=SC2086
    same_at_budgets "loop stress ($variant)" tests/render/scenes/loop-stress.txt $options
done

# The direct emission sums (--aovs) and light group layers, which a pass holds in registers
# and stores at its end: a pass boundary anywhere must leave them as they are.
same_at_budgets "lights, AOVs" scenes/lights.txt --size 32x18 --spp 16 --aovs
same_at_budgets "lights, light groups" scenes/lights.txt --size 32x18 --spp 16 --light-groups

# Many lights (70: the light tree) and paths whose next emitter hit comes in the next pass:
# the choice memo (the normal the walk used, glsl/lights.glsl choose_light_at) must come
# through the pass state, or MIS weighs those hits otherwise and the image changes.
same_at_budgets "many lights (light tree)" scenes/many-lights.txt --size 12x8 --spp 64

# A Whitted vertex's shadow rays to 16 lights through foggy balls, at the largest budget
# (see the scene): the render must not reach the work cap, and gives the image of the
# smallest budget.
same_at_budgets "lights behind volumes (whitted)" tests/render/scenes/lights-behind-volumes.txt --integrator whitted

# Passes that skip finished pixels (core/gpu.h gpu_tracer_cull_finished; on their own only
# for images of 512x512 pixels or more, RTSPHERES_TEST_CULL forces them on or off): the
# last passes of a render with many small passes, where a few pixels behind glass take
# the longest, must leave every channel as passes over the whole image do: the beauty,
# light group layers, AOVs, samples and variance.
same_with_culling() {
    name=$1 scene=$2
    shift 2
    stem=$(printf '%s' "$name" | tr -c 'a-z0-9' '-')
    for mode in always never; do
        if ! RTSPHERES_TEST_CULL=$mode "$program" render "$scene" -o "$scratch/$stem-$mode.exr" --pass-budget 300 \
            --verbose "$@" 2>"$scratch/$stem-$mode.log"; then
            fail "$name, culling $mode" "render failed: $(tr '\n' ' ' <"$scratch/$stem-$mode.log")"
            return
        fi
        "$program" stats "$scratch/$stem-$mode.exr" | grep -v render_seconds >"$scratch/$stem-$mode.stats"
    done
    culled=$(sed -n 's/.*; \([0-9]*\) of its passes skipped finished pixels.*/\1/p' "$scratch/$stem-always.log")
    never=$(sed -n 's/.*; \([0-9]*\) of its passes skipped finished pixels.*/\1/p' "$scratch/$stem-never.log")
    if [ "${culled:-0}" -gt 0 ] && [ "$never" = 0 ]; then
        pass "$name: $culled passes skipped finished pixels (none when told not to)"
    else
        fail "$name" "passes that skipped finished pixels: '$culled' forced on, '$never' forced off"
    fi
    if "$program" diff "$scratch/$stem-always.exr" "$scratch/$stem-never.exr" --fail 0 --failpercent 0 \
        >"$scratch/$stem.diff" 2>&1 && cmp -s "$scratch/$stem-always.stats" "$scratch/$stem-never.stats"; then
        pass "$name: the same image and channels with and without skipping"
    else
        fail "$name" "$(tr '\n' ' ' <"$scratch/$stem.diff") $(diff "$scratch/$stem-always.stats" \
            "$scratch/$stem-never.stats" | head -n 4 | tr '\n' ' ')"
    fi
}
same_with_culling "three balls, skipping finished pixels" scenes/three-balls.txt --size 64x36 --spp 32 --aovs --variance
same_with_culling "lights, light groups, skipping finished pixels" scenes/lights.txt --size 64x36 --spp 32 \
    --light-groups
finish
