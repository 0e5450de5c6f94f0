#!/bin/sh
# test-analytic.sh: scenes whose correct image is known in closed form, so they check
# correctness itself (golden images only catch change).
#   usage: sh tests/render/test-analytic.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# White furnace: a convex diffuse sphere of albedo a in a uniform white sky. A camera ray
# that hits it scatters once and escapes, so its pixels are exactly a (0.5, and 0.8 with
# -D albedo=0.8). The crop is well inside the sphere's silhouette.
for albedo in 0.5 0.8; do
    out="$scratch/furnace-$albedo.exr"
    if "$program" render scenes/furnace.txt -o "$out" --size 64x64 --spp 16 -D albedo=$albedo --quiet; then
        for channel in R G B; do
            mean=$(channel_mean "$out" $channel 20,20,44,44)
            if within "$mean" "$albedo" 0.01; then pass "furnace albedo $albedo channel $channel (mean $mean)"
            else fail "furnace albedo $albedo channel $channel" "mean $mean, expected $albedo within 1%"; fi
        done
        range=$(channel_range "$out" G 20,20,44,44)
        if within "${range% *}" "$albedo" 0.001 && within "${range#* }" "$albedo" 0.001; then
            pass "furnace albedo $albedo: every pixel exactly the albedo (min/max $range)"
        else fail "furnace albedo $albedo pixel range" "min/max $range, expected $albedo"; fi
    else
        fail "furnace albedo $albedo" "render failed"
    fi
done

# Clear glass in a white sky: nothing absorbs, every path ends in the sky: 1 everywhere.
out="$scratch/glass-furnace.exr"
if "$program" render scenes/glass-furnace.txt -o "$out" --size 64x64 --spp 64 --quiet; then
    for channel in R G B; do
        mean=$(channel_mean "$out" $channel)
        if within "$mean" 1 0.01; then pass "glass furnace channel $channel (mean $mean)"
        else fail "glass furnace channel $channel" "mean $mean, expected 1 within 1%"; fi
    done
else
    fail "glass furnace" "render failed"
fi
# The whole image is mostly the sphere, but a missing or invisible sphere would give 1
# too: so also the pixels inside its silhouette (radius about 31 pixels), rendered as a
# crop with AOVs. There every pixel is 1 (each bounce has weight exactly 1, so every
# sample is 1), the depth shows every pixel hits the sphere's front (3 from the camera
# in the middle, 3.12 at the crop's corners; 0 would be the sky), and the paths pass
# through the glass: 3 segments (in, out, to the sky) or more for most samples, 2 for the
# few (about 4%) reflected at the front; measured 2.998 per sample. The sky alone would
# be 1, an opaque sphere 2: more than 2.5 is required.
out="$scratch/glass-furnace-sphere.exr"
if "$program" render scenes/glass-furnace.txt -o "$out" --size 64x64 --spp 64 --crop 20,20,44,44 --aovs --quiet; then
    "$program" stats "$out" >"$scratch/glass-stats"
    crop_range() { sed -n "s/^channel $1: mean [^ ]* min \([^ ]*\) max \([^ ]*\)/\1 \2/p" "$scratch/glass-stats"; }
    crop_mean() { sed -n "s/^channel $1: mean \([^ ]*\) .*/\1/p" "$scratch/glass-stats"; }
    for channel in R G B; do
        mean=$(crop_mean $channel)
        range=$(crop_range $channel)
        if within "$mean" 1 0.01 && within "${range% *}" 1 0.001 && within "${range#* }" 1 0.001; then
            pass "glass furnace on the sphere, channel $channel: every pixel 1 (mean $mean, min/max $range)"
        else fail "glass furnace on the sphere, channel $channel" "mean $mean, min/max $range, expected 1"; fi
    done
    depth=$(crop_range depth.Z)
    segments=$(sed -n 's/^metadata rtspheres:path_segments: //p' "$scratch/glass-stats")
    samples=$(sed -n 's/^metadata rtspheres:samples_finished: //p' "$scratch/glass-stats")
    per_sample=$(awk -v s="$segments" -v n="$samples" 'BEGIN { if (n > 0) printf "%.3f", s / n }')
    if ! awk -v r="$depth" 'BEGIN { split(r, v, " "); exit !(v[1] >= 2.999 && v[2] <= 3.2) }'; then
        fail "glass furnace: the crop sees the sphere" "depth.Z min/max '$depth', expected 3 to 3.2"
    elif ! awk -v p="$per_sample" 'BEGIN { exit !(p != "" && p > 2.5) }'; then
        fail "glass furnace: the crop sees the sphere" "$per_sample path segments per sample, expected more than 2.5"
    else
        pass "glass furnace: the crop sees the sphere (depth $depth, $per_sample path segments per sample)"
    fi
