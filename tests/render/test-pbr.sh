#!/bin/sh
# test-pbr.sh: the pbr material (glsl/material_pbr.glsl) in renders, checked by what must
# hold exactly or statistically (tests/unit/test_material_pbr.c checks its sampling,
# density, furnaces and reciprocity on the device): white furnaces, roughness 0 against
# the metal and the dielectric, light sampling on and off, one-sided emitters, alpha masks
# (also through an instance), Whitted's Phong stand-in, bad input.
#   usage: sh tests/render/test-pbr.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# scene NAME TEXT: writes TEXT to $scratch/NAME.txt.
scene() { printf '%s\n' "$2" >"$scratch/$1.txt"; }

# draw NAME OUTPUT [OPTIONS...]: renders $scratch/NAME.txt quietly to $scratch/OUTPUT.exr.
draw() {
    lib_name=$1 lib_out=$2
    shift 2
    "$program" render "$scratch/$lib_name.txt" -o "$scratch/$lib_out.exr" --quiet "$@" 2>"$scratch/$lib_out.log"
}

# range_within NAME FILE LOW HIGH [CROP]: one check: every R, G and B value of FILE (in
# CROP) lies in [LOW, HIGH].
range_within() {
    stats_of "$2" ${5:+--crop "$5"}
    for lib_channel in R G B; do
        set -- "$1" "$2" "$3" "$4" $(stat_range $lib_channel)
        if ! awk -v lo="$5" -v hi="$6" -v a="$3" -v b="$4" 'BEGIN { exit !(lo >= a && hi <= b) }'; then
            fail "$1" "channel $lib_channel spans $5 .. $6, expected within $3 .. $4"
            return
        fi
    done
    pass "$1"
}

furnace='render size 24 24 spp 16 depth 64 seed 1
camera from 0 0 4 at 0 0 0 up 0 1 0 fov 30
sky constant 1 1 1'

# A white smooth pbr metal reflects all (its Fresnel term is 1 at base colour 1), and
# smooth pbr glass of base colour 1 reflects or refracts all: both render exactly 1.
scene mirror-furnace "$furnace
material m pbr 1 1 1 metallic 1 roughness 0
sphere 0 0 0 1 m"
scene glass-furnace "$furnace
material g pbr 1 1 1 metallic 0 roughness 0 transmission 1
sphere 0 0 0 1 g"
for integrator in path whitted; do
    if draw mirror-furnace mirror-$integrator --integrator $integrator &&
       draw glass-furnace glass-$integrator --integrator $integrator; then
        # Whitted's ambient term lights the mirror's own colour a little (0.03 x 1).
        high=1.00001
        [ $integrator = whitted ] && high=1.03001
        range_within "$integrator: a white smooth pbr metal in a white furnace renders 1" \
            "$scratch/mirror-$integrator.exr" 0.99999 $high
        range_within "$integrator: smooth pbr glass in a white furnace renders 1" "$scratch/glass-$integrator.exr" \
            0.99999 1.00001
    else
        fail "$integrator: pbr furnaces" "a render failed: $(cat "$scratch"/*-$integrator.log | head -c 300)"
    fi
done

# A rough white metal loses what single-scattering GGX loses and gains nothing: its
# sphere is darker than the sky but never brighter (the loss itself is checked against
# an integral in tests/unit/test_material_pbr.c).
scene rough-furnace "$furnace
material m pbr 1 1 1 metallic 1 roughness 0.8
sphere 0 0 0 1 m"
if draw rough-furnace rough --spp 64; then
    mean=$(channel_mean "$scratch/rough.exr" G 8,8,16,16)
    if awk -v m="$mean" 'BEGIN { exit !(m > 0.5 && m < 0.9) }'; then
        pass "a rough white metal in a white furnace loses energy, gains none (centre $mean)"
    else fail "a rough white metal in a white furnace" "centre mean $mean, expected 0.5 .. 0.9"; fi
else
    fail "a rough white metal in a white furnace" "render failed: $(head -c 300 "$scratch/rough.log")"
fi

