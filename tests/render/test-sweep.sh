#!/bin/sh
# test-sweep.sh: render --sweep TABLE end to end: a 3-row table writes, bit for bit, the
# images of three separate renders with those -D values, in one process whose tracer
# program is compiled once (--verbose says how often); {NAME} and %d name the outputs;
# --shard splits the rows; bad tables (an unknown variable, a missing value, two rows to
# one file, a column also given by -D) are exit 2 with the table's file:line before
# anything is rendered or written; rows that change no shape reuse the BVH and upload
# only what changed (--verbose says per row). About 20 s on an idle machine.
#   usage: sh tests/render/test-sweep.sh PROGRAM SCRATCH_DIR
here=$(dirname "$0")
. "$here/lib.sh"
scene=scenes/three-balls.txt
render_options="--size 48x27 --spp 8"

printf 'light_x\tlight_z\n# a comment, then a blank line\n\n3\t0\n-1.5\t2.6\n-1.5\t(-2.6)\n' >"$scratch/lights.tsv"
mkdir -p "$scratch/sweep"
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/sweep/row-%d-x{light_x}.exr" $render_options --sweep "$scratch/lights.tsv" \
    --verbose >"$scratch/stdout" 2>"$scratch/verbose"
files_are "a row per image, named by {NAME} and %d" "$scratch/sweep" \
    "row-0-x3.exr row-1-x-1.5.exr row-2-x-1.5.exr"
if grep -q "the tracer program was compiled 1 time for 3 images" "$scratch/verbose"; then
    pass "the tracer is compiled once for the sweep"
else
    fail "the tracer is compiled once for the sweep" "$(grep 'compiled' "$scratch/verbose" | head -c 300)"
