#!/bin/sh
# sweep-light.sh: renders scenes/three-balls.txt with its light orbiting the balls, one
# frame per light position, and lays the frames out as a contact sheet.
#
#   usage: scenes/sweep-light.sh [OUTDIR] [FRAMES]     (defaults: sweep-out, 12)
#
# Frame i (0 .. FRAMES-1) puts the light on a circle of radius 4 around the balls, at the
# scene's own height (light_y):
#   -D light_x="4*cos(2*pi*i/FRAMES)" -D light_z="4*sin(2*pi*i/FRAMES)"
# (rtspheres evaluates -D values as expressions and knows pi), and is written to
# OUTDIR/light-00.png, light-01.png, ...; then OUTDIR/contact-sheet.png shows them all,
# row by row. Run it from the top of the repository.
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

# One render per frame rather than --frames: each frame's light position is spelled out
# as -D expressions, which is the part a script usually wants to change.
i=0
set --
while [ "$i" -lt "$frames" ]; do
    frame=$(printf '%s/light-%02d.png' "$outdir" "$i")
    "$program" render "$scene" -o "$frame" --size "$size" --spp "$spp" --quiet \
        -D "light_x=4*cos(2*pi*$i/$frames)" -D "light_z=4*sin(2*pi*$i/$frames)"
    set -- "$@" "$frame"
    i=$((i + 1))
done

"$program" montage "$@" -o "$outdir/contact-sheet.png" --quiet
echo "sweep-light.sh: $frames frames and $outdir/contact-sheet.png"
