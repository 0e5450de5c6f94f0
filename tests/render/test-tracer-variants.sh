#!/bin/sh
# test-tracer-variants.sh: the tracer is compiled without the code a scene cannot reach
# (gpu.h GPU_OMIT_*: light sampling without lights, volumes, textures, each primitive
# type, instances, emitters; and the integrator and sky type compiled in as constants),
# which must change no image. Each scene is rendered twice, as it is and with
# --full-tracer (everything compiled in, every setting a uniform), with the same seed: the
# code left out never runs for these scenes, so the images agree but for float rounding:
# with the integrator and sky type compiled in as constants LLVM may contract a multiply
# and an add into one fused operation where the uniform version does not (seen: 1.5e-8
# on 9 of 16 pixels of loop-stress.txt; the other scenes agree bit for bit), hence the
# 1e-5 threshold. A feature left out that the scene does reach (a wrong rule in
# core/render.c omitted_features) shows as errors of 0.1 and more (seen: 1.47 with moving
# spheres left out of next-week.txt). Between them the scenes below leave out and keep
# each feature.
#   usage: sh tests/render/test-tracer-variants.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# check NAME SCENE [OPTIONS...]: renders SCENE both ways and compares.
check() {
    name=$1 scene=$2
    shift 2
    if ! "$program" render "$scene" -o "$scratch/$name.exr" --size 64x36 --spp 4 --seed 3 --quiet "$@" \
            2>"$scratch/$name.log" ||
       ! "$program" render "$scene" -o "$scratch/$name-full.exr" --size 64x36 --spp 4 --seed 3 --quiet \
            --full-tracer "$@" 2>>"$scratch/$name.log"; then
        fail "tracer variant $name" "a render failed: $(head -c 300 "$scratch/$name.log")"
        return
    fi
    if "$program" diff "$scratch/$name.exr" "$scratch/$name-full.exr" --fail 1e-5 --failpercent 0 \
            >"$scratch/$name.diff" 2>&1; then
        pass "tracer variant $name: agrees with the full tracer ($(grep "^max error" "$scratch/$name.diff"))"
    else
        fail "tracer variant $name" "differs from the full tracer: $(tr '\n' ' ' <"$scratch/$name.diff")"
    fi
}

# Spheres only: no lights, volumes, textures, triangles, moving spheres, instances or
# emitters; a gradient sky. Still spheres in one level: the BVH walked along the threaded
# lists (core/packed_layout.h), where the full tracer walks it with its stack.
check weekend scenes/weekend.txt --max-depth 16
# The same spheres under a sphere light: shadow rays along the threaded lists too.
check weekend-lamp tests/render/scenes/weekend-lamp.txt --max-depth 16
# Lights, but light sampling off: the direct-lighting code left out; point, spot and sun
# lights, quads and emitters kept.
check lights-without-sampling scenes/lights.txt --light-sampling off
check lights scenes/lights.txt
# Lights and a volume (the smoke boxes are instances), quads, no textures, no spheres.
check cornell-smoke scenes/cornell-smoke.txt
# One quad light (rectangles by solid angle, no light to choose), lambertian and emissive
# materials only; one sphere light with metal and glass; triangle lights (a mesh). The
# Cornell box (quads), three balls and lights.txt (spheres and quads) walk threaded lists.
check cornell scenes/cornell.txt
check three-balls scenes/three-balls.txt
check mesh-light tests/render/scenes/mesh-light.txt
# Seventy lights (quads and points): the light tree walked, the per-point choice of 2 to 8
# lights left out.
check many-lights scenes/many-lights.txt
check many-lights-whitted scenes/many-lights.txt --integrator whitted
# Textures (image, checker, noise, normal maps) and an image sky.
check textures scenes/textures.txt
# Moving spheres, instances, a volume, fog, textures, emitters, a black sky.
check next-week scenes/next-week.txt --size 32x32 --spp 2
# A mesh in instances, a sky box.
check crystal-ball scenes/crystal-ball.txt
check instancing scenes/instancing.txt
# Whitted always keeps direct lighting (its ambient term), even without lights.
check weekend-whitted scenes/weekend.txt --integrator whitted --max-depth 8
check lights-whitted scenes/lights.txt --integrator whitted
# Everything at once: environment light, point/spot/sun, textures, a volume, emitters.
check loop-stress tests/render/scenes/loop-stress.txt --spp 16
# The pbr material (and not its alpha masks or vertex colours), in both integrators; an
# alpha mask with an image (the traversal's alpha test).
check pbr-chart scenes/pbr-chart.txt
check pbr-chart-whitted scenes/pbr-chart.txt --integrator whitted
check pbr-lights tests/render/scenes/pbr-lights.txt
check pbr-mask tests/render/scenes/pbr-mask.txt
# The AOV pass and the denoiser use the render's variant too.
check three-balls-aovs scenes/three-balls.txt --aovs
# --denoise adds the direct emission sums (glsl/direct_emission.glsl), which its denoiser
# reads from 8 samples a pixel on.
check cornell-denoise scenes/cornell.txt --denoise --spp 8

# A tracer that does not compile (a driver's compiler that rejects it) is exit 1 and a
# message with the compiler's error, not the warnings Mesa puts before it (one for every
# global read before it is written: they alone filled the message), and no image.
# RTSPHERES_TEST_SHADER_LINE puts a line of GLSL before the first module (core/gpu_program.c).
rm -f "$scratch/broken.exr"
RTSPHERES_TEST_SHADER_LINE='float broken_line = undeclared_name_for_the_test;' expect_exit \
    "a tracer that does not compile is the compiler's error" 1 \
    "GPU: the fragment shader does not compile: .*error.*undeclared_name_for_the_test" \
    "$program" render scenes/cornell.txt -o "$scratch/broken.exr" --size 16x16 --spp 1 --quiet
if grep -qi 'warning' "$scratch/stderr"; then fail "no compiler warnings in the message" "$(head -c 300 "$scratch/stderr")"
elif [ -e "$scratch/broken.exr" ]; then fail "no image from a tracer that does not compile" "broken.exr written"
else pass "the message holds the error alone, and no image is written"; fi

finish
