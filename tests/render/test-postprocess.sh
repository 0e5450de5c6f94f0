#!/bin/sh
# test-postprocess.sh: AOVs (their layers and their values on scenes where they are known),
# the denoiser, blur, exposure and tone mapping from the command line.
#   usage: sh tests/render/test-postprocess.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
scene=scenes/three-balls.txt
small="--size 96x54 --seed 3 --quiet"

# rms A B: the RMS error that `diff` prints.
rms() { "$program" diff "$1" "$2" --fail 1 --failpercent 100 | sed -n 's/^rms error: //p'; }

# stats_lines FILE [CROP]: the "channel NAME: mean M min A max B" lines of `stats`.
stats_lines() {
    "$program" stats "$1" ${2:+--crop "$2"} | grep '^channel '
}

# pixel FILE X Y: `stats` of the one pixel (X, Y) (row 0 at the top) into $scratch/pixel;
# value CHANNEL then reads that pixel's value of a channel.
pixel() { "$program" stats "$1" --crop "$2,$3,$(($2 + 1)),$(($3 + 1))" >"$scratch/pixel"; }
value() { stat_mean "$1" "$scratch/pixel"; }

# range_of CHANNEL: "min max" of a channel in the stats lines kept in $scratch/inside.
range_of() { stat_range "$1" "$scratch/inside"; }

# near A B TOLERANCE: true when |A - B| <= TOLERANCE (absolute) and A is a number.
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a != "" && d <= t) }'; }

# A reference, a noisy render and the same render denoised. The diffuse scene: first-hit
# guides cannot tell the denoiser where reflections and refractions of bright things are
# (only the render's per-pixel variance keeps such highlights, tested below), so the RMS
# check is on diffuse surfaces.
diffuse=scenes/materials/lambertian.txt
"$program" render $diffuse -o "$scratch/reference.exr" $small --spp 512
"$program" render $diffuse -o "$scratch/noisy.exr" $small --spp 8
"$program" render $diffuse -o "$scratch/denoised.exr" $small --spp 8 --denoise
# Exactly these channels, each once (in any order): colour, samples, the four AOV layers,
# the direct emission and the noisy colour.
channels=$(channels_of "$scratch/denoised.exr")
expected="B G R albedo.B albedo.G albedo.R depth.Z emission.B emission.G emission.R noisy.B noisy.G noisy.R normal.X normal.Y normal.Z samples variance.Y"
if [ "$channels" = "$expected" ]; then pass "--denoise keeps the noisy image and the AOVs as layers ($channels)"
else fail "--denoise layers" "channels '$channels', expected '$expected'"; fi
noisy_error=$(rms "$scratch/noisy.exr" "$scratch/reference.exr")
denoised_error=$(rms "$scratch/denoised.exr" "$scratch/reference.exr")
if awk -v n="$noisy_error" -v d="$denoised_error" 'BEGIN { exit !(d < 0.8 * n) }'; then
    pass "the denoiser brings 8 spp closer to 512 spp (RMS $noisy_error -> $denoised_error)"
else fail "the denoiser" "RMS $noisy_error -> $denoised_error"; fi
# The denoised colour is not the noisy one...
if "$program" diff "$scratch/denoised.exr" "$scratch/noisy.exr" --fail 0 --failpercent 0 >/dev/null 2>&1; then
    fail "--denoise changes the colour" "the denoised R, G, B equal the plain 8 spp render"
