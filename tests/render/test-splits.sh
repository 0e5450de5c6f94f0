#!/bin/sh
# test-splits.sh: the ways `rtspheres render` splits one render (docs/scale-out.md):
# --crop regions are exactly the full render's pixels, --shard I/N by tiles and by
# samples merge back into it, --shard with --frames renders exactly the frames whose
# position in the list is I mod N, and options that contradict each other are usage
# errors (exit 2, a message, nothing written).
#   usage: sh tests/render/test-splits.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# The test scene and its whole render $full (lib.sh); nothing to compare without it.
render_split_scene || { finish; exit; }

# merged_equals NAME TOLERANCE PARTS...: merges PARTS (into $scratch/merged.exr) and compares the result with the
# full render by `diff --fail TOLERANCE --failpercent 0`; every pixel must have 16 samples.
merged_equals() {
    merged_name=$1 merged_tolerance=$2
    shift 2
    problem=$(merge_problem "$full" "$merged_tolerance" 16 "$scratch/merged.exr" "$@")
    if [ -n "$problem" ]; then fail "$merged_name" "$problem"; else pass "$merged_name"; fi
}

# usage_error NAME PATTERN ARGS...: `render ARGS` (the test scene, size and spp, output
# $scratch/refused/out.exr or a pattern there) exits 2, says PATTERN (grep -E) on stderr
# and writes nothing.
usage_error() {
    usage_name=$1 usage_pattern=$2
    shift 2
    # shellcheck disable=SC2086 # $render_options is a list of options
    expect_refusal "$usage_name" "$usage_pattern" "$scratch/refused" \
        "$program" render "$scene" $render_options --quiet "$@"
}

# (a) Crops. Three crops that tile the image (uneven, and meeting inside rows and columns)
# merge by their data windows into exactly the full render.
render "$scratch/crop-a.exr" --crop 0,0,20,12
render "$scratch/crop-b.exr" --crop 20,0,48,12
render "$scratch/crop-c.exr" --crop 0,12,48,27
merged_equals "crops covering the image merge into exactly the full render" 0 \
    "$scratch/crop-b.exr" "$scratch/crop-c.exr" "$scratch/crop-a.exr"
