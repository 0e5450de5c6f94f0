#!/bin/sh
# test-tracer-variants.sh: the tracer is compiled without the code a scene cannot reach
# (no light sampling without lights, no volumes, no textures: gpu.h GPU_OMIT_*), which
# must change no image. Each scene is rendered twice, as it is and with --full-tracer
# (everything compiled in), with the same seed: the images must agree exactly, since the
# code left out never runs for these scenes. A difference means a feature was left out
# that the scene does reach (a wrong GPU_OMIT_* rule in core/render.c), or the shader's
# #ifdef blocks changed what the remaining code computes.
#   usage: sh tests/render/test-tracer-variants.sh PROGRAM SCRATCH_DIR
set -u
program=$1
scratch=$2
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
    if "$program" diff "$scratch/$name.exr" "$scratch/$name-full.exr" --fail 0 --failpercent 0 \
            >"$scratch/$name.diff" 2>&1; then
        pass "tracer variant $name: the same image as the full tracer ($(grep "^max error" "$scratch/$name.diff"))"
    else
        fail "tracer variant $name" "differs from the full tracer: $(tr '\n' ' ' <"$scratch/$name.diff")"
    fi
}

# No lights, no volumes, no textures: all three left out.
check weekend scenes/weekend.txt --max-depth 16
# Lights, but light sampling off: the direct-lighting code left out.
check lights-without-sampling scenes/lights.txt --light-sampling off
# Lights and a volume, no textures.
check cornell-smoke scenes/cornell-smoke.txt
# Textures and image skies: only what the scene lacks is left out.
check textures scenes/textures.txt
# Whitted always keeps direct lighting (its ambient term), even without lights.
check weekend-whitted scenes/weekend.txt --integrator whitted --max-depth 8

finish