# Roughness 0 is the fuzz-0 metal and the dielectric (white, where the metal's Fresnel
# term is 1), in both integrators, ground and sky around them: the same image but for
# float rounding. The scene has no lights, so Whitted's highlights (which differ) are not
# in it.
limit='render size 48 27 spp 8 depth 12 seed 3
camera from 0 1 4 at 0 0.4 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.5 0.7 1
material ground lambertian 0.5 0.5 0.5
sphere 0 -1000 0 1000 ground'
scene limit-old "$limit
material mirror metal 1 1 1
material glass dielectric 1.5
sphere -0.6 0.5 0 0.5 mirror
sphere 0.6 0.5 0 0.5 glass"
scene limit-pbr "$limit
material mirror pbr 1 1 1 metallic 1 roughness 0
material glass pbr 1 1 1 metallic 0 roughness 0 transmission 1 ior 1.5
sphere -0.6 0.5 0 0.5 mirror
sphere 0.6 0.5 0 0.5 glass"
for integrator in path whitted; do
    if draw limit-old old-$integrator --integrator $integrator && draw limit-pbr pbr-$integrator --integrator $integrator
    then
        if "$program" diff "$scratch/old-$integrator.exr" "$scratch/pbr-$integrator.exr" --fail 1e-4 --failpercent 0 \
                >"$scratch/limit.diff" 2>&1; then
            pass "$integrator: roughness 0 renders as the metal and the dielectric ($(grep '^max error' "$scratch/limit.diff"))"
        else
            fail "$integrator: roughness 0 renders as the metal and the dielectric" "$(tr '\n' ' ' <"$scratch/limit.diff")"
        fi
    else
        fail "$integrator: roughness 0" "a render failed"
    fi
done

# Light sampling on and off: two estimators of the same image, so every quarter agrees
# within noise (measured at these settings: within 1.5%); the materials' MIS densities
# must be the densities they sample, and transmitted directions must not be weighted
# against light sampling, which does not gather through surfaces.
lights=tests/render/scenes/pbr-lights.txt
on="$scratch/lights-on.exr" off="$scratch/lights-off.exr"
if "$program" render $lights -o "$on" --spp 512 --quiet && "$program" render $lights -o "$off" --spp 512 \
        --light-sampling off --quiet; then
    agree=true
    for crop in 0,0,32,18 32,0,64,18 0,18,32,36 32,18,64,36; do
        for channel in R G B; do
            a=$(channel_mean "$on" $channel $crop) b=$(channel_mean "$off" $channel $crop)
            if ! within "$a" "$b" 0.03; then
                fail "pbr: light sampling unbiased, region $crop channel $channel" "$a vs $b (over 3%)"
                agree=false
            fi
        done
    done
    $agree && pass "pbr: light sampling on and off agree in every quarter (within 3%)"
else
    fail "pbr: light sampling on and off" "a render failed"
fi

# One-sided emitters emit along their normal only; by default both sides emit. A lamp
# facing up (+Y) over a floor lights it only when it is two-sided; a camera below sees
# its back: black when one-sided (but for light a surface sends itself at grazing
# angles, below 1e-6), radiance 4 when not (the pbr lamp also reflects a little of the
# lit floor). Emissive and pbr emission alike, with light sampling on and off.
for kind in emissive pbr; do
    for sides in one two; do
        clause=
        [ $sides = one ] && clause=one_sided
        lamp="material lamp emissive 1 1 1 strength 4 $clause"
        [ $kind = pbr ] && lamp="material lamp pbr 0 0 0 metallic 0 roughness 1 emission 1 1 1 strength 4 $clause"
        scene sided-$kind-$sides "render size 16 16 spp 64 depth 4 seed 1
camera from 0 0.3 2.5 at 0 0.6 0 up 0 1 0 fov 70
sky constant 0 0 0
$lamp
material floor lambertian 0.8 0.8 0.8
quad -1 1 1  2 0 0  0 0 -2 lamp
quad -3 0 -3  0 0 6  6 0 0 floor"
    done
    for sampling in on off; do
        if draw sided-$kind-one one-$kind-$sampling --light-sampling $sampling &&
           draw sided-$kind-two two-$kind-$sampling --light-sampling $sampling; then
            lit_one=$(channel_mean "$scratch/one-$kind-$sampling.exr" G 0,10,16,16)
            lit_two=$(channel_mean "$scratch/two-$kind-$sampling.exr" G 0,10,16,16)
            back_one=$(channel_mean "$scratch/one-$kind-$sampling.exr" G 4,5,12,6)
            back_two=$(channel_mean "$scratch/two-$kind-$sampling.exr" G 4,5,12,6)
            if awk -v a="$lit_one" -v b="$lit_two" -v c="$back_one" -v d="$back_two" \
                    'BEGIN { exit !(a < 1e-6 && b > 0.1 && c < 1e-6 && d > 3.99 && d < 4.05) }'; then
                pass "$kind, light sampling $sampling: a one-sided lamp facing up neither lights the floor nor shows its back; a two-sided one does both"
            else
                fail "$kind, light sampling $sampling: one-sided lamps" \
                    "floor $lit_one (one-sided) $lit_two (two-sided), back $back_one / $back_two"
            fi
        else
            fail "$kind: one-sided lamps" "a render failed: $(head -c 300 "$scratch/one-$kind-$sampling.log")"
        fi
    done
done