# One crop on its own is the full render's region: size, and every channel's
# mean/min/max printed by `stats` identical to `stats --crop` of the full render.
for crop in 20,0,48,12 47,26,48,27 5,7,31,19; do
    render "$scratch/crop.exr" --crop $crop
    x0=${crop%%,*} rest=${crop#*,}; y0=${rest%%,*} rest=${rest#*,}; x1=${rest%%,*} y1=${rest#*,}
    "$program" stats "$scratch/crop.exr" | grep -E '^(size:|channel )' >"$scratch/crop.stats"
    "$program" stats "$full" --crop $crop | grep '^channel ' >"$scratch/region.stats"
    if [ "$(head -n 1 "$scratch/crop.stats")" != "size: $((x1 - x0))x$((y1 - y0))" ]; then
        fail "--crop $crop size" "$(head -n 1 "$scratch/crop.stats"), expected $((x1 - x0))x$((y1 - y0))"
    elif [ "$(grep -c '^channel ' "$scratch/region.stats")" != 4 ]; then
        fail "--crop $crop" "stats of the full render's region printed no channels"
    elif [ "$(sed 1d "$scratch/crop.stats")" = "$(cat "$scratch/region.stats")" ]; then
        pass "--crop $crop has the full render's pixel statistics in that region"
    else
        fail "--crop $crop" "crop: $(sed 1d "$scratch/crop.stats" | tr '\n' ' ') region: $(tr '\n' ' ' <"$scratch/region.stats")"
    fi
done

# (b) --shard I/4 --shard-by tiles: 27 rows in bands of 6, 7, 7, 7 rows (floor(I*27/4)),
# merged bit-exactly.
for i in 0 1 2 3; do render "$scratch/tile$i.exr" --shard $i/4 --shard-by tiles; done
heights=""
for i in 0 1 2 3; do heights="$heights $("$program" stats "$scratch/tile$i.exr" | sed -n 's/^size: //p')"; done
if [ "$heights" = " 48x6 48x7 48x7 48x7" ]; then pass "--shard I/4 --shard-by tiles: bands of 6, 7, 7, 7 rows"
else fail "--shard-by tiles band sizes" "sizes:$heights, expected 48x6 48x7 48x7 48x7"; fi
merged_equals "--shard-by tiles parts merge into exactly the full render" 0 \
    "$scratch/tile3.exr" "$scratch/tile1.exr" "$scratch/tile0.exr" "$scratch/tile2.exr"
# --shard-by tiles is --tile: the same band, pixel for pixel.
render "$scratch/band2.exr" --tile 2/4
if "$program" diff "$scratch/band2.exr" "$scratch/tile2.exr" --fail 0 --failpercent 0 >/dev/null 2>&1; then
    pass "--shard 2/4 --shard-by tiles equals --tile 2/4"
else fail "--shard-by tiles vs --tile" "the two bands differ"; fi

# (c) --shard I/3 --shard-by samples of 16 samples: sample ranges 0:5, 5:5, 10:6, which
# merge into the full render within float rounding.
expected_ranges="0:5 5:5 10:6"
ranges=""
for i in 0 1 2; do
    render "$scratch/samples$i.exr" --shard $i/3 --shard-by samples
    ranges="$ranges $(metadata "$scratch/samples$i.exr" sample_start):$(metadata "$scratch/samples$i.exr" spp)"
done
if [ "$ranges" = " $expected_ranges" ]; then pass "--shard I/3 --shard-by samples: sample ranges $expected_ranges"
else fail "--shard-by samples ranges" "start:count$ranges, expected $expected_ranges"; fi
merged_equals "--shard-by samples parts merge into the full render within 1e-5" 1e-5 \
    "$scratch/samples2.exr" "$scratch/samples0.exr" "$scratch/samples1.exr"
# Without --frames the default is by samples.
render "$scratch/default1.exr" --shard 1/3
if "$program" diff "$scratch/default1.exr" "$scratch/samples1.exr" --fail 0 --failpercent 0 >/dev/null 2>&1 &&
   [ "$(metadata "$scratch/default1.exr" sample_start)" = 5 ]; then
    pass "--shard 1/3 without --frames splits by samples"
else fail "default --shard-by" "--shard 1/3 differs from --shard 1/3 --shard-by samples"; fi
# A region and a sample shard combine: two bands times two sample halves.
for t in 0 1; do
    for s in 0 1; do render "$scratch/band$t-half$s.exr" --tile $t/2 --shard $s/2; done
done
merged_equals "--tile I/2 --shard J/2 parts merge into the full render within 1e-5" 1e-5 \
    "$scratch/band0-half0.exr" "$scratch/band0-half1.exr" "$scratch/band1-half0.exr" "$scratch/band1-half1.exr"

# (d) --shard I/3 with --frames 1-10,15,20-30:2 (17 frames; by frames, the default when
# --frames lists several): part I renders the frames at positions I, I+3, I+6, ... of the
# list (docs/scale-out.md).
list=1-10,15,20-30:2
all=""
for i in 0 1 2; do
    dir=$scratch/frame-shard$i
    mkdir -p "$dir"
    "$program" render scenes/three-balls.txt -o "$dir/f-%02d.png" --size 16x9 --spp 1 --max-depth 2 --quiet \
        --frames $list --shard $i/3
    case $i in
        0) expected="f-01.png f-04.png f-07.png f-10.png f-22.png f-28.png" ;;
        1) expected="f-02.png f-05.png f-08.png f-15.png f-24.png f-30.png" ;;
        2) expected="f-03.png f-06.png f-09.png f-20.png f-26.png" ;;
    esac
    files_are "--frames $list --shard $i/3 renders exactly $expected" "$dir" "$expected"
    all="$all $(ls "$dir")"