else pass "--denoise changes the colour"; fi
# ... and the noisy layer is the plain render of the same samples: noisy.R/G/B have the
# plain render's R/G/B mean, min and max (printed to 9 digits) over the whole image, each
# quarter (a flipped or shifted layer differs there) and three single pixels (a ball, the
# ground, the sky).
name="the noisy layer is the undenoised render"
mismatch=""
for region in "" 0,0,48,27 48,0,96,27 0,27,48,54 48,27,96,54 48,28,49,29 10,50,11,51 5,2,6,3; do
    layer=$(stats_lines "$scratch/denoised.exr" $region | sed -n 's/^channel noisy\.\([RGB]\):/channel \1:/p')
    plain=$(stats_lines "$scratch/noisy.exr" $region | grep -E '^channel [RGB]:')
    if [ -z "$plain" ] || [ "$(echo "$layer" | wc -l)" != 3 ] || [ "$layer" != "$plain" ]; then
        mismatch="region '${region:-whole}': layer '$(echo $layer)', plain '$(echo $plain)'"
        break
    fi
done
if [ -z "$mismatch" ]; then pass "$name"; else fail "$name" "$mismatch"; fi
# Edges: the balls' silhouettes against the floor and sky stay as sharp as the
# reference: nearly every denoised pixel is within 0.1 of the reference (a blur across
# edges would spread the balls' colours into the floor).
worst=$("$program" diff "$scratch/denoised.exr" "$scratch/reference.exr" --fail 0.1 --failpercent 100 |
    sed -n 's/^pixels over 0.1: \([0-9]*\) .*/\1/p')
total=$((96 * 54))
if [ -n "$worst" ] && [ "$worst" -lt $((total / 50)) ]; then pass "denoised pixels within 0.1 of the reference except $worst of $total"
else fail "denoiser edges" "$worst of $total pixels off by more than 0.1"; fi

# Highlights that only the colour shows (the light in the metal and glass balls): the
# render's per-pixel variance tells the denoiser they are no noise. The brightest pixel
# (the light in the metal ball) keeps at least 3/4 of its reference value (measured 0.83
# at seeds 3, 5, 7, 9; with the noise measured around each pixel instead, as --denoise did
# before it read the render's variance, 0.41).
"$program" render $scene -o "$scratch/balls-reference.exr" $small --spp 1024
"$program" render $scene -o "$scratch/balls-denoised.exr" $small --spp 32 --denoise
reference_peak=$(channel_range "$scratch/balls-reference.exr" R)
denoised_peak=$(channel_range "$scratch/balls-denoised.exr" R)
if awk -v r="${reference_peak#* }" -v d="${denoised_peak#* }" 'BEGIN { exit !(r > 2 && d >= 0.75 * r && d <= 1.1 * r) }'
then pass "--denoise keeps the light seen in the metal ball (peak ${denoised_peak#* } against ${reference_peak#* })"
else fail "--denoise keeps highlights" "peak '${denoised_peak#* }' against the reference's '${reference_peak#* }'"; fi

# Emitters and the sky seen at once are no noise: a scene of nothing else (an emissive
# sphere in a constant sky) denoises to itself, silhouette pixels included, and its
# emission layer is the colour. Filtering them with the rest made a silhouette pixel that a
# light covers in part the average of its neighbours.
cat >"$scratch/glow.txt" <<'SCENE'
render size 32 32 spp 8 depth 8 seed 1
camera from 0 0 4 at 0 0 0 up 0 1 0 fov 30
sky constant 0.2 0.3 0.4
material glow emissive 0.7 0.4 0.2 strength 3
sphere 0 0 0 1 glow
SCENE
"$program" render "$scratch/glow.txt" -o "$scratch/glow-plain.exr" --quiet
"$program" render "$scratch/glow.txt" -o "$scratch/glow.exr" --denoise --quiet
if "$program" diff "$scratch/glow.exr" "$scratch/glow-plain.exr" --fail 1e-5 --failpercent 0 >/dev/null; then
    pass "--denoise leaves a scene of emitters and sky as it was rendered (within 1e-5)"
