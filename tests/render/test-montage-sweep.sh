#!/bin/sh
# test-montage-sweep.sh: the light-sweep example (scenes/sweep-light.sh) and the montage
# command: the frames change with the light, -D overrides reach the scene and repeat
# exactly, the contact sheet holds the frames as they are, and bad montages exit 2
# without touching their inputs.
#   usage: sh tests/render/test-montage-sweep.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

image_size() { "$program" stats "$1" | sed -n 's/^size: //p'; }

# colour_means FILE [CROP]: "R G B", the colour channels' means, from one `stats` run.
colour_means() {
    "$program" stats "$1" ${2:+--crop "$2"} | sed -n 's/^channel [RGB]: mean \([^ ]*\) .*/\1/p' | tr '\n' ' '
}

# same_means A CROP_A B CROP_B: true when every colour channel's mean agrees to 8-bit
# rounding (the sheet re-encodes the frames' 8-bit values; decoding sRGB twice, or not
# at all, would move a mid grey by 0.2).
same_means() {
    echo "$(colour_means "$1" "$2") $(colour_means "$3" "$4")" | awk '{
        if (NF != 6) exit 1
        for (c = 1; c <= 3; c++) { d = $c - $(c + 3); if (d < 0) d = -d; if (d > 0.002) exit 1 }
    }'
}

sweep=$scratch/sweep
if RTSPHERES=$program RTSPHERES_SIZE=32x18 RTSPHERES_SPP=4 sh scenes/sweep-light.sh "$sweep" 4 >"$scratch/sweep.log" 2>&1; then
    pass "sweep-light.sh runs"
else fail "sweep-light.sh runs" "exit $?: $(head -c 300 "$scratch/sweep.log")"; fi

sizes=""
for i in 00 01 02 03; do sizes="$sizes $(image_size "$sweep/light-$i.png" 2>/dev/null)"; done
if [ "$sizes" = " 32x18 32x18 32x18 32x18" ] && [ ! -e "$sweep/light-04.png" ]; then
    pass "sweep writes 4 frames of 32x18"
else fail "sweep writes 4 frames of 32x18" "sizes:$sizes"; fi

# 4 frames: ceil(sqrt(4)) = 2 columns, 2 rows, the default gap of 2 pixels between them;
# under each frame its label band: 5 characters a line at 32 pixels (scale 1, 6 pixels a
# character), the values' text needs the most lines (4), so 4 x 8 + 2 = 34 pixels.
sheet=$sweep/contact-sheet.png
size=$(image_size "$sheet" 2>/dev/null)
if [ "$size" = 66x106 ]; then pass "contact sheet is 2x2 labelled frames with 2-pixel gaps (66x106)"
else fail "contact sheet is 2x2 labelled frames with 2-pixel gaps (66x106)" "size '$size'"; fi

# The tiles are the frames, not re-brightened by decoding sRGB twice, in row order.
if same_means "$sheet" 0,0,32,18 "$sweep/light-00.png" "" && same_means "$sheet" 34,0,66,18 "$sweep/light-01.png" "" &&
   same_means "$sheet" 0,54,32,72 "$sweep/light-02.png" "" && same_means "$sheet" 34,54,66,72 "$sweep/light-03.png" ""; then
    pass "sheet tiles equal the frames, row by row"
else fail "sheet tiles equal the frames, row by row" "a tile's channel means differ from its frame's"; fi
if [ "$(channel_range "$sheet" G 32,0,34,106)" = "0 0" ] && [ "$(channel_range "$sheet" G 0,52,66,54)" = "0 0" ]; then
    pass "sheet gaps are black"
else fail "sheet gaps are black" "gap range $(channel_range "$sheet" G 32,0,34,106)"; fi
# The label bands hold white text on black: pixels of 1 and of 0, mostly 0.
band=$(channel_range "$sheet" G 0,18,32,52)
band_mean=$(channel_mean "$sheet" G 0,18,32,52)
if [ "$band" = "0 1" ] && awk -v m="$band_mean" 'BEGIN { exit !(m > 0.05 && m < 0.5) }'; then
    pass "label bands hold white text on black"