done
count=$(echo $all | tr ' ' '\n' | sort -u | wc -l)
if [ "$count" = 17 ]; then pass "the three frame shards together render each of the 17 frames once"
else fail "frame shards cover the list" "$count distinct frames"; fi
# A sharded frame is that frame's render.
"$program" render scenes/three-balls.txt -o "$scratch/f-%02d.png" --size 16x9 --spp 1 --max-depth 2 --quiet --frames 22
if "$program" diff "$scratch/frame-shard0/f-22.png" "$scratch/f-22.png" --fail 0 --failpercent 0 >/dev/null 2>&1; then
    pass "frame 22 of shard 0 equals --frames 22"
else fail "sharded frame" "frame 22 of shard 0 differs from --frames 22"; fi
# --shard-by samples with --frames: every frame, each with its part of the samples.
dir=$scratch/frames-by-samples
mkdir -p "$dir"
"$program" render scenes/three-balls.txt -o "$dir/f-%d.exr" --size 16x9 --spp 4 --max-depth 2 --quiet \
    --frames 0-1 --shard 1/2 --shard-by samples
files_are "--frames 0-1 --shard 1/2 --shard-by samples renders both frames" "$dir" "f-0.exr f-1.exr"
got="$(metadata "$dir/f-1.exr" sample_start):$(metadata "$dir/f-1.exr" spp)"
if [ "$got" = 2:2 ]; then pass "each frame of a sample shard has samples 2:2 of 4"
else fail "sample shard of frames" "frame 1 has samples $got, expected 2:2"; fi

# (e) Contradictions and empty parts: exit 2 with a message, nothing written.
out=$scratch/refused/out.exr
usage_error "--crop with --tile refused" "--crop and --tile both choose the region" -o "$out" --crop 0,0,8,8 --tile 0/2
usage_error "--shard-by tiles with --crop refused" "--shard by tiles and --crop/--tile" -o "$out" --crop 0,0,8,8 \
    --shard 0/2 --shard-by tiles
usage_error "--shard-by tiles with --tile refused" "--shard by tiles and --crop/--tile" -o "$out" --tile 0/2 \
    --shard 0/2 --shard-by tiles
usage_error "--shard by samples with --samples refused" "--shard by samples and --samples" -o "$out" --samples 0:8 \
    --shard 0/2
usage_error "--shard-by frames without --frames refused" "--shard-by frames needs --frames" -o "$out" --shard 0/2 \
    --shard-by frames
usage_error "--shard-by without --shard refused" "--shard-by tiles does nothing without --shard" -o "$out" \
    --shard-by tiles
usage_error "--resume with several frames refused" "--resume continues one image" -o "$scratch/refused/f-%d.exr" \
    --frames 0-1 --resume "$full"
usage_error "--shard 3/3 refused" "I must be 0 to N-1" -o "$out" --shard 3/3
usage_error "--shard-by pixels refused" "--shard-by wants frames, samples or tiles" -o "$out" --shard 0/2 --shard-by pixels
usage_error "--crop 8,0,8,4 refused" "--crop wants x0,y0,x1,y1 with x0 < x1" -o "$out" --crop 8,0,8,4
usage_error "--crop past the image refused" "region 40,20,49,27 is not a non-empty part of the 48x27 image" -o "$out" \
    --crop 40,20,49,27
# Shard 0/17 of 16 samples is 0:0 (floor(I*S/N) to floor((I+1)*S/N)).
usage_error "an empty sample shard refused" "shard 0/17 of 16 samples per pixel is empty" -o "$out" --shard 0/17
usage_error "an empty tile refused" "tile 0/30 of a 27-row image is empty" -o "$out" --tile 0/30
usage_error "an empty frame shard refused" "shard 2/3 of 2 frames is empty" -o "$scratch/refused/f-%d.exr" \
    --frames 1-2 --shard 2/3

finish