else fail "--denoise and direct emission" "$("$program" diff "$scratch/glow.exr" "$scratch/glow-plain.exr" --fail 1e-5 --failpercent 0 | tail -n 3 | tr '\n' ' ')"; fi
mismatch=""
for region in "" 15,15,17,17 0,0,2,2 2,12,8,20; do
    layer=$(stats_lines "$scratch/glow.exr" $region | sed -n 's/^channel emission\.\([RGB]\):/channel \1:/p')
    plain=$(stats_lines "$scratch/glow-plain.exr" $region | grep -E '^channel [RGB]:')
    if [ -z "$plain" ] || [ "$layer" != "$plain" ]; then
        mismatch="region '${region:-whole}': emission '$(echo $layer)', colour '$(echo $plain)'"
        break
    fi
done
if [ -z "$mismatch" ]; then pass "--denoise: emission.R/G/B is the colour where camera rays see only emitters and sky"
else fail "--denoise emission layer" "$mismatch"; fi

# `rtspheres denoise` of an EXR rendered with --aovs is --denoise's image, bit for bit,
# with the same layers; also when that EXR was rendered in tiles (which cannot denoise
# themselves: the denoiser needs the whole image), since tiles change no pixel.
cornell=scenes/cornell.txt
"$program" render $cornell -o "$scratch/c-denoised.exr" --size 64x48 --spp 16 --seed 3 --quiet --denoise
"$program" render $cornell -o "$scratch/c-aovs.exr" --size 64x48 --spp 16 --seed 3 --quiet --aovs
"$program" render $cornell -o "$scratch/c-tiled.exr" --size 64x48 --spp 16 --seed 3 --quiet --aovs \
    --memory-budget 700K
"$program" stats "$scratch/c-tiled.exr" >/dev/null 2>&1 || fail "a tiled render with --aovs" "no output"
for source in aovs tiled; do
    name="rtspheres denoise of the --aovs render ($source) is --denoise's image"
    if ! "$program" denoise "$scratch/c-$source.exr" -o "$scratch/c-$source-denoised.exr" --quiet; then
        fail "$name" "denoise failed"
    elif ! "$program" diff "$scratch/c-$source-denoised.exr" "$scratch/c-denoised.exr" --fail 0 --failpercent 0 \
            >/dev/null; then
        fail "$name" "$("$program" diff "$scratch/c-$source-denoised.exr" "$scratch/c-denoised.exr" | grep 'max error')"
    elif [ "$(channels_of "$scratch/c-$source-denoised.exr")" != "$(channels_of "$scratch/c-denoised.exr")" ]; then
        fail "$name" "layers '$(channels_of "$scratch/c-$source-denoised.exr")'"
    else pass "$name"; fi
done
if "$program" render $cornell -o "$scratch/c-tiled-check.exr" --size 64x48 --spp 16 --seed 3 --aovs \
        --memory-budget 700K 2>&1 | grep -q 'tiles'; then
    pass "the 700K budget renders the 64x48 Cornell box in tiles"
