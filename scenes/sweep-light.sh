#!/bin/sh
# sweep-light.sh: renders scenes/three-balls.txt with its light orbiting the balls, one
# frame per light position, and lays the frames out as a contact sheet.
#
#   usage: scenes/sweep-light.sh [OUTDIR] [FRAMES]     (defaults: sweep-out, 12)
#
# Frame i (0 .. FRAMES-1) puts the light on a circle of radius 4 around the balls, at the
# scene's own height (light_y): row i of the sweep table OUTDIR/light-positions.tsv is
#   light_x = 4*cos(2*pi*i/FRAMES)    light_z = 4*sin(2*pi*i/FRAMES)
# (rtspheres evaluates the values as expressions, as -D does, and knows pi), written to
# OUTDIR/light-00.png, light-01.png, ...; then OUTDIR/contact-sheet.png shows them all,
# row by row, each with its light_x and light_z written under it. Run it from the top of
# the repository.
#
# Environment:
#   RTSPHERES        the program (default ./rtspheres)
#   RTSPHERES_SIZE   frame size WxH (default 320x180)
#   RTSPHERES_SPP    samples per pixel (default 32)
# For example, a quick look:  RTSPHERES_SIZE=160x90 RTSPHERES_SPP=8 scenes/sweep-light.sh /tmp/sweep 8
set -eu

outdir=${1:-sweep-out}
frames=${2:-12}
program=${RTSPHERES:-./rtspheres}
size=${RTSPHERES_SIZE:-320x180}
spp=${RTSPHERES_SPP:-32}
scene=$(dirname "$0")/three-balls.txt

case $frames in
    '' | *[!0-9]* | 0) echo "sweep-light.sh: FRAMES must be a whole number of at least 1, not '$frames'" >&2; exit 2 ;;
esac
mkdir -p "$outdir"

# One sweep table, one render: a row per frame with the light's position as expressions
# (the part a script usually wants to change), rendered in one process on one GPU context
# with the tracer compiled once; %02d in the output is the row number.
table=$outdir/light-positions.tsv
i=0
printf 'light_x\tlight_z\n' >"$table"
set --
while [ "$i" -lt "$frames" ]; do
    printf '4*cos(2*pi*%d/%d)\t4*sin(2*pi*%d/%d)\n' "$i" "$frames" "$i" "$frames" >>"$table"
    set -- "$@" "$(printf '%s/light-%02d.png' "$outdir" "$i")"
    i=$((i + 1))
done
"$program" render "$scene" -o "$outdir/light-%02d.png" --sweep "$table" --size "$size" --spp "$spp" --quiet

# Each frame labelled with its row's values (the built-in 5x7 font of core/bitmap_font.h).
"$program" montage "$@" -o "$outdir/contact-sheet.png" --label-table "$table" --quiet
echo "sweep-light.sh: $frames frames and $outdir/contact-sheet.png"