else
    fail "glass furnace on the sphere" "render failed"
fi

# A diffuse plane (radius-1000 sphere) under a uniform sky: exactly albedo * sky = 0.6
# in every pixel; anything darker is self-intersection on the big sphere.
out="$scratch/plane.exr"
if "$program" render tests/render/scenes/plane-under-sky.txt -o "$out" --quiet; then
    mean=$(channel_mean "$out" G)
    range=$(channel_range "$out" G)
    if within "$mean" 0.6 0.01; then pass "plane under uniform sky: mean $mean"
    else fail "plane under uniform sky" "mean $mean, expected 0.6 within 1%"; fi
    if within "${range% *}" 0.6 0.001; then pass "plane under uniform sky: no darker pixel (min $range)"
    else fail "plane under uniform sky: min/max" "$range, expected 0.6 everywhere"; fi
else
    fail "plane under uniform sky" "render failed"
fi

# Two estimators of one image: Russian roulette from the first bounce versus none before
# the depth limit. Both are unbiased, so the image means agree within noise.
a="$scratch/roulette-early.exr"
b="$scratch/roulette-late.exr"
if "$program" render scenes/materials/lambertian.txt -o "$a" --size 64x36 --spp 256 --roulette-depth 1 --quiet &&
   "$program" render scenes/materials/lambertian.txt -o "$b" --size 64x36 --spp 256 --roulette-depth 1000 --quiet; then
    for channel in R G B; do
        mean_a=$(channel_mean "$a" $channel)
        mean_b=$(channel_mean "$b" $channel)
        if within "$mean_a" "$mean_b" 0.01; then pass "Russian roulette unbiased, channel $channel ($mean_a vs $mean_b)"
        else fail "Russian roulette unbiased, channel $channel" "$mean_a vs $mean_b differ by more than 1%"; fi
    done
else
    fail "Russian roulette estimators" "render failed"
fi
# Light sampling (next-event estimation with MIS) against BSDF sampling alone: two
# estimators of the same image, so every quarter of it agrees within noise (measured
# differences at these settings: under 1%).
a="$scratch/light-sampling-on.exr"
b="$scratch/light-sampling-off.exr"
if "$program" render scenes/three-balls.txt -o "$a" --size 64x36 --spp 512 --light-sampling on --quiet &&
   "$program" render scenes/three-balls.txt -o "$b" --size 64x36 --spp 512 --light-sampling off --quiet; then
    for crop in 0,0,32,18 32,0,64,18 0,18,32,36 32,18,64,36; do
        for channel in R G B; do
            mean_a=$(channel_mean "$a" $channel $crop)
            mean_b=$(channel_mean "$b" $channel $crop)
            if within "$mean_a" "$mean_b" 0.02; then :
            else fail "light sampling unbiased, region $crop channel $channel" "$mean_a vs $mean_b (over 2%)"; fi
        done
    done
    pass "light sampling and BSDF sampling agree in every quarter of the image (within 2%)"
    # And light sampling must really reduce the noise: the ground's pixel spread shrinks.
    spread_a=$("$program" stats "$a" --crop 0,27,64,36 | sed -n 's/^channel G: mean [^ ]* min \([^ ]*\) max \([^ ]*\)/\2 \1/p' | awk '{print $1 - $2}')
    spread_b=$("$program" stats "$b" --crop 0,27,64,36 | sed -n 's/^channel G: mean [^ ]* min \([^ ]*\) max \([^ ]*\)/\2 \1/p' | awk '{print $1 - $2}')
    if awk -v a="$spread_a" -v b="$spread_b" 'BEGIN { exit !(a < b) }'; then
        pass "light sampling reduces noise on the ground (spread $spread_a vs $spread_b)"
    else fail "light sampling reduces noise" "spread $spread_a with, $spread_b without"; fi
