#!/bin/sh
# test-tiles.sh: images larger than the device or the memory budget render in tiles
# (render_job.h "Tiles", README "Large images") through the command: an image wider than
# the device (17000x4, 1 spp) renders; 8-bit outputs, tone mapping and the samples map
# under a forced small --memory-budget are the untiled files byte for byte; --tile parts
# that are tiled inside merge into exactly the untiled image; frames and sweep rows tile
# each image, and a montage of them is the untiled montage; a time limit is shared out
# over the tiles; what tiles cannot do, and a budget too small for one tile, are refused
# (exit 2, nothing written); an interrupted tiled render leaves the output as it was; device and
# host failures (forced by RTSPHERES_TEST_* hooks) name the size and --memory-budget; the
# --size and --memory-budget limits. Every channel bit for bit (AOVs, variance, light
# groups, adaptive sampling) is tests/unit/test_render_tiles.c.
#   usage: sh tests/render/test-tiles.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
scene=scenes/materials/metal.txt
render_options="--size 48x27 --spp 4"
# About 500 KiB untiled: 3 to 8 tiles.
budget=--memory-budget=150K

# tiled NAME: one check that the last command's stderr says it rendered in tiles.
tiled() {
    if grep -qE 'rendering in [0-9]+ x [0-9]+ tiles' "$scratch/stderr"; then pass "$1"
    else fail "$1" "no tiles reported: $(head -c 300 "$scratch/stderr")"; fi
}

# (a) Wider than the device: 17000 pixels is more than llvmpipe's 16384 (the hook makes
# any larger device as small), one sample per pixel.
RTSPHERES_TEST_MAX_TEXTURE_SIZE=16384 "$program" render scenes/three-balls.txt -o "$scratch/wide.exr" \
    --size 17000x4 --spp 1 2>"$scratch/stderr"
tiled "17000x4 is rendered in tiles"
if stats_of "$scratch/wide.exr" && grep -q '^size: 17000x4$' "$scratch/stats" \
    && [ "$(stat_range samples)" = "1 1" ] && [ "$(stat_metadata complete)" = 1 ]; then
    pass "a 17000x4 image renders, every pixel with its sample"
else
    fail "17000x4" "$(head -c 300 "$scratch/stats")"
fi

# (b) 8-bit files, tone mapping, the samples map: the untiled files byte for byte.
mkdir -p "$scratch/out"
render "$scratch/untiled.png" --tonemap aces --samples-map "$scratch/untiled-map.png"
render "$scratch/out/tiled.png" --tonemap aces --samples-map "$scratch/out/tiled-map.png" "$budget" 2>"$scratch/stderr"
render "$scratch/untiled.jpg" --noise-threshold 0.2 --min-spp 4 --spp 16
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/out/tiled.jpg" $render_options --noise-threshold 0.2 --min-spp 4 --spp 16 \
    "$budget" 2>"$scratch/stderr"
tiled "a forced budget renders in tiles"
for file in tiled.png tiled-map.png tiled.jpg; do
    if cmp -s "$scratch/out/$file" "$scratch/un$file"; then pass "tiled $file is the untiled file byte for byte"
    else fail "tiled $file" "differs from the untiled one"; fi
done
files_are "a tiled render leaves no spool or temporary file" "$scratch/out" "tiled-map.png tiled.jpg tiled.png"

# (c) --tile parts, each tiled inside, merge into exactly the untiled render.
render "$scratch/full.exr"
render "$scratch/part0.exr" --tile 0/2 "$budget" 2>"$scratch/stderr"
render "$scratch/part1.exr" --tile 1/2 "$budget"
problem=$(merge_problem "$scratch/full.exr" 0 4 "$scratch/merged.exr" "$scratch/part0.exr" "$scratch/part1.exr")
if [ -n "$problem" ]; then fail "tiled --tile parts merge" "$problem"
else pass "--tile parts rendered in tiles merge into exactly the untiled render"; fi

# (d) Frames and sweeps: each image is tiled, and is the untiled one.
render "$scratch/frame-%d.exr" --frames 1-2
render "$scratch/tiled-frame-%d.exr" --frames 1-2 "$budget"
same "tiled frame 2 is the untiled frame" "$scratch/frame-2.exr" "$scratch/tiled-frame-2.exr"

# Sweeps tile each row's image too, and a contact sheet of tiled images is the sheet of
# the untiled ones (montage reads the files, which are the same).
printf 'light_x\tlight_z\n3\t0\n-1.5\t2.6\n' >"$scratch/lights.tsv"
"$program" render scenes/three-balls.txt -o "$scratch/row-%d.exr" --size 48x27 --spp 2 --quiet \
    --sweep "$scratch/lights.tsv"
"$program" render scenes/three-balls.txt -o "$scratch/tiled-row-%d.exr" --size 48x27 --spp 2 --sweep \
    "$scratch/lights.tsv" "$budget" 2>"$scratch/stderr"
tiled "sweep rows are rendered in tiles"
same "tiled sweep row 1 is the untiled row" "$scratch/row-1.exr" "$scratch/tiled-row-1.exr"
"$program" montage "$scratch/frame-1.exr" "$scratch/frame-2.exr" -o "$scratch/sheet.png" --quiet
"$program" montage "$scratch/tiled-frame-1.exr" "$scratch/tiled-frame-2.exr" -o "$scratch/tiled-sheet.png" --quiet
if cmp -s "$scratch/sheet.png" "$scratch/tiled-sheet.png"; then pass "a montage of tiled frames is the untiled one"
else fail "montage of tiled frames" "differs from the montage of the untiled frames"; fi

