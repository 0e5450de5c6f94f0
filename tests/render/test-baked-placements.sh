#!/bin/sh
# test-baked-placements.sh: a placement baked into the world (core/pack_collect.c, "which
# placements bake") renders the image the same placement renders as an instance. Baking
# moves the intersection arithmetic from object to world coordinates, so the two differ
# by float rounding (a path that rounding sends another way, at grazing hits): each pair
# must agree at the golden tolerance (a pixel fails over 0.016, at most 1% may) and in
# the mean of each region within 1%.
#
# Each scene is rendered as it is (its placements baked, "0 instances") and with copies
# of its groups hidden where no ray goes (under the floor, which closes the view), so
# many that the copies beyond the first pass the bake budget (262,144 primitives) and the
# visible placements stay instances too.
#   usage: sh tests/render/test-baked-placements.sh PROGRAM SCRATCH_DIR
set -u
program=$1
scratch=$2
. "$(dirname "$0")/lib.sh"

# instances SCENE: "N instances" from --verbose.
instances() {
    "$program" render "$1" -o "$scratch/count.exr" --size 8x8 --spp 1 --verbose 2>&1 | grep -o "[0-9]* instances"
}

# hidden_copies GROUP COUNT DX DY DZ: COUNT instance statements of GROUP, each moved by
# (DX, DY, DZ).
hidden_copies() {
    awk -v group="$1" -v count="$2" -v d="$3 $4 $5" \
        'BEGIN { for (i = 0; i < count; i++) printf "instance %s {\n    translate %s\n}\n", group, d }'
}

# compare NAME SCENE OPTIONS CROPS: renders SCENE baked and with hidden copies (the file
# SCENE-instanced.txt), checks the instance counts, the difference and each crop's mean.
compare() {
    name=$1 scene=$2 options=$3 crops=$4
    baked_count=$(instances "$scene")
    instanced_count=$(instances "${scene%.txt}-instanced.txt")
    if [ "$baked_count" = "0 instances" ] && [ "${instanced_count% instances}" -gt 0 ] 2>/dev/null; then
        pass "$name: baked ($baked_count), and instanced with the hidden copies ($instanced_count)"
    else
        fail "$name: baked and instanced" "got '$baked_count' and '$instanced_count'"
        return
    fi
    # shellcheck disable=SC2086
    if ! "$program" render "$scene" -o "$scratch/$name-baked.exr" --quiet $options ||
       ! "$program" render "${scene%.txt}-instanced.txt" -o "$scratch/$name-instanced.exr" --quiet $options; then
        fail "$name" "a render failed"
        return
    fi
    if "$program" diff "$scratch/$name-baked.exr" "$scratch/$name-instanced.exr" --fail 0.016 --failpercent 1 \
            >"$scratch/$name.diff" 2>&1; then
        pass "$name: baked and instanced agree ($(grep '^pixels over' "$scratch/$name.diff"); $(grep '^max error' "$scratch/$name.diff"))"
    else
        fail "$name: baked and instanced agree" "$(tr '\n' ' ' <"$scratch/$name.diff")"
    fi
    for crop in $crops; do
        for channel in R G B; do
            baked=$(channel_mean "$scratch/$name-baked.exr" $channel "$crop")
            instanced=$(channel_mean "$scratch/$name-instanced.exr" $channel "$crop")
            if ! within "$baked" "$instanced" 0.01; then
                fail "$name: mean of $crop" "channel $channel baked $baked, instanced $instanced (more than 1% apart)"
                return
            fi
        done
    done
    pass "$name: the means of the regions $crops agree within 1%"
}

# The Cornell box (scenes/cornell.txt): two boxes of six quads, turned and moved by groups.
# Copies 2,000 below the floor: rays leave the box only through its open front, towards
# -z, and never come back under it. Regions (x0,y0,x1,y1): the tall block, the short
# block, the back wall.
cp scenes/cornell.txt "$scratch/cornell.txt"
{
    sed 's/^group tall_block/group blocks {\ngroup tall_block/' scenes/cornell.txt
    echo "}"
    # 43,691 copies of six quads beyond the first: 262,146 primitives, over the budget.
    hidden_copies blocks 43691 0 -2000 0
} >"$scratch/cornell-instanced.txt"
compare cornell "$scratch/cornell.txt" "--size 64x64 --spp 64" "20,30,32,56 33,43,48,60 20,10,44,26"

# Shapes of every kind, turned and scaled uniformly by a group: spheres (one of metal), a
# moving sphere, a quad, a box, a triangle with vertex normals and uvs, and a mesh with
# vertex normals (scenes/assets/stand.obj), over a wide floor under a gradient sky.
# Copies 50 below the floor, inside its edges: rays from above meet the floor before them.
# Regions: the red sphere, the gold one, the quad and the triangle, the box and the
# stand, the floor in front.
cp scenes/assets/stand.obj "$scratch/stand.obj"
cat >"$scratch/shapes.txt" <<'SCENE'
render size 96 54 spp 32 depth 8 seed 5
camera from 0 1.6 5 at 0 0.7 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.5 0.7 1
material floor lambertian 0.5 0.5 0.5
material red lambertian 0.8 0.2 0.1
material gold metal 0.9 0.7 0.3 fuzz 0.1
material blue lambertian 0.2 0.3 0.8
quad -100 0 100  200 0 0  0 0 -200 floor
group shapes {
    rotate 1 3 0.5 25
    scale 1.3
    translate 0 0.9 0
    sphere -1.2 0 0 0.4 red
    sphere 1.2 0.1 0 0.4 gold
    moving_sphere 0 0.8 -0.5  0.2 0.8 -0.5  0.25 blue
    quad -0.5 -0.5 -1  1 0 0  0 1 0.2 blue
    box -0.3 -0.6 0.3  0.3 -0.2 0.7 red
    triangle -0.6 0.3 0.5  0 0.5 0.5  -0.3 0.8 0.3 normals 0 0 1  0.6 0 0.8  0 0.6 0.8 uvs 0 0  1 0  0 1 gold
    group {
        scale 0.6
        translate 0.6 -0.5 0.6
        mesh "stand.obj" gold
    }
}
SCENE
{
    cat "$scratch/shapes.txt"
    # 43,691 copies of 11 shapes and of a 40-triangle mesh beyond the first: over the budget.
    hidden_copies shapes 43691 0 -50 0
} >"$scratch/shapes-instanced.txt"
compare shapes "$scratch/shapes.txt" "" "16,20,32,34 60,12,74,26 34,12,50,30 46,28,74,42 0,44,96,54"

finish