fi
row=0
for values in "3 0" "-1.5 2.6" "-1.5 (-2.6)"; do
    x=${values% *} z=${values#* }
    render "$scratch/single-$row.exr" -D "light_x=$x" -D "light_z=$z"
    same "row $row equals its own render" "$scratch/sweep/row-$row-x$x.exr" "$scratch/single-$row.exr"
    row=$((row + 1))
done

# Shards split the rows as they split frames: 0/2 takes rows 0 and 2, 1/2 row 1.
mkdir -p "$scratch/shard0" "$scratch/shard1"
render "$scratch/shard0/r%d.exr" --sweep "$scratch/lights.tsv" --shard 0/2
render "$scratch/shard1/r%d.exr" --sweep "$scratch/lights.tsv" --shard 1/2
files_are "shard 0/2 renders rows 0 and 2" "$scratch/shard0" "r0.exr r2.exr"
files_are "shard 1/2 renders row 1" "$scratch/shard1" "r1.exr"
same "a shard's row equals the whole sweep's" "$scratch/shard1/r1.exr" "$scratch/sweep/row-1-x-1.5.exr"

# Reuse between rows (--verbose's "set-up of" line per image): a row that changes only a
# point light's colour and position takes the BVH from the row before and uploads only
# the changed 16 KiB blocks of the packed scene (the light section's), not the geometry; a
# row that moves a shape builds its BVH again. 400 small spheres make the packed scene
# several blocks long. Each image is still that of its own render.
# shellcheck disable=SC2016 # the $NAME are the scene's variables, not the shell's
{
    echo 'set lx -2'
    echo 'set red 1'
    echo 'set ball_y 0.3'
    echo 'render size 24 14 spp 2 depth 3 seed 3'
    echo 'camera from 0 3 9 at 0 0.5 0 up 0 1 0 fov 50'
    echo 'material clay lambertian 0.7 0.4 0.3'
    echo 'sphere 0 $ball_y 0 0.3 clay'
    for i in $(seq 0 19); do
        for j in $(seq 0 19); do echo "sphere $((i - 10)).5 0.1 $((j - 15)).5 0.1 clay"; done
    done
    echo 'light point $lx 2.5 1.5 color $red 0.85 0.7 intensity 6'
} >"$scratch/spheres.txt"
printf 'lx\tred\tball_y\n-2\t1\t0.3\n2\t0.5\t0.3\n2\t0.5\t0.8\n' >"$scratch/reuse.tsv"
mkdir -p "$scratch/reuse"
"$program" render "$scratch/spheres.txt" -o "$scratch/reuse/r%d.exr" --sweep "$scratch/reuse.tsv" --verbose \
    >"$scratch/stdout" 2>"$scratch/verbose"
# reuse_line ROW PATTERN NAME: one check: row ROW's set-up line matches PATTERN (grep -E).
reuse_line() {
    line=$(grep "set-up of $scratch/reuse/r$1.exr:" "$scratch/verbose")
    if echo "$line" | grep -Eq "$2"; then pass "$3"; else fail "$3" "'$line'"; fi
}
reuse_line 0 "BVH built \(0 of 1 trees reused\); upload whole \([0-9]+ bytes\); shader compiled" \
    "the first row builds, uploads and compiles everything"
reuse_line 1 "BVH reused \(1 of 1 trees reused\); upload partial \([0-9]+ of [0-9]+ bytes: the blocks that changed\); shader reused" \
    "a row changing only a light keeps the BVH, uploads part of the scene and keeps the shader"
# Of the packed scene (more than two blocks), at most the one block holding the light.
uploaded=$(sed -n "s|.*set-up of $scratch/reuse/r1.exr:.*upload partial (\([0-9]*\) of \([0-9]*\) bytes.*|\1 \2|p" "$scratch/verbose")
if [ -n "$uploaded" ] && awk -v u="${uploaded% *}" -v t="${uploaded#* }" 'BEGIN { exit !(u <= 16384 && t > 2 * 16384) }'
then pass "the light-only row uploads at most one 16 KiB block of a scene of more than two ($uploaded bytes)"
else fail "the light-only row uploads at most one 16 KiB block of a scene of more than two" "uploaded, total: '$uploaded'"; fi
reuse_line 2 "BVH built \(0 of 1 trees reused\); upload (partial|whole) .*; shader reused" \
    "a row moving a sphere builds the BVH again"
"$program" render "$scratch/spheres.txt" -o "$scratch/reuse-1.exr" --quiet -D lx=2 -D red=0.5
same "the row that reused the BVH and most of the upload equals its own render" "$scratch/reuse/r1.exr" \
    "$scratch/reuse-1.exr"
"$program" render "$scratch/spheres.txt" -o "$scratch/reuse-2.exr" --quiet -D lx=2 -D red=0.5 -D ball_y=0.8
same "the row after a partial upload that moved a sphere equals its own render" "$scratch/reuse/r2.exr" \
    "$scratch/reuse-2.exr"

# Bad tables: exit 2, the table's file:line, nothing written.
mkdir -p "$scratch/out"
printf 'light_x\tbrightness\n1\t2\n' >"$scratch/unknown.tsv"
expect_refusal "a column the scene does not use" "unknown.tsv:1: column 'brightness': the scene never sets or uses" \
    "$scratch/out" "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scratch/unknown.tsv"
printf 'light_x,light_z\n1,2\n-1\n' >"$scratch/short.csv"
expect_refusal "a missing value" "short.csv:3: 1 value, but the header \\(line 1\\) names 2 columns" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scratch/short.csv"
printf 'light_x,light_z\n1,2\n-1, \n' >"$scratch/empty.csv"
expect_refusal "an empty value" "empty.csv:3: no value for column 'light_z'" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scratch/empty.csv"
printf 'light_x\tlight_z\n1\t2\n1\t3\n' >"$scratch/same.tsv"
expect_refusal "two rows writing one file" "same.tsv:3: this row writes '.*r1.png', as the row of line 2 does" \
    "$scratch/out" "$program" render "$scene" -o "$scratch/out/r{light_x}.png" --sweep "$scratch/same.tsv"
expect_refusal "a column also given by -D" "lights.tsv:1: column 'light_x' and -D light_x both set" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scratch/lights.tsv" -D light_x=1
expect_refusal "an output pattern naming no column" "\\{light_y\\} is no column of" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r{light_y}.png" --sweep "$scratch/lights.tsv"
expect_refusal "--sweep with --frames" "--sweep and --frames both" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scratch/lights.tsv" --frames 1-3
printf 'light_x\n' >"$scratch/header.tsv"
expect_refusal "a header without rows" "header.tsv: a header but no row" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scratch/header.tsv"
expect_refusal "a table of another kind" "a sweep table is a .tsv" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/r%d.png" --sweep "$scene"
finish
