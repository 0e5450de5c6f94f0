#!/bin/sh
# test-placed-lights.sh: emitters of placed objects (shapes in a group with a transform,
# meshes placed by groups and instances) are lights like world ones: the packer bakes
# such a placement into the world (core/pack_collect.c, placement_of), so light
# sampling and the Whitted integrator see them. Spheres under a non-uniform scale stay
# instanced (found by BSDF sampling only): checked too.
#   usage: sh tests/render/test-placed-lights.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# lights_and_instances SCENE [OPTIONS]: "N instances, M lights" from --verbose.
lights_and_instances() {
    scene=$1
    shift
    "$program" render "$scene" -o "$scratch/count.exr" --size 8x8 --spp 1 --verbose "$@" 2>&1 |
        grep -o "[0-9]* instances, [0-9]* lights"
}

# A quad turned over and lifted by a group equals the same quad written in the world,
# in both integrators (the scene swaps which of two identical quads is far away).
scene=tests/render/scenes/placed-light.txt
counts=$(lights_and_instances $scene)
if [ "$counts" = "0 instances, 2 lights" ]; then pass "a placed emissive quad is a light ($counts)"
else fail "a placed emissive quad is a light" "got '$counts', expected 0 instances, 2 lights"; fi
for integrator in path whitted; do
    placed="$scratch/placed-$integrator.exr" world="$scratch/world-$integrator.exr"
    if "$program" render $scene -o "$placed" --integrator $integrator --quiet &&
       "$program" render $scene -o "$world" --integrator $integrator -D world=1 --quiet; then
        if "$program" diff "$placed" "$world" --fail 1e-5 --failpercent 0 >"$scratch/$integrator.diff" 2>&1; then
            floor=$(channel_mean "$placed" R 0,18,48,27)
            if awk -v f="$floor" 'BEGIN { exit !(f > 0.02) }'; then
                pass "$integrator: the placed quad lights the floor as the world quad does (floor mean R $floor)"
            else
                fail "$integrator: the placed quad lights the floor" "floor mean R $floor, expected light"
            fi
        else
            fail "$integrator: placed quad equals the world quad" "$(tr '\n' ' ' <"$scratch/$integrator.diff")"
        fi
    else
        fail "$integrator: placed quad" "render failed"
    fi
done

# An emissive mesh stretched, turned and moved by a group: its 80 triangles are lights,
# and light sampling on and off agree on the lit floor (the same expectation, less noise).
cat >"$scratch/mesh-light.txt" <<SCENE
render size 48 27 spp 512 depth 6 seed 2
camera from 0 2 6 at 0 0.5 0 up 0 1 0 fov 40
sky constant 0 0 0
material floor lambertian 0.7 0.7 0.7
material glow emissive 1 0.9 0.8 strength 4
quad -5 0 -5  0 0 10  10 0 0 floor
group material glow {
    scale 1 0.4 2
    rotate 0 1 0 30
    translate 0.5 1.5 0
    mesh "$(pwd)/scenes/assets/crystal.obj"
}
SCENE
counts=$(lights_and_instances "$scratch/mesh-light.txt")
if [ "$counts" = "0 instances, 80 lights" ]; then pass "a placed emissive mesh is 80 lights"
else fail "a placed emissive mesh is 80 lights" "got '$counts'"; fi
if "$program" render "$scratch/mesh-light.txt" -o "$scratch/mesh-on.exr" --quiet &&
   "$program" render "$scratch/mesh-light.txt" -o "$scratch/mesh-off.exr" --light-sampling off --quiet; then
    on=$(channel_mean "$scratch/mesh-on.exr" R 0,18,48,27)
    off=$(channel_mean "$scratch/mesh-off.exr" R 0,18,48,27)
    if within "$on" "$off" 0.03; then pass "placed mesh light: light sampling on $on, off $off (within 3%)"
    else fail "placed mesh light: light sampling on and off agree" "on $on, off $off"; fi
else
    fail "placed mesh light" "render failed"
fi

# An emissive sphere in a group stretched along y stays an instance (no light); turned
# or not, and scaled uniformly, it is baked: a light of twice the radius.
cat >"$scratch/sphere-light.txt" <<SCENE
set turn 30
set stretch 2
render size 16 9 spp 4 depth 4
camera from 0 1 6 at 0 1 0 up 0 1 0 fov 40
material glow emissive 1 1 1 strength 2
group {
    rotate 0 1 0 \$turn
    scale 2 \$stretch 2
    sphere 0 0.5 0 0.25 glow
}
SCENE
counts=$(lights_and_instances "$scratch/sphere-light.txt" -D stretch=3)
if [ "$counts" = "1 instances, 0 lights" ]; then pass "a stretched emissive sphere stays instanced ($counts)"
else fail "a stretched emissive sphere stays instanced" "got '$counts'"; fi
counts=$(lights_and_instances "$scratch/sphere-light.txt")
if [ "$counts" = "0 instances, 1 lights" ]; then pass "a turned, uniformly scaled emissive sphere is a light ($counts)"
else fail "a turned, uniformly scaled emissive sphere is a light" "got '$counts'"; fi
counts=$(lights_and_instances "$scratch/sphere-light.txt" -D turn=0)
if [ "$counts" = "0 instances, 1 lights" ]; then pass "a uniformly scaled emissive sphere is a light ($counts)"
else fail "a uniformly scaled emissive sphere is a light" "got '$counts'"; fi

finish