# (e) A time limit far too short for 4096 spp: every tile still gets its first pass (a
# fixed pass budget of 4000 work units finishes a few samples in every pixel of it, so
# no pixel, in whatever tile, is left without samples), and the image says the time
# ended it.
if render "$scratch/timed.exr" --spp 4096 --time-limit 0.05 --pass-budget 4000 "$budget" \
    && stats_of "$scratch/timed.exr" && [ "$(stat_metadata stop_reason)" = time ] \
    && [ "$(stat_metadata complete)" = 0 ] \
    && awk -v r="$(stat_range samples)" 'BEGIN { split(r, v, " "); exit !(v[1] >= 1 && v[2] < 4096) }'; then
    pass "a time limit is shared out over the tiles: every tile gets samples, the image is marked time"
else
    fail "time limit under tiles" "stop_reason '$(stat_metadata stop_reason)', samples '$(stat_range samples)'"
fi

# (f) What tiles cannot do: refused, naming the tiling and what to do.
printf 'partial' >"$scratch/some.partial.exr"
# --display: refused before it connects (nothing listens on port 1 anyway).
for options in "--checkpoint 10" "--resume $scratch/some.partial.exr" "--display 127.0.0.1:1"; do
    word=${options%% *}
    # shellcheck disable=SC2086
    expect_refusal "$word under tiles is refused" "^rtspheres render: $word .*rendered in [0-9]+ tiles .*: " \
        "$scratch/refused" "$program" render "$scene" -o "$scratch/refused/out.exr" $render_options "$budget" \
        $options
done
# Adaptive sampling's margins (25 pixels at --min-spp 2 and 1024 spp) round even a
# one-pixel tile: a budget too small for that says how much one needs.
# shellcheck disable=SC2086
expect_refusal "a budget too small for one tile" \
    "--memory-budget 64 KiB is too small for even a one-pixel tile of this render \([0-9.]+ [KM]iB\)" \
    "$scratch/refused" "$program" render "$scene" -o "$scratch/refused/out.exr" $render_options --spp 1024 \
    --noise-threshold 0.1 --min-spp 2 --memory-budget 64K
expect_refusal "--size above 65536 names the limit" "--size wants WIDTHxHEIGHT, each 1 to 65536" "$scratch/refused" \
    "$program" render "$scene" -o "$scratch/refused/out.exr" --size 65537x4
expect_refusal "--memory-budget below 64K" "--memory-budget wants a size of at least 64K" "$scratch/refused" \
    "$program" render "$scene" -o "$scratch/refused/out.exr" --memory-budget 10K
expect_refusal "--memory-budget without a size" "--memory-budget wants" "$scratch/refused" \
    "$program" render "$scene" -o "$scratch/refused/out.exr" --memory-budget 2Q

# (g) Device and host failures: the size that failed, what to try, the budget in force;
# never a raw framebuffer status. The tiled one names the tile's size.
for failure in memory framebuffer; do
    # shellcheck disable=SC2086
    RTSPHERES_TEST_GPU_FAILURE=$failure expect_exit "GPU $failure failure is a message to act on" 1 \
        "GPU: out of memory for the state of a 48x27 image \([0-9.]+ MiB .*give a smaller --memory-budget.*this render's budget: .*the default\)$" \
        "$program" render "$scene" -o "$scratch/failed.exr" $render_options
done
# shellcheck disable=SC2086
RTSPHERES_TEST_GPU_FAILURE=framebuffer expect_exit "a tile's failure names the tile and the budget" 1 \
    "state of a [0-9]+x[0-9]+ image .*this render's budget: 150 KiB\)$" \
    "$program" render "$scene" -o "$scratch/failed.exr" $render_options "$budget"
if grep -q 'framebuffer is incomplete' "$scratch/stderr"; then fail "no raw framebuffer status" "$(cat "$scratch/stderr")"
else pass "no raw framebuffer status"; fi
# shellcheck disable=SC2086
RTSPHERES_TEST_HOST_FAILURE=memory expect_exit "host memory failure is a message to act on" 1 \
    "out of memory reading back a 48x27 image .*--memory-budget" \
    "$program" render "$scene" -o "$scratch/failed.exr" $render_options

# (h) Ctrl-C in a tiled render: exit 1 saying so, the previous output as it was, no
# partial and no spool. Signalled once it says it renders in tiles (the handlers are
# set by then).
mkdir -p "$scratch/stop"
printf 'previous image' >"$scratch/stop/out.exr"
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/stop/out.exr" --size 48x27 --spp 100000 "$budget" 2>"$scratch/stop.err" &
pid=$!
tries=0
while ! grep -q 'rendering in' "$scratch/stop.err" 2>/dev/null && [ "$tries" -lt 600 ]; do
    tries=$((tries + 1))
    sleep 0.1
done
sleep 1
kill -s INT "$pid" 2>/dev/null
wait "$pid"
code=$?
if [ "$code" = 1 ] && grep -q 'interrupted in tile [0-9]* of [0-9]*; a tiled render keeps no partial file' \
    "$scratch/stop.err" && [ "$(cat "$scratch/stop/out.exr")" = "previous image" ]; then
    pass "an interrupted tiled render keeps the previous output and says why there is no partial"
else
    fail "interrupted tiled render" "exit $code: $(head -c 300 "$scratch/stop.err")"
fi
files_are "an interrupted tiled render leaves nothing behind" "$scratch/stop" "out.exr"
finish