# Alpha masks: a quad whose base colour image is opaque on the left half and clear on the
# right (a 2x1 TGA: bilinear alpha crosses the cutoff 0.5 at u = 0 and 0.5) shows the sky
# through its right half; with alpha 0.2 (below the cutoff everywhere) it is not there at
# all: not seen, casting no shadow. The same quad placed by a mirroring group (which stays
# an instance: core/pack_collect.c) is masked alike.
printf '\0\0\2\0\0\0\0\0\0\0\0\0\2\0\1\0\40\50\0\0\377\377\0\0\377\0' >"$scratch/half.tga"
mask='render size 32 32 spp 16 depth 4 seed 1
camera from 0 0 3 at 0 0 0 up 0 1 0 fov 40
sky constant 1 1 1
texture half image "half.tga"
material floor lambertian 0.5 0.5 0.5
quad -3 -1 -3  0 0 6  6 0 0 floor'
scene masked "$mask
material cut pbr @half metallic 0 roughness 1 alpha_cutoff 0.5
quad -1 -0.8 0  2 0 0  0 1.6 0 cut"
scene masked-instance "$mask
material cut pbr @half metallic 0 roughness 1 alpha_cutoff 0.5
group {
    scale -1 1 1
    quad 1 -0.8 0  -2 0 0  0 1.6 0 cut
}"
scene gone "$mask
material cut pbr 1 0 0 metallic 0 roughness 1 alpha 0.2 alpha_cutoff 0.5
quad -1 -0.8 0  2 0 0  0 1.6 0 cut
quad -1 -0.99 -1  2 0 0  0 0 2 cut"
scene bare "$mask"
if draw masked masked && draw masked-instance masked-instance && draw gone gone && draw bare bare; then
    left=$(channel_mean "$scratch/masked.exr" B 9,10,14,18) right=$(channel_mean "$scratch/masked.exr" B 18,10,23,18)
    if awk -v l="$left" -v r="$right" 'BEGIN { exit !(l < 0.2 && r > 0.999) }'; then
        pass "an alpha mask shows the sky where alpha is below the cutoff (left B $left, right B $right)"
    else fail "an alpha mask" "left B $left (expected red: under 0.2), right B $right (expected the sky: 1)"; fi
    if "$program" diff "$scratch/masked.exr" "$scratch/masked-instance.exr" --fail 1e-4 --failpercent 0 \
            >"$scratch/mask.diff" 2>&1; then
        pass "an alpha mask through an instance equals the mask in the world"
    else fail "an alpha mask through an instance" "$(tr '\n' ' ' <"$scratch/mask.diff")"; fi
    if "$program" diff "$scratch/gone.exr" "$scratch/bare.exr" --fail 1e-4 --failpercent 0 >"$scratch/gone.diff" 2>&1
    then pass "quads masked everywhere are neither seen nor cast shadows"
    else fail "quads masked everywhere" "$(tr '\n' ' ' <"$scratch/gone.diff")"; fi
else
    fail "alpha masks" "a render failed: $(cat "$scratch"/masked*.log "$scratch/gone.log" | head -c 300)"
fi

# Whitted's stand-in: a pbr plane (base 0.5, metallic 0, roughness 1) seen from straight
# above a point light of intensity 10 at height 2 reflects ambient x base + E (base / pi
# + F0 (n + 2) / (2 pi)) with E = 10 / 2^2, F0 = 0.04 and the Phong exponent n = 1 of
# roughness 1: 0.015 + 2.5 (0.159155 + 0.019099) = 0.460634 at the centre.
scene whitted "render size 9 9 spp 1 depth 2 seed 1
camera from 0 3 0 at 0 0 0 up 0 0 -1 fov 2
sky constant 0 0 0
ambient 0.03 0.03 0.03
light point 0 2 0 intensity 10
material plane pbr 0.5 0.5 0.5 metallic 0 roughness 1
quad -5 0 5  10 0 0  0 0 -10 plane"
if draw whitted whitted --integrator whitted; then
    centre=$(channel_mean "$scratch/whitted.exr" G 4,4,5,5)
    if within "$centre" 0.460634 0.002; then pass "Whitted shades pbr with its Phong stand-in ($centre)"
    else fail "Whitted shades pbr with its Phong stand-in" "centre $centre, expected 0.460634"; fi
else
    fail "Whitted shades pbr" "render failed: $(head -c 300 "$scratch/whitted.log")"
fi

# Bad input: a clear message with the position, exit 2.
scene bad "material m pbr 1 1 1 metallic 0"
expect_exit "a pbr material without roughness is refused (exit 2)" 2 \
    "bad.txt:1:12: the pbr material 'm' needs metallic M and roughness R" \
    "$program" render "$scratch/bad.txt" -o "$scratch/bad.exr" --quiet

finish