else
    fail "light sampling estimators" "render failed"
fi

# Point, spot and sun lights on a diffuse plane (albedo 0.5, black sky: no other light):
# radiance = albedo / pi * E with E = I cos(theta) / r^2 for a point light (inverse
# square), I cos / (c + l r + q r^2) for the polynomial falloff, the sun's irradiance times
# cos for the sun. A camera with a tiny field of view looks at one point of the plane.
# Both integrators must agree (Whitted with no ambient and no specular highlight).
# plane_light NAME TARGET LIGHTS EXPECTED INTEGRATOR [OPTIONS...]: one such check; LIGHTS
# are scene lines, OPTIONS go to the render.
plane_light() {
    name=$1 target=$2 light=$3 expected=$4 integrator=$5
    shift 5
    extra=""
    [ $# = 0 ] || extra=", $*"
    cat >"$scratch/$name.txt" <<SCENE
render size 8 8 spp 4 depth 4 seed 1
camera from 1 3 2 at $target up 0 1 0 fov 0.2
sky constant 0 0 0
ambient 0 0 0
material floor lambertian 0.5 0.5 0.5 specular 0 0 0
quad -50 0 -50  100 0 0  0 0 100 floor
$light
SCENE
    if "$program" render "$scratch/$name.txt" -o "$scratch/$name.exr" --integrator "$integrator" --quiet "$@"; then
        mean=$(channel_mean "$scratch/$name.exr" G)
        if within "$mean" "$expected" 0.01; then pass "$name ($integrator$extra): $mean, analytic $expected"
        else fail "$name ($integrator$extra)" "$mean, analytic $expected"; fi
    else
        fail "$name ($integrator$extra)" "render failed"
    fi
}
for integrator in path whitted; do
    # 0.5 * 10 / (pi * 2^2)
    plane_light point-below "0 0 0" "light point 0 2 0 intensity 10" 0.397887 $integrator
    # r^2 = 8, cos = 2 / sqrt(8): 0.5 * 10 * 0.707107 / (pi * 8)
    plane_light point-aside "2 0 0" "light point 0 2 0 intensity 10" 0.140683 $integrator
    # 0.5 * 10 / (pi * (1 + 0 * 2 + 1 * 4))
    plane_light point-polynomial "0 0 0" "light point 0 2 0 intensity 10 falloff polynomial 1 0 1" 0.318310 $integrator
    # Inside the spot's inner cone it is the point light; outside its outer cone, dark.
    plane_light spot-inside "0 0 0" "light spot 0 2 0 at 0 0 0 intensity 10 cone 20 30" 0.397887 $integrator
    plane_light spot-outside "3 0 0" "light spot 0 2 0 at 0 0 0 intensity 10 cone 20 30" 0 $integrator
    # Sun straight down, irradiance 3: 0.5 * 3 / pi; tilted 60 degrees: times cos 60.
    plane_light sun-down "0 0 0" "light sun 0 -1 0 intensity 3 angle 0" 0.477465 $integrator
    plane_light sun-tilted "0 0 0" "light sun 0.866025 -0.5 0 intensity 3 angle 0" 0.238732 $integrator
done

# Rectangle lights on a diffuse plane (albedo 0.5, black sky): the point below a
# rectangle's centre, parallel to it at height h, receives E = pi L F with F the form
# factor of the four quarter rectangles (one corner each above the point): F = 4 / (2 pi)
# (X / sqrt(1 + X^2) atan(Y / sqrt(1 + X^2)) + Y / sqrt(1 + Y^2) atan(X / sqrt(1 + Y^2))),
# X, Y the quarter's sides over h; radiance albedo L F. Near (2 x 1 at h = 0.3: it covers
# most of the sky above the point) light sampling draws points by solid angle (the
# spherical rectangle of glsl/lights.glsl); far (0.5 x 0.5 at h = 50: 1e-4 sr, under the
# threshold where float32 angles are precise enough) by area. The camera looks from the
# side, under the light.
rectangle_light() {
    name=$1 h=$2 a=$3 b=$4 strength=$5 expected=$6 integrator=$7
    cat >"$scratch/$name.txt" <<SCENE
render size 8 8 spp 64 depth 2 seed 1
camera from 3 0.5 0 at 0 0 0 up 0 1 0 fov 0.2
sky constant 0 0 0
ambient 0 0 0
material floor lambertian 0.5 0.5 0.5 specular 0 0 0
material panel emissive 1 1 1 strength $strength
quad -50 0 -50  100 0 0  0 0 100 floor
quad (-$a / 2) $h (-$b / 2)  $a 0 0  0 0 $b panel
SCENE
    if "$program" render "$scratch/$name.txt" -o "$scratch/$name.exr" --integrator "$integrator" --quiet; then
        mean=$(channel_mean "$scratch/$name.exr" G)
        if within "$mean" "$expected" 0.01; then pass "$name ($integrator): $mean, analytic $expected"
        else fail "$name ($integrator)" "$mean, analytic $expected"; fi
    else
        fail "$name ($integrator)" "render failed"
    fi
}
for integrator in path whitted; do
    # F = 0.841662: 0.5 * 0.841662
    rectangle_light rectangle-near 0.3 2 1 1 0.420831 $integrator
    # F = 3.18299e-5: 0.5 * 1e4 * 3.18299e-5
    rectangle_light rectangle-far 50 0.5 0.5 10000 0.159150 $integrator
done

# Several area lights: light sampling then chooses a light by its estimated irradiance at
# the point (glsl/lights.glsl, choose_light_at) and samples rectangles by solid angle, a
# sheared parallelogram and a triangle by area, a sphere by its cone; BSDF sampling alone
# must converge to the same image, in every quarter.
# The room both area-light scenes below share: a floor, a box, two emissive materials.
area_room="render size 48 27 spp 256 depth 3 seed 1
camera from 0 2.5 6 at 0 0.5 0 up 0 1 0 fov 45
sky constant 0 0 0
material floor lambertian 0.6 0.6 0.6
material wall lambertian 0.3 0.5 0.7
material warm emissive 1 0.8 0.6 strength 3
material cool emissive 0.6 0.8 1 strength 6
quad -6 0 -6  12 0 0  0 0 12 floor
box -0.6 0 -0.6  0.6 1.2 0.6 wall"
cat >"$scratch/area-lights.txt" <<SCENE
$area_room
quad -3 2 -1  1.5 0 0  0 0 1 warm
quad 1.5 1.5 0  0.8 0 0  0.3 0.2 0.9 cool
triangle 0 3 -2  1 3 -2  0 3 -1 warm
sphere -2 0.5 1.5 0.25 cool
SCENE
# samplings_agree NAME SCENE [OPTIONS...]: renders SCENE (48x27) with light sampling on,
# and off with OPTIONS; one check: every quarter's R, G and B means agree within 3%.
samplings_agree() {
    name=$1 scene=$2
    shift 2
    stem=$(printf '%s' "$name" | tr -c 'a-z0-9' '-')
    on="$scratch/$stem-on.exr" off="$scratch/$stem-off.exr"
    if "$program" render "$scene" -o "$on" --light-sampling on --quiet &&
       "$program" render "$scene" -o "$off" --light-sampling off --quiet "$@"; then
        problems=""
        for crop in 0,0,24,14 24,0,48,14 0,14,24,27 24,14,48,27; do
            for channel in R G B; do
                mean_on=$(channel_mean "$on" $channel $crop)
                mean_off=$(channel_mean "$off" $channel $crop)
                within "$mean_on" "$mean_off" 0.03 || problems="$problems $crop/$channel: $mean_on vs $mean_off;"
            done
        done
        if [ -z "$problems" ]; then pass "$name: light sampling and BSDF sampling agree in every quarter (within 3%)"
        else fail "$name: light sampling and BSDF sampling agree" "$problems"; fi
    else
        fail "$name" "render failed"
    fi
}
samplings_agree "four area lights" "$scratch/area-lights.txt"

# Many lights (more than LIGHT_LOCAL_CHOICE_MAX of core/tracer_interface.h): light sampling
# walks the light tree (glsl/lights.glsl, walk_light_tree) to choose one, and so does
# Whitted beyond 16 (WHITTED_ALL_LIGHTS of glsl/direct_light.glsl). Eighteen point lights
# and a sun over a diffuse plane (albedo 0.5, black sky), the camera on one point:
# radiance = albedo / pi x (sum of I cos / r^2 over the points + E cos of the sun), so a
# choice whose probability were not the walk's would be off. Computed here from the list.
many_lights=""
for k in 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17; do
    x=$(awk -v k=$k 'BEGIN { printf "%.3f", 3 * cos(k * 2.4) * (1 + k % 3) }')
    y=$(awk -v k=$k 'BEGIN { printf "%.3f", 0.5 + 0.4 * k }')
    z=$(awk -v k=$k 'BEGIN { printf "%.3f", 3 * sin(k * 2.4) * (1 + k % 3) }')
    intensity=$(awk -v k=$k 'BEGIN { printf "%.3f", 1 + 2 * (k % 4) }')
    many_lights="$many_lights
light point $x $y $z intensity $intensity"
done
many_lights="$many_lights
light sun 0.6 -0.8 0 intensity 0.5 angle 0"
expected=$(printf '%s\n' "$many_lights" | awk '
    $1 == "light" && $2 == "point" { r2 = $3 * $3 + $4 * $4 + $5 * $5; e += $7 * $4 / sqrt(r2) / r2 }
    $1 == "light" && $2 == "sun" { e += $7 * 0.8 }
    END { printf "%.6f", 0.5 / 3.14159265358979 * e }')
# 1024 spp: choosing by power, the mean of 64 pixels at 256 spp varied by 0.7% between
# seeds (1.2% once), too near the 1% checked; the tree's by 0.2%. With --light-tree off
# they are chosen by power, the same image.
for integrator in path whitted; do
    for tree in on off; do
        plane_light "many-points-$tree" "0 0 0" "$many_lights" "$expected" $integrator --spp 1024 --light-tree $tree
    done
done

# Many spots (the tree bounds a node of spots alone by their cones, one-sided, and gives it
# nothing outside them: glsl/lights.glsl, tree_node_importance): twelve aimed at the point
# (cone 20 30, the point well inside 20 degrees), twelve aimed away from it (at least 45
# degrees off, outside their 30), and two point lights among them. Radiance = albedo / pi x
# the aimed spots' and the points' I cos / r^2.
many_spots=""
for k in 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25; do
    many_spots="$many_spots
$(awk -v k=$k 'BEGIN { x = 2.5 * cos(k * 2.4) * (1 + k % 2); z = 2.5 * sin(k * 2.4) * (1 + k % 2); y = 1.5 + 0.3 * (k % 5)
        if (k >= 24) printf "light point %.3f %.3f %.3f intensity 2", x, y, z
        else if (k % 2 == 0) printf "light spot %.3f %.3f %.3f at 0 0 0 intensity %d cone 20 30", x, y, z, 2 + k % 3
        else printf "light spot %.3f %.3f %.3f at %.3f 0 %.3f intensity 5 cone 20 30", x, y, z, 2 * x, 2 * z }')"
done
expected=$(printf '%s\n' "$many_spots" | awk '
    $1 == "light" && ($2 == "point" || ($7 == "0" && $9 == "0")) {
        r2 = $3 * $3 + $4 * $4 + $5 * $5; i = $2 == "point" ? $7 : $11; e += i * $4 / sqrt(r2) / r2 }
    $1 == "light" && $2 == "spot" && !($7 == "0" && $9 == "0") {
        # the angle between the spot and the way to the point must be over 30 degrees
        ax = $7 - $3; ay = -$4; az = $9 - $5; dot = -(ax * $3 + ay * $4 + az * $5)
        cosine = dot / sqrt((ax * ax + ay * ay + az * az) * ($3 * $3 + $4 * $4 + $5 * $5))
        if (cosine > 0.7) bad = 1 }
    END { if (bad) print "bad"; else printf "%.6f", 0.5 / 3.14159265358979 * e }')
for integrator in path whitted; do
    for tree in on off; do
        plane_light "many-spots-$tree" "0 0 0" "$many_spots" "$expected" $integrator --spp 1024 --light-tree $tree
    done
done

# Many area lights (12 quads, 2 triangles, 2 spheres, facing every way): the light tree's
# choice and, at an emitter a path hits, the probability MIS recomputes from the light's
# trail must agree, or light sampling and BSDF sampling alone converge to different images.
{
    cat <<SCENE
$area_room
triangle 0 3 -2  1 3 -2  0 3 -1 warm
triangle -1 2 -3  -1 3 -3  -2 2 -3 cool
sphere -2 0.5 1.5 0.25 cool
sphere 2 0.3 1 0.2 warm
SCENE
    for k in 0 1 2 3 4 5 6 7 8 9 10 11; do
        awk -v k=$k 'BEGIN { a = k * 0.52; printf "quad %.3f %.3f %.3f  0.5 0 0  0 %.3f %.3f  %s\n",
            3 * cos(a) - 0.25, 1 + 0.15 * k, 3 * sin(a) - 2, 0.4 * sin(a), 0.4 * cos(a), k % 2 ? "warm" : "cool" }'
    done
} >"$scratch/many-areas.txt"
samplings_agree "16 area lights (light tree)" "$scratch/many-areas.txt" --spp 1024

# The choice of a light weighs a surface point's lights by its normal too: a light wholly
# below the surface gets no chance by its estimate (glsl/lights.glsl, light_importance and
# tree_node_importance). The path carries the normal to its next hit (the choice memo),
# where MIS must find the same probability. Area lights around a floor seen from above and
# as many under it, out of its reach: six (chosen by the point) and twelve (by the tree).
# Had MIS left the normal out, light sampling would give these quarters 2 to 20% more
# light than BSDF sampling alone (seen 2026-12-03).
for pairs in 3 6; do
    {
        cat <<SCENE
render size 48 27 spp 1024 depth 2 seed 1
camera from 0 3 0.01 at 0 0 0 up 0 1 0 fov 40
sky constant 0 0 0
material floor lambertian 0.7 0.7 0.7
material warm emissive 1 0.8 0.6 strength 3
material cool emissive 0.6 0.8 1 strength 6
quad -10 0 -10  0 0 20  20 0 0 floor
SCENE
        k=0
        while [ $k -lt $pairs ]; do
            awk -v k=$k -v step=$((6 / pairs)) 'BEGIN { a = k * step * 1.0472 + 0.3; dx = cos(a); dz = sin(a)
                printf "quad %.3f 0.1 %.3f  0 0.8 0  %.3f 0 %.3f  %s\n", 2.5 * dx + 0.4 * dz, 2.5 * dz - 0.4 * dx,
                    -0.8 * dz, 0.8 * dx, k % 2 ? "warm" : "cool"
                printf "quad %.3f -0.5 %.3f  0.8 0 0  0 0 0.8  %s\n", 1.5 * dx - 0.4, 1.5 * dz - 0.4, k % 2 ? "cool" : "warm" }'
            k=$((k + 1))
        done
    } >"$scratch/lights-under-$pairs.txt"
    if [ $pairs = 3 ]; then how="chosen by the point"; else how="light tree"; fi
    samplings_agree "$((2 * pairs)) area lights, $pairs below the surface ($how, receiver normal)" \
        "$scratch/lights-under-$pairs.txt"
done

# An environment map as a light: a dim sky with one small, very bright patch (a "sun" of
# four pixels). Importance sampling it must give the image that BSDF sampling alone
# converges to (the mean of the floor agrees within 3%), with much less noise.
envdir="$scratch/environment"
mkdir -p "$envdir"
{
    printf 'PF\n64 32\n-1.0\n'
    # PFM rows run bottom to top; little-endian floats: 0.05 = cd cc 4c 3d, 2000 = 00 00 fa 44.
    y=31
    while [ "$y" -ge 0 ]; do
        x=0
        while [ "$x" -lt 64 ]; do
            if [ "$x" -ge 10 ] && [ "$x" -lt 12 ] && { [ "$y" = 8 ] || [ "$y" = 9 ]; }; then
                printf '\000\000\372\104\000\000\372\104\000\000\372\104'
            else
                printf '\315\314\114\075\315\314\114\075\315\314\114\075'
            fi
            x=$((x + 1))
        done
        y=$((y - 1))
    done
} >"$envdir/env.pfm"
cat >"$envdir/scene.txt" <<'SCENE'
render size 64 36 spp 16 depth 4 seed 1
camera from 0 1 4 at 0 0 0 fov 40
sky environment "env.pfm"
material floor lambertian 0.6 0.6 0.6
quad -5 0 -5  0 0 10  10 0 0 floor
sphere 0 0.5 0 0.5 floor
SCENE
if "$program" render "$envdir/scene.txt" -o "$envdir/on.exr" --quiet &&
   "$program" render "$envdir/scene.txt" -o "$envdir/off.exr" --light-sampling off --quiet &&
   "$program" render "$envdir/scene.txt" -o "$envdir/reference.exr" --light-sampling off --spp 1024 --quiet; then
    mean_on=$(channel_mean "$envdir/on.exr" G 0,20,64,36)
    mean_reference=$(channel_mean "$envdir/reference.exr" G 0,20,64,36)
    if within "$mean_on" "$mean_reference" 0.03; then pass "environment light sampling converges to the same floor ($mean_on vs $mean_reference)"
    else fail "environment light sampling" "floor mean $mean_on, reference $mean_reference"; fi
    rms_on=$("$program" diff "$envdir/on.exr" "$envdir/reference.exr" --fail 1000 --failpercent 100 | sed -n 's/^rms error: //p')
    rms_off=$("$program" diff "$envdir/off.exr" "$envdir/reference.exr" --fail 1000 --failpercent 100 | sed -n 's/^rms error: //p')
    if awk -v a="$rms_on" -v b="$rms_off" 'BEGIN { exit !(a < 0.5 * b) }'; then
        pass "environment importance sampling cuts the error (RMS $rms_on vs $rms_off)"
    else fail "environment importance sampling" "RMS $rms_on with, $rms_off without"; fi
else
    fail "environment light sampling" "render failed"
fi
# Volumes sample lights too: the Cornell box with two smoke boxes (scattering in the
# media, where next-event estimation uses the phase function) is the same image, within
# noise, with light sampling on and off (seen: 0.526 and 0.523 at 192 spp).
on="$scratch/smoke-on.exr" off="$scratch/smoke-off.exr"
if "$program" render scenes/cornell-smoke.txt -o "$on" --size 32x32 --spp 192 --quiet &&
   "$program" render scenes/cornell-smoke.txt -o "$off" --size 32x32 --spp 192 --light-sampling off --quiet; then
    for channel in R G B; do
        mean_on=$(channel_mean "$on" $channel)
        mean_off=$(channel_mean "$off" $channel)
        if within "$mean_on" "$mean_off" 0.03; then
            pass "smoke: light sampling in volumes agrees, channel $channel ($mean_on vs $mean_off)"
        else
            fail "smoke: light sampling in volumes agrees, channel $channel" "$mean_on vs $mean_off, over 3% apart"
        fi
    done
else
    fail "smoke: light sampling in volumes" "render failed"
fi

finish