else fail "label bands hold white text on black" "range '$band', mean $band_mean"; fi
# --labels writes the file names: "light-00.png" is 12 characters, 3 lines of 5 at 32
# pixels, a band of 3 x 8 + 2 = 26 pixels.
"$program" montage "$sweep/light-00.png" "$sweep/light-01.png" -o "$scratch/named.png" --labels --quiet
expect_exit "montage --labels adds a band of 3 lines (26 pixels)" 0 "" \
    test "$(image_size "$scratch/named.png")" = 66x44
expect_exit "montage --labels and --label-table together" 2 "give one" \
    "$program" montage "$sweep/light-00.png" -o "$scratch/bad.png" --labels --label-table "$sweep/light-positions.tsv"
expect_exit "montage --label-table with another number of rows" 2 "has 4 rows for 1 image" \
    "$program" montage "$sweep/light-00.png" -o "$scratch/bad.png" --label-table "$sweep/light-positions.tsv"

# The images actually change with the light: frames 0 and 2 put it on opposite sides.
expect_exit "frames 0 and 2 differ (light on opposite sides)" 1 "" \
    "$program" diff "$sweep/light-00.png" "$sweep/light-02.png" --fail 0.01

# -D reaches the scene: two light positions give two images, one position twice the same.
small="--size 32x18 --spp 4 --quiet"
"$program" render scenes/three-balls.txt -o "$scratch/left.png" $small -D 'light_x=-4' &&
"$program" render scenes/three-balls.txt -o "$scratch/right-a.png" $small -D 'light_x=4*cos(pi/6)' &&
"$program" render scenes/three-balls.txt -o "$scratch/right-b.png" $small -D 'light_x=4*cos(pi/6)'
expect_exit "-D light_x=-4 and 4*cos(pi/6) differ" 1 "" "$program" diff "$scratch/left.png" "$scratch/right-a.png" --fail 0.01
expect_exit "the same -D twice gives the same image" 0 "" \
    "$program" diff "$scratch/right-a.png" "$scratch/right-b.png" --fail 0 --failpercent 0 --quiet

# Montage errors: exit 2, and the inputs stay as they were.
"$program" montage "$sweep/light-00.png" "$sweep/light-01.png" --columns 2 --gap 0 -o "$scratch/wide.png" --quiet
expect_exit "montage --columns 2 --gap 0" 0 "" test "$(image_size "$scratch/wide.png")" = 64x18
expect_exit "montage of different sizes" 2 "wide.png' is 64x18 but .*light-00.png' is 32x18" \
    "$program" montage "$sweep/light-00.png" "$scratch/wide.png" -o "$scratch/bad.png"
expect_exit "montage of a missing image" 2 "no-such-frame.png" \
    "$program" montage "$sweep/light-00.png" "$scratch/no-such-frame.png" -o "$scratch/bad.png"
cp "$sweep/light-01.png" "$scratch/kept.png"
expect_exit "montage -o naming an input" 2 "refusing to overwrite" \
    "$program" montage "$sweep/light-00.png" "$sweep/light-01.png" -o "$sweep/light-01.png"
expect_exit "montage -o naming an input by another path" 2 "refusing to overwrite" \
    "$program" montage "$sweep/light-00.png" "$sweep/light-01.png" -o "$sweep/../sweep/light-01.png"
if cmp -s "$scratch/kept.png" "$sweep/light-01.png"; then pass "montage leaves its inputs untouched"
else fail "montage leaves its inputs untouched" "light-01.png changed"; fi
if [ ! -e "$scratch/bad.png" ]; then pass "failed montages write nothing"
else fail "failed montages write nothing" "bad.png exists"; fi
expect_exit "montage without -o" 2 "no output" "$program" montage "$sweep/light-00.png"
expect_exit "montage without images" 2 "no images" "$program" montage -o "$scratch/bad.png"
expect_exit "montage --columns 0" 2 "--columns wants" \
    "$program" montage "$sweep/light-00.png" --columns 0 -o "$scratch/bad.png"
expect_exit "montage --gap -1" 2 "--gap wants" "$program" montage "$sweep/light-00.png" --gap -1 -o "$scratch/bad.png"
expect_exit "montage of an unknown format" 2 "cannot tell the format" \
    "$program" montage "$sweep/light-00.png" -o "$scratch/bad.bmpx"
expect_exit "montage --help" 0 "" "$program" montage --help
expect_exit "sweep-light.sh with 0 frames" 2 "FRAMES" \
    env RTSPHERES="$program" sh scenes/sweep-light.sh "$scratch/none" 0
finish
