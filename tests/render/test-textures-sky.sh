#!/bin/sh
# test-textures-sky.sh: textures, image textures, the sky box and the environment map,
# and motion blur, checked by what must hold exactly (not against goldens).
#   usage: sh tests/render/test-textures-sky.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# ppm FILE TOP BOTTOM: an 8x8 binary PPM whose top four rows are colour TOP and bottom
# four BOTTOM, colours given as three octal byte escapes for printf, e.g. '\377\000\000'.
ppm() {
    {
        printf 'P6\n8 8\n255\n'
        for row in 0 1 2 3 4 5 6 7; do
            for column in 0 1 2 3 4 5 6 7; do
                if [ "$row" -lt 4 ]; then printf "$2"; else printf "$3"; fi
            done
        done
    } >"$1"
}

# render_centre NAME SCENE-TEXT: renders SCENE-TEXT (16x16) and prints the G mean of the
# centre 4x4 pixels... for clarity, prints "R G B" means.
render_rgb() {
    name=$1
    printf '%s\n' "$2" >"$scratch/$name.txt"
    "$program" render "$scratch/$name.txt" -o "$scratch/$name.exr" --quiet 2>"$scratch/$name.err" || {
        echo "render-failed"
        return
    }
    crop=${3:-6,6,10,10}
    echo "$(channel_mean "$scratch/$name.exr" R "$crop") $(channel_mean "$scratch/$name.exr" G "$crop") $(channel_mean "$scratch/$name.exr" B "$crop")"
}

header='render size 16 16 spp 4 depth 8 seed 1
camera from 0 0 0 at 0 0 -1 up 0 1 0 fov 20'