else fail "the tiled case of rtspheres denoise" "the 700K budget did not tile the render"; fi
# --denoise and --blur of a render in tiles: the image filtered in blocks, each read with
# the filters' reach (postprocess.h) more pixels on every side, is the untiled image bit
# for bit, layers and all; at the 700K budget the blocks are 64 pixels a side, so a
# 48x400 image has 7 of them in a column and a 300x160 one 5 x 3.
for case in "48x400 --denoise" "48x400 --blur 1.5:2" "48x400 --denoise --blur 1" "300x160 --blur 1.5:2" \
    "300x160 --denoise"; do
    size=${case%% *} options=${case#* }
    name="$options of a $size render in tiles is the untiled image"
    # shellcheck disable=SC2086
    "$program" render $cornell -o "$scratch/tall.exr" --size "$size" --spp 8 --seed 5 --quiet $options
    # shellcheck disable=SC2086
    if ! "$program" render $cornell -o "$scratch/tall-tiled.exr" --size "$size" --spp 8 --seed 5 $options \
            --memory-budget 700K >"$scratch/tall.log" 2>&1; then
        fail "$name" "$(head -c 300 "$scratch/tall.log")"
    elif ! grep -q 'tiles' "$scratch/tall.log"; then
        fail "$name" "the 700K budget did not tile it: $(head -c 300 "$scratch/tall.log")"
    elif ! "$program" diff "$scratch/tall-tiled.exr" "$scratch/tall.exr" --fail 0 --failpercent 0 >/dev/null; then
        fail "$name" "$("$program" diff "$scratch/tall-tiled.exr" "$scratch/tall.exr" | grep 'max error')"
    elif [ "$(channels_of "$scratch/tall-tiled.exr")" != "$(channels_of "$scratch/tall.exr")" ]; then
        fail "$name" "layers '$(channels_of "$scratch/tall-tiled.exr")' against '$(channels_of "$scratch/tall.exr")'"
    elif [ "$(metadata "$scratch/tall-tiled.exr" postprocess)" != "$(metadata "$scratch/tall.exr" postprocess)" ]; then
        fail "$name" "postprocess '$(metadata "$scratch/tall-tiled.exr" postprocess)'"
    else pass "$name"; fi
done
# Each layer too, not only R, G, B: the noisy colour and the AOVs as the untiled file has them.
name="a tiled --denoise render's layers are the untiled render's"
stats_of "$scratch/tall-tiled.exr"
cp "$scratch/stats" "$scratch/stats-tiled"
stats_of "$scratch/tall.exr"
if [ "$(grep '^channel' "$scratch/stats-tiled")" = "$(grep '^channel' "$scratch/stats")" ]; then pass "$name"
else fail "$name" "$(diff "$scratch/stats-tiled" "$scratch/stats" | grep '^[<>] channel' | head -n 4 | tr '\n' ' ')"; fi
if "$program" denoise "$scratch/c-aovs.exr" -o "$scratch/c-aovs.png" --tonemap aces --quiet &&
    [ "$(channels_of "$scratch/c-aovs.png")" = "B G R" ]; then
    pass "rtspheres denoise writes a tone-mapped PNG"
else fail "rtspheres denoise to a PNG" "channels '$(channels_of "$scratch/c-aovs.png")'"; fi
# The denoised file says what its render said (scene, hash, samples, seed, ...), less the
# options hash (it is not what those options render: --skip-existing renders over it), and
# that it was denoised; so do --denoise's and --blur's renders, and the PNG.
stats_of "$scratch/c-aovs.exr"
cp "$scratch/stats" "$scratch/stats-aovs"
stats_of "$scratch/c-aovs-denoised.exr"
name="rtspheres denoise carries the render's metadata"
problem=""
for key in scene scene_hash spp seed max_depth samples_finished path_segments complete stop_reason render_seconds; do
    [ "$(stat_metadata $key)" = "$(stat_metadata $key "$scratch/stats-aovs")" ] && [ -n "$(stat_metadata $key)" ] ||
        problem="$problem $key '$(stat_metadata $key)' against '$(stat_metadata $key "$scratch/stats-aovs")';"
done
[ -z "$(stat_metadata options_hash)" ] || problem="$problem an options_hash;"
[ "$(stat_metadata postprocess)" = denoise ] || problem="$problem postprocess '$(stat_metadata postprocess)';"
if [ -z "$problem" ]; then pass "$name"; else fail "$name" "$problem"; fi
if [ "$(metadata "$scratch/c-aovs.png" postprocess)" = denoise ] &&
    [ "$(metadata "$scratch/c-aovs.png" scene_hash)" = "$(stat_metadata scene_hash "$scratch/stats-aovs")" ]; then
    pass "rtspheres denoise's PNG carries the metadata too"
else fail "rtspheres denoise's PNG metadata" "postprocess '$(metadata "$scratch/c-aovs.png" postprocess)'"; fi
"$program" render $cornell -o "$scratch/c-blurred.exr" --size 32x24 --spp 4 --quiet --denoise --blur 1.5
stats_of "$scratch/c-blurred.exr"
if [ "$(stat_metadata postprocess)" = "denoise; blur sigma=1.5 passes=1" ] && [ -n "$(stat_metadata options_hash)" ]; then
    pass "render --denoise --blur records both in rtspheres:postprocess"
else fail "render's postprocess metadata" "'$(stat_metadata postprocess)', options hash '$(stat_metadata options_hash)'"; fi
if [ -z "$(metadata "$scratch/c-aovs.exr" postprocess)" ]; then pass "a raw render has no postprocess key"
else fail "a raw render's metadata" "postprocess '$(metadata "$scratch/c-aovs.exr" postprocess)'"; fi
cp "$scratch/c-aovs-denoised.exr" "$scratch/c-skip.exr"
name="--skip-existing renders over a denoised file, not taking it for the --aovs render"
if "$program" render $cornell -o "$scratch/c-skip.exr" --size 64x48 --spp 16 --seed 3 --aovs --skip-existing \
        >"$scratch/skip.log" 2>&1 && grep -q 'rendering afresh' "$scratch/skip.log" &&
    [ -z "$(metadata "$scratch/c-skip.exr" postprocess)" ]; then
    pass "$name"
else fail "$name" "$(head -c 300 "$scratch/skip.log")"; fi

"$program" render $cornell -o "$scratch/c-plain.exr" --size 64x48 --spp 4 --quiet
expect_refusal "rtspheres denoise of an EXR without AOVs is refused" "no albedo.R/G/B layer.*--aovs" \
    "$scratch/refused" "$program" denoise "$scratch/c-plain.exr" -o "$scratch/refused/x.exr"
expect_refusal "rtspheres denoise of a denoised EXR is refused" "is post-processed already .denoise." \
    "$scratch/refused" "$program" denoise "$scratch/c-denoised.exr" -o "$scratch/refused/x.exr"
expect_refusal "rtspheres denoise without -o is refused" "no output" \
    "$scratch/refused" "$program" denoise "$scratch/c-aovs.exr"
expect_refusal "rtspheres denoise to an unknown format is refused" "cannot tell the output's format" \
    "$scratch/refused" "$program" denoise "$scratch/c-aovs.exr" -o "$scratch/refused/x.abc"
expect_refusal "rtspheres denoise of a missing file is refused" "c-missing.exr" \
    "$scratch/refused" "$program" denoise "$scratch/c-missing.exr" -o "$scratch/refused/x.exr"
cp "$scratch/c-aovs.exr" "$scratch/c-keep.exr"
name="rtspheres denoise never writes over its input"
if exits_with 2 "is the input" "$program" denoise "$scratch/c-aovs.exr" -o "$scratch/c-aovs.exr" &&
    cmp -s "$scratch/c-aovs.exr" "$scratch/c-keep.exr"; then
    pass "$name"
else fail "$name" "$problem"; fi

# AOVs alone; a PNG cannot carry them.
"$program" render $scene -o "$scratch/aovs.exr" $small --spp 2 --aovs
depth=$(channel_range "$scratch/aovs.exr" depth.Z)
if awk -v r="$depth" 'BEGIN { split(r, v, " "); exit !(v[1] == 0 && v[2] > 4) }'; then
    pass "--aovs: depth is 0 where the sky is seen and metres elsewhere ($depth)"
else fail "--aovs depth" "range $depth"; fi
variance=$(channel_range "$scratch/aovs.exr" variance.Y)
if awk -v r="$variance" 'BEGIN { split(r, v, " "); exit !(v[1] == 0 && v[2] > 0) }'; then
    pass "--aovs: the variance of a noisy 2 spp render is positive somewhere ($variance)"
else fail "--aovs variance on a noisy render" "range '$variance'"; fi

# AOV values where they are known. A diffuse sphere of albedo (0.7, 0.4, 0.2), radius 1 at
# the origin, in a white sky, seen from (0, 0, 4) with a 30 degree fov (furnace.txt in
# colour): its pixels' radiance is exactly the albedo in every sample.
cat >"$scratch/aov-sphere.txt" <<'SCENE'
render size 32 32 spp 4 depth 8 seed 1
camera from 0 0 4 at 0 0 0 up 0 1 0 fov 30
sky constant 1 1 1
material paint lambertian 0.7 0.4 0.2
sphere 0 0 0 1 paint
SCENE
sphere=$scratch/aov-sphere.exr
if "$program" render "$scratch/aov-sphere.txt" -o "$sphere" --aovs --quiet; then
    inside=10,10,22,22   # well inside the silhouette (radius about 15 pixels)
    stats_lines "$sphere" $inside >"$scratch/inside"
    bad=""
    for pair in albedo.R:0.7 albedo.G:0.4 albedo.B:0.2; do
        range=$(range_of ${pair%:*})
        near "${range% *}" ${pair#*:} 1e-6 && near "${range#* }" ${pair#*:} 1e-6 || bad="$bad ${pair%:*} '$range'"
    done
    if [ -z "$bad" ]; then pass "--aovs: albedo.R/G/B is (0.7, 0.4, 0.2) on every pixel of the sphere"
    else fail "--aovs albedo on the sphere" "expected 0.7 0.4 0.2:$bad"; fi
    range=$(range_of variance.Y)
    if [ "$range" = "0 0" ]; then pass "--aovs: variance.Y is 0 where every sample is the same (the sphere)"
    else fail "--aovs variance on the sphere" "min/max '$range', expected 0 0"; fi
    # Over the whole image samples lie between the sphere's luminance (0.449) and the sky's
    # (1), so the variance is at most (1 - 0.449)^2 / 4 = 0.0758; silhouette pixels mix both.
    range=$(channel_range "$sphere" variance.Y)
    if awk -v r="$range" 'BEGIN { split(r, v, " "); exit !(v[1] == 0 && v[2] > 0 && v[2] <= 0.0759) }'; then
        pass "--aovs: variance.Y is within [0, 0.0758] and positive on the silhouette ($range)"
    else fail "--aovs variance bounds" "min/max '$range', expected 0 and (0, 0.0758]"; fi
    range=$(range_of normal.Z)
    if awk -v r="$range" 'BEGIN { split(r, v, " "); exit !(v[1] > 0.85 && v[2] <= 1) }'; then
        pass "--aovs: normal.Z faces the camera on the sphere's middle ($range)"
    else fail "--aovs normals face the camera" "normal.Z min/max '$range', expected (0.85, 1]"; fi
    # At single pixels: the normal is unit length and, like the depth, that of the ray
    # through the pixel's centre hitting the unit sphere (the AOVs average 8 jittered rays
    # in the pixel: within 0.02).
    for xy in 16,16 24,8 6,20 4,16; do
        x=${xy%,*} y=${xy#*,}
        pixel "$sphere" $x $y
        nx=$(value normal.X) ny=$(value normal.Y) nz=$(value normal.Z) t=$(value depth.Z)
        expected=$(awk -v x=$x -v y=$y 'BEGIN {
            k = sin(15 * atan2(0, -1) / 180) / cos(15 * atan2(0, -1) / 180)
            dx = (2 * (x + 0.5) / 32 - 1) * k; dy = (1 - 2 * (y + 0.5) / 32) * k; l = sqrt(dx * dx + dy * dy + 1)
            dx /= l; dy /= l; dz = -1 / l
            b = 4 * dz; t = -b - sqrt(b * b - 15)
            printf "%.6f %.6f %.6f %.6f", dx * t, dy * t, 4 + dz * t, t }')
        set -- $expected
        name="--aovs at pixel ($x, $y): unit normal ($nx $ny $nz) and depth $t, expected ($1 $2 $3) and $4"
        length=$(awk -v a="$nx" -v b="$ny" -v c="$nz" 'BEGIN { print sqrt(a * a + b * b + c * c) }')
        if near "$length" 1 1e-4 && near "$nx" $1 0.02 && near "$ny" $2 0.02 && near "$nz" $3 0.02 \
            && near "$t" $4 0.02; then
            pass "$name"
        else fail "$name" "length $length"; fi
    done
else
    fail "--aovs on the sphere" "render failed"
fi

# A plane facing the camera 5 units away, seen with a 2 degree fov: depth.Z (the distance
# along each ray) is 5 at the middle and 5 / cos(1.41 degrees) = 5.0015 in the corners;
# the normal is exactly (0, 0, 1) everywhere; the albedo is the plane's.
cat >"$scratch/aov-plane.txt" <<'SCENE'
render size 16 16 spp 1 depth 4 seed 1
camera from 0 0 5 at 0 0 0 up 0 1 0 fov 2
sky constant 0.5 0.5 0.5
material wall lambertian 0.3 0.6 0.9
quad -10 -10 0  20 0 0  0 20 0 wall
SCENE
plane=$scratch/aov-plane.exr
if "$program" render "$scratch/aov-plane.txt" -o "$plane" --aovs --quiet; then
    stats_lines "$plane" >"$scratch/inside"
    bad=""
    depth=$(range_of depth.Z)
    near "${depth% *}" 5 1e-4 && near "${depth#* }" 5.0008 0.0008 || bad="$bad depth.Z '$depth' (expected 5 to 5.0016)"
    for pair in normal.X:0 normal.Y:0 normal.Z:1 albedo.R:0.3 albedo.G:0.6 albedo.B:0.9; do
        range=$(range_of ${pair%:*})
        near "${range% *}" ${pair#*:} 1e-6 && near "${range#* }" ${pair#*:} 1e-6 || bad="$bad ${pair%:*} '$range'"
    done
    if [ -z "$bad" ]; then pass "--aovs on a plane facing the camera: depth 5 to 5.0016, normal (0, 0, 1), albedo (0.3, 0.6, 0.9)"
    else fail "--aovs on a plane facing the camera" "$bad"; fi
else
    fail "--aovs on a plane" "render failed"
fi
"$program" render $scene -o "$scratch/aovs.png" $small --spp 2 --aovs 2>"$scratch/err"
code=$?
if [ "$code" = 2 ] && grep -q "only .exr" "$scratch/err"; then pass "--aovs with a PNG output is refused"
else fail "--aovs with a PNG" "exit $code: $(cat "$scratch/err")"; fi

# Blur: off by default (a render without it equals the noisy one), on when asked, and it
# keeps the mean.
"$program" render $diffuse -o "$scratch/blurred.exr" $small --spp 8 --blur 1.5:2
if "$program" diff "$scratch/blurred.exr" "$scratch/noisy.exr" --fail 0 --failpercent 0 >/dev/null; then
    fail "--blur" "the blurred image equals the plain one"
else pass "--blur changes the image"; fi
mean_blurred=$(channel_mean "$scratch/blurred.exr" G)
mean_plain=$(channel_mean "$scratch/noisy.exr" G)
if within "$mean_blurred" "$mean_plain" 0.01; then pass "--blur keeps the image mean ($mean_blurred vs $mean_plain)"
else fail "--blur mean" "$mean_blurred vs $mean_plain"; fi

# Exposure: an 8-bit output at +1 stop is twice as bright in linear terms. The furnace
# sphere of albedo 0.2 is exactly 0.2 (linear) inside its silhouette: 8-bit sRGB codes
# round(255 * srgb(0.2)) = 124 at 0 stops and round(255 * srgb(0.4)) = 170 at +1 stop (no
# clipping); decoded, their ratio is 2 within the 8-bit rounding (2%). EXR stays linear.
inside=10,10,22,22
for stops in 0 1; do
    "$program" render scenes/furnace.txt -o "$scratch/exposure$stops.png" --size 32x32 --spp 4 -D albedo=0.2 \
        --exposure $stops --quiet
done
"$program" render scenes/furnace.txt -o "$scratch/exposure1.exr" --size 32x32 --spp 4 -D albedo=0.2 --exposure 1 --quiet
"$program" render scenes/furnace.txt -o "$scratch/exposure0.exr" --size 32x32 --spp 4 -D albedo=0.2 --quiet
srgb_code() { awk -v v="$1" 'BEGIN { e = v <= 0.0031308 ? 12.92 * v : 1.055 * exp(log(v) / 2.4) - 0.055; printf "%d", e * 255 + 0.5 }'; }
decode() { awk -v c="$1" 'BEGIN { printf "%.9g", c <= 0.04045 ? c / 12.92 : exp(2.4 * log((c + 0.055) / 1.055)) }'; }
linear=$(channel_range "$scratch/exposure0.exr" G $inside)
range0=$(channel_range "$scratch/exposure0.png" G $inside)
range1=$(channel_range "$scratch/exposure1.png" G $inside)
code0=$(awk -v v="${range0% *}" 'BEGIN { printf "%d", v * 255 + 0.5 }')
code1=$(awk -v v="${range1% *}" 'BEGIN { printf "%d", v * 255 + 0.5 }')
ratio=$(awk -v a="$(decode "${range1% *}")" -v b="$(decode "${range0% *}")" 'BEGIN { print a / b }')
name="--exposure 1: 8-bit code $code0 -> $code1, decoded linear ratio $ratio"
if [ "$linear" != "0.200000003 0.200000003" ]; then
    fail "$name" "the linear render inside the sphere is '$linear', expected 0.2 everywhere"
elif [ "${range0% *}" != "${range0#* }" ] || [ "${range1% *}" != "${range1#* }" ]; then
    fail "$name" "the 8-bit pixels are not uniform: '$range0', '$range1'"
elif [ "$code0" != "$(srgb_code 0.2)" ] || [ "$code1" != "$(srgb_code 0.4)" ]; then
    fail "$name" "expected codes $(srgb_code 0.2) and $(srgb_code 0.4)"
elif ! within "$ratio" 2 0.02; then
    fail "$name" "expected 2 within 2%"
else pass "$name"; fi
if "$program" diff "$scratch/exposure1.exr" "$scratch/exposure0.exr" --fail 0 --failpercent 0 >/dev/null 2>&1; then
    pass "--exposure leaves an EXR linear"
else fail "--exposure and EXR" "the EXR changed"; fi

# Tone mapping: 8-bit only; Reinhard darkens the bright light seen in the image.
"$program" render $scene -o "$scratch/clamp.png" $small --spp 4
"$program" render $scene -o "$scratch/reinhard.png" $small --spp 4 --tonemap reinhard
"$program" render $scene -o "$scratch/reinhard.exr" $small --spp 4 --tonemap reinhard
"$program" render $scene -o "$scratch/plain.exr" $small --spp 4
mean_clamp=$(channel_mean "$scratch/clamp.png" G)
mean_reinhard=$(channel_mean "$scratch/reinhard.png" G)
if awk -v c="$mean_clamp" -v r="$mean_reinhard" 'BEGIN { exit !(r < c) }'; then
    pass "--tonemap reinhard compresses the 8-bit image ($mean_reinhard < $mean_clamp)"
else fail "--tonemap reinhard" "$mean_reinhard vs $mean_clamp"; fi
if "$program" diff "$scratch/reinhard.exr" "$scratch/plain.exr" --fail 0 --failpercent 0 >/dev/null; then
    pass "--tonemap leaves an EXR linear"
else fail "--tonemap and EXR" "the EXR changed"; fi
"$program" render $scene -o "$scratch/x.png" $small --spp 1 --tonemap filmic 2>/dev/null
code=$?
if [ "$code" = 2 ]; then pass "an unknown --tonemap is refused"
else fail "unknown --tonemap" "exit $code"; fi
finish