# A constant texture is the colour itself: bit-identical images.
common="$header
sky constant 1 1 1"
plain=$(render_rgb plain "$common
material m lambertian 0.2 0.4 0.6
sphere 0 0 -5 2 m")
textured=$(render_rgb textured "$common
texture c constant 0.2 0.4 0.6
material m lambertian @c
sphere 0 0 -5 2 m")
if [ "$plain" = "$textured" ] && [ "$plain" != render-failed ]; then pass "a constant texture equals its colour ($plain)"
else fail "a constant texture equals its colour" "plain '$plain', textured '$textured'"; fi

# A uniform 8-bit image texture is sRGB-decoded: byte 128 is 0.2158 in linear light. In a
# white furnace the sphere then shows exactly that albedo. A second image of another size
# is used by another sphere in the same scene (no "all textures one size" limit).
ppm "$scratch/grey.ppm" '\200\200\200' '\200\200\200'
printf 'P6\n3 1\n255\n\377\377\377\377\377\377\377\377\377' >"$scratch/white.ppm"
result=$(render_rgb image "$header
sky constant 1 1 1
texture grey image \"grey.ppm\"
texture white image \"white.ppm\"
material g lambertian @grey
material w lambertian @white
sphere 0 0 -5 1.5 g
sphere 0 0 -20 1 w")
mean=${result%% *}
# OpenImageIO reports PPM as Rec.709-encoded: 128 decodes to 0.2615 (sRGB would be 0.2158).
if within "$mean" 0.2615 0.02 || within "$mean" 0.2158 0.02; then pass "an 8-bit image texture is decoded to linear ($mean)"
else fail "an 8-bit image texture is decoded to linear" "got $result"; fi

# The checker picks the even texture where floor(p/scale) sums to an even number.
result=$(render_rgb checker "render size 16 16 spp 4 depth 8 seed 1
camera from 50 50 60 at 50 50 0 up 0 1 0 fov 20
sky constant 1 1 1
texture squares checker 100 1 0 0  0 0 1
material m lambertian @squares
sphere 50 50 40 5 m")
if awk -v r="$result" 'BEGIN { split(r, c, " "); exit !(c[1] > 0.9 && c[3] < 0.01) }'; then
    pass "checker: the cell containing the sphere uses the even colour ($result)"
else fail "checker" "centre $result, expected red"; fi

# Sky box orientation: six faces of different colours, each with a different top row, seen
# straight on from the centre. Looking along +X must show the +X face, its top row above.
red='\377\000\000' green='\000\377\000' blue='\000\000\377' white='\377\377\377' black='\000\000\000'
ppm "$scratch/px.ppm" "$white" "$red"
ppm "$scratch/nx.ppm" "$white" "$green"
ppm "$scratch/py.ppm" "$white" "$blue"
ppm "$scratch/ny.ppm" "$black" "$red"
ppm "$scratch/pz.ppm" "$black" "$green"
ppm "$scratch/nz.ppm" "$black" "$blue"
sky='sky box "px.ppm" "nx.ppm" "py.ppm" "ny.ppm" "pz.ppm" "nz.ppm"'
# looking DIRECTION UP EXPECTED-BOTTOM-HALF-CHANNEL: the lower half of the view shows the
# face's bottom row colour.
look() {
    direction=$1 up=$2 channel=$3 label=$4
    # fov 90 shows exactly the face; rows 13-16 of 16 are the bottom eighth of the face.
    result=$(render_rgb "sky-$label" "render size 16 16 spp 1 depth 2 seed 1
camera from 0 0 0 at $direction up $up fov 90
$sky" 4,13,12,16)
    case $channel in
        R) want='c[1] > 0.9 && c[2] < 0.1 && c[3] < 0.1' ;;
        G) want='c[2] > 0.9 && c[1] < 0.1 && c[3] < 0.1' ;;
        B) want='c[3] > 0.9 && c[1] < 0.1 && c[2] < 0.1' ;;
    esac
    if awk -v r="$result" "BEGIN { split(r, c, \" \"); exit !($want) }"; then pass "sky box $label face, bottom half ($result)"
    else fail "sky box $label face" "bottom half $result, expected pure $channel"; fi
}
look "1 0 0" "0 1 0" R "+X"
look "-1 0 0" "0 1 0" G "-X"
look "0 0 1" "0 1 0" G "+Z"
look "0 0 -1" "0 1 0" B "-Z"
# Looking up (+Y) with "up" towards -Z, the bottom of the view is +Z side: the +Y face's
# bottom row (t = +1 is +Z) is blue.
look "0 1 0" "0 0 -1" B "+Y"
look "0 -1 0" "0 0 1" R "-Y"

# A mismatched face is an error naming the face.
printf 'P6\n3 3\n255\n%027d' 0 | tr '0' '\000' >"$scratch/big.ppm"   # 3x3, the others 8x8
printf 'sky box "px.ppm" "nx.ppm" "big.ppm" "ny.ppm" "pz.ppm" "nz.ppm"\n' >"$scratch/mismatch.txt"
"$program" render "$scratch/mismatch.txt" -o "$scratch/mismatch.png" 2>"$scratch/mismatch.err" >/dev/null
code=$?
if [ "$code" = 2 ] && grep -q "+Y" "$scratch/mismatch.err"; then pass "a sky box face of another size is an error naming +Y"
else fail "mismatched sky box face" "exit $code: $(cat "$scratch/mismatch.err")"; fi

# Environment map: looking straight up sees the top row, straight down the bottom row.
ppm "$scratch/env.ppm" "$red" "$blue"
for case in "0 1 0:0 0 -1:R:up" "0 -1 0:0 0 1:B:down"; do
    direction=${case%%:*}; rest=${case#*:}; up=${rest%%:*}; rest=${rest#*:}; channel=${rest%%:*}; label=${rest#*:}
    result=$(render_rgb "env-$label" "render size 8 8 spp 1 depth 2 seed 1
camera from 0 0 0 at $direction up $up fov 10
sky environment \"env.ppm\"" 2,2,6,6)
    if [ "$channel" = R ]; then want='c[1] > 0.9 && c[3] < 0.1'; else want='c[3] > 0.9 && c[1] < 0.1'; fi
    if awk -v r="$result" "BEGIN { split(r, c, \" \"); exit !($want) }"; then pass "environment map looking $label ($result)"
    else fail "environment map looking $label" "$result"; fi
done

# Motion blur: a moving sphere seen at shutter 0.5 0.5 is the static sphere at its
# midpoint (bit-identical), and with the shutter open a pixel it covers part of the time
# is between sky and sphere.
motion="render size 16 16 spp 16 depth 4 seed 1
sky constant 1 1 1
material black lambertian 0 0 0"
moving=$(render_rgb moving "$motion
camera from 0 0 0 at 0 0 -1 up 0 1 0 fov 30 shutter 0.5 0.5
moving_sphere -1 0 -5  1 0 -5  0.5 black" 0,0,16,16)
static=$(render_rgb static "$motion
camera from 0 0 0 at 0 0 -1 up 0 1 0 fov 30
sphere 0 0 -5 0.5 black" 0,0,16,16)
if [ "$moving" = "$static" ] && [ "$moving" != render-failed ]; then pass "a moving sphere at mid-shutter is the static sphere at its midpoint"
else fail "moving sphere at mid-shutter" "moving '$moving', static '$static'"; fi
blurred=$(render_rgb blurred "$motion
camera from 0 0 0 at 0 0 -1 up 0 1 0 fov 30 shutter 0 1
moving_sphere -1 0 -5  1 0 -5  0.5 black" 7,7,9,9)
if awk -v r="$blurred" 'BEGIN { split(r, c, " "); exit !(c[2] > 0.2 && c[2] < 0.9) }'; then
    pass "motion blur: the sweep's middle is partly covered ($blurred)"
else fail "motion blur" "centre $blurred, expected between 0.2 and 0.9"; fi
# Normal maps: a tangent-space map that is (0.5, 0.5, 1) everywhere, (0, 0, 1) once
# decoded, leaves the shading normal as it is, on a sphere and on a quad, so the image
# equals the one without a map (but for float rounding in the bilinear weights); a
# tilted map, (0.7, 0.5, 0.714) = a normal leaning 23 degrees along the tangent, changes
# it. The maps are EXRs rendered by rtspheres itself from a constant sky: exact floats.
printf 'camera from 0 0 1 at 0 0 0 up 0 1 0 fov 40\nsky constant 0.5 0.5 1\n' >"$scratch/flat-map.txt"
printf 'camera from 0 0 1 at 0 0 0 up 0 1 0 fov 40\nsky constant 0.7 0.5 0.714\n' >"$scratch/tilt-map.txt"
if "$program" render "$scratch/flat-map.txt" -o "$scratch/flat.exr" --size 8x8 --spp 1 --quiet &&
   "$program" render "$scratch/tilt-map.txt" -o "$scratch/tilt.exr" --size 8x8 --spp 1 --quiet; then
    for map in none flat tilt; do
        clause=""
        [ $map = none ] || clause="normal_map \"$map.exr\""
        printf 'render size 48 27 spp 16 depth 4 seed 2\ncamera from 0 1 4 at 0 0.6 0 up 0 1 0 fov 40\n%s\n%s\n%s\n%s\n%s\n%s\n%s\n' \
            "sky gradient 1 1 1  0.3 0.5 1" "light sun -0.4 -1 -0.3 color 1 1 1 intensity 2" \
            "material m lambertian 0.8 0.8 0.8 $clause" "material floor lambertian 0.5 0.5 0.5" \
            "sphere 0 0.6 0 0.6 m" "quad -2 0 -1  1.6 0 0  0 1.2 0 m" "sphere 0 -100 0 100 floor" \
            >"$scratch/normal-$map.txt"
        "$program" render "$scratch/normal-$map.txt" -o "$scratch/normal-$map.exr" --quiet ||
            fail "normal map render ($map)" "render failed"
    done
    if "$program" diff "$scratch/normal-flat.exr" "$scratch/normal-none.exr" --fail 1e-5 --failpercent 0 \
            >"$scratch/normal.diff" 2>&1; then
        pass "a flat normal map changes nothing ($(grep '^max error' "$scratch/normal.diff"))"
    else
        fail "a flat normal map changes nothing" "$(tr '\n' ' ' <"$scratch/normal.diff")"
    fi
    if "$program" diff "$scratch/normal-tilt.exr" "$scratch/normal-none.exr" --failpercent 5 >/dev/null 2>&1; then
        fail "a tilted normal map changes the shading" "under 5% of pixels changed"
    else
        pass "a tilted normal map changes the shading"
    fi
else
    fail "normal maps" "could not render the map images"
fi

finish
