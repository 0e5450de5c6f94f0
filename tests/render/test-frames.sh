#!/bin/sh
# test-frames.sh: `rtspheres render --frames`: the files a frame list writes, each frame
# equal to the single render with its $frame / $time set by -D, the frames-per-second
# report, reuse of an unchanged scene on the device, bad lists, and output name patterns
# without --frames (formatted with -D frame=N, else 0).
#   usage: sh tests/render/test-frames.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

scene=scenes/three-balls.txt
tiny="--size 16x9 --spp 2 --max-depth 4"

# usage_error NAME PATTERN ARGS...: `render ARGS` exits 2, says PATTERN (grep -E) on stderr
# and writes nothing into $scratch/refused.
usage_error() {
    usage_name=$1 usage_pattern=$2
    shift 2
    expect_refusal "$usage_name" "$usage_pattern" "$scratch/refused" "$program" render "$@"
}

# A scene that uses $frame (not $time): the sphere moves with it.
cat >"$scratch/frame-scene.txt" <<'SCENE'
set frame 0
render size 16 9 spp 2 depth 4 seed 1
camera from 0 0.5 4 at 0 0 0 up 0 1 0 fov 40
sky gradient 0.1 0.1 0.1  0.6 0.7 0.9
material grey lambertian 0.5 0.5 0.5
material red lambertian 0.8 0.2 0.1
sphere 0 -1000 0 999 grey
sphere (0.2 * $frame - 1) 0 0 0.6 red
SCENE
# A scene whose geometry never changes: only the camera orbits with $frame.
cat >"$scratch/orbit-scene.txt" <<'SCENE'
set frame 0
render size 16 9 spp 2 depth 4 seed 1
camera from (4 * sin(0.3 * $frame)) 0.5 (4 * cos(0.3 * $frame)) at 0 0 0 up 0 1 0 fov 40
sky gradient 0.1 0.1 0.1  0.6 0.7 0.9
material grey lambertian 0.5 0.5 0.5
material red lambertian 0.8 0.2 0.1
sphere 0 -1000 0 999 grey
sphere -0.8 0 0 0.6 red
sphere 0.8 0 0 0.6 grey
SCENE

# (a) --frames 0-2 writes exactly f-000 .. f-002 and reports frames per second.
dir=$scratch/frames-0-2
mkdir -p "$dir"
if "$program" render $scene -o "$dir/f-%03d.exr" $tiny --frames 0-2 2>"$scratch/frames.err"; then
    files_are "--frames 0-2 writes exactly f-000..f-002" "$dir" "f-000.exr f-001.exr f-002.exr"
else
    fail "--frames 0-2" "render failed: $(head -c 300 "$scratch/frames.err")"
fi
if grep -qE '^rtspheres: 3 frames in [0-9.]+ s \([0-9.e+]+ frames/s\)$' "$scratch/frames.err"; then
    pass "--frames reports frames per second on stderr ($(grep 'frames/s' "$scratch/frames.err"))"
else fail "--frames frames per second" "no 'rtspheres: 3 frames in ... (... frames/s)' line: $(tail -c 300 "$scratch/frames.err")"; fi
# Each frame has its number in the metadata and its own summary line, in order.
summaries=$(sed -n 's/^rtspheres: .* -> .*\/\(f-[0-9]*\.exr\): .*/\1/p' "$scratch/frames.err" | tr '\n' ' ')
if [ "$summaries" = "f-000.exr f-001.exr f-002.exr " ]; then pass "--frames: one summary line per frame, in order"
else fail "--frames summary lines" "files named: '$summaries'"; fi
for n in 0 2; do
    got=$(metadata "$dir/f-00$n.exr" frame)
    if [ "$got" = "$n" ]; then pass "f-00$n.exr has rtspheres:frame $n"
    else fail "f-00$n.exr metadata" "rtspheres:frame '$got', expected $n"; fi
done

# (b) Frame N is the single render with $time = N/24 (the default --fps): three-balls
# uses $time only; -D frame=N would be an error there ("never sets or uses $frame").
for n in 0 1 2; do
    "$program" render $scene -o "$scratch/single-$n.exr" $tiny -D "time=$n/24" --quiet
    same "frame $n equals the single render with -D time=$n/24" "$dir/f-00$n.exr" "$scratch/single-$n.exr"
done
# ... and the frames are really different images (the camera orbits, the balls bounce).
if "$program" diff "$dir/f-000.exr" "$dir/f-002.exr" --fail 0 --failpercent 0 >/dev/null 2>&1; then
    fail "frames 0 and 2 differ" "they are identical: \$time does not reach the scene"
else pass "frames 0 and 2 differ"; fi
# --fps sets $time = frame / fps.
"$program" render $scene -o "$scratch/fps-%d.exr" $tiny --frames 6 --fps 12 --quiet
"$program" render $scene -o "$scratch/fps-single.exr" $tiny -D time=0.5 --quiet
same "--fps 12: frame 6 equals the single render with -D time=0.5" "$scratch/fps-6.exr" "$scratch/fps-single.exr"
# A scene that uses $frame: frame 3 equals -D frame=3.
"$program" render "$scratch/frame-scene.txt" -o "$scratch/fs-%d.exr" --frames 3 --quiet
"$program" render "$scratch/frame-scene.txt" -o "$scratch/fs-single.exr" -D frame=3 --quiet
same "\$frame: frame 3 equals the single render with -D frame=3" "$scratch/fs-3.exr" "$scratch/fs-single.exr"

# (c) A list renders exactly its frames, in the order given.
dir=$scratch/frames-list
mkdir -p "$dir"
expected=""
for n in 1 2 3 4 5 6 7 8 9 10 15 20 25 30; do expected="$expected f-$(printf %03d $n).png"; done
expected=${expected# }
if "$program" render $scene -o "$dir/f-%03d.png" --size 16x9 --spp 1 --max-depth 2 --frames 1-10,15,20-30:5 \
        2>"$scratch/list.err"; then
    files_are "--frames 1-10,15,20-30:5 writes exactly those 14 frames" "$dir" "$expected"
    order=$(sed -n 's/^rtspheres: .* -> .*\/\(f-[0-9]*\.png\): .*/\1/p' "$scratch/list.err" | tr '\n' ' ' | sed 's/ $//')
    if [ "$order" = "$expected" ]; then pass "the frames render in list order"
    else fail "frame order" "rendered '$order'"; fi
    if grep -qE '^rtspheres: 14 frames in .*frames/s\)$' "$scratch/list.err"; then pass "the report counts 14 frames"
    else fail "14-frame report" "$(tail -c 300 "$scratch/list.err")"; fi
else
    fail "--frames 1-10,15,20-30:5" "render failed: $(head -c 300 "$scratch/list.err")"
fi

# (d) --quiet: nothing on stderr, no frames-per-second line.
"$program" render $scene -o "$scratch/quiet-%d.exr" $tiny --frames 0-1 --quiet 2>"$scratch/quiet.err"
if [ -f "$scratch/quiet-1.exr" ] && [ ! -s "$scratch/quiet.err" ]; then pass "--frames --quiet prints nothing"
else fail "--frames --quiet" "stderr: $(head -c 300 "$scratch/quiet.err")"; fi

# (e) Reuse: an unchanged packed scene stays on the device (--verbose says "already on
# the device" for every frame after the first); the moving balls of three-balls are a new
# scene every frame. The orbit scene changes only the camera: the frames must still be
# the single renders of their $frame.
"$program" render "$scratch/orbit-scene.txt" -o "$scratch/orbit-%d.exr" --frames 0-2 -v 2>"$scratch/orbit.err"
reused=$(grep '^rtspheres: scene:' "$scratch/orbit.err" | sed 's/.*already on the device.*/yes/; t; s/.*/no/' | tr '\n' ' ')
if [ "$reused" = "no yes yes " ]; then pass "an unchanged scene is uploaded once: frames 1 and 2 say 'already on the device'"
else fail "scene reuse" "reuse per frame: '$reused'; $(grep '^rtspheres: scene:' "$scratch/orbit.err" | head -c 300)"; fi
"$program" render "$scratch/orbit-scene.txt" -o "$scratch/orbit-single.exr" -D frame=2 --quiet
same "a reused scene with a moved camera: frame 2 equals -D frame=2" "$scratch/orbit-2.exr" "$scratch/orbit-single.exr"
if "$program" diff "$scratch/orbit-0.exr" "$scratch/orbit-2.exr" --fail 0 --failpercent 0 >/dev/null 2>&1; then
    fail "orbit frames differ" "frames 0 and 2 are identical: the camera did not move"
else pass "orbit frames 0 and 2 differ (the camera moved)"; fi
"$program" render $scene -o "$scratch/moving-%d.exr" $tiny --frames 0-2 -v 2>"$scratch/moving.err"
count=$(grep -c '^rtspheres: scene:' "$scratch/moving.err")
if [ "$count" = 3 ] && ! grep -q "already on the device" "$scratch/moving.err"; then
    pass "a scene that changes every frame is never reported as reused"
else fail "no reuse of a changed scene" "$count scene lines; $(grep 'already' "$scratch/moving.err" | head -c 300)"; fi

# (f) Bad lists and conflicting options are usage errors: exit 2, a message, no file.
out=$scratch/refused/f-%d.exr
usage_error "--frames 5-2 refused" "frames: '5-2' runs backwards" $scene -o "$out" $tiny --frames 5-2
usage_error "--frames 1,1 refused" "frame 1 is listed twice" $scene -o "$out" $tiny --frames 1,1
usage_error "--frames 1-3,2 refused" "frame 2 is listed twice" $scene -o "$out" $tiny --frames 1-3,2
usage_error "--frames '' refused" "empty" $scene -o "$out" $tiny --frames ""
usage_error "--frames a refused" "expected a frame number" $scene -o "$out" $tiny --frames a
usage_error "--frames -3 refused" "expected a frame number" $scene -o "$out" $tiny --frames -3
usage_error "--frames 1-5:0 refused" "step of 1 or more" $scene -o "$out" $tiny --frames 1-5:0
usage_error "--frames 1- refused" "last frame" $scene -o "$out" $tiny --frames 1-
usage_error "--frames 1;2 refused" "unexpected ';'" $scene -o "$out" $tiny --frames "1;2"
usage_error "--frames 1-999999999 refused" "goes past frame 99999999" $scene -o "$out" $tiny --frames 1-999999999
usage_error "several frames to one name refused" "2 frames would all write" $scene -o "$scratch/refused/one.exr" $tiny --frames 0-1
usage_error "two conversions in the pattern refused" "exactly one %d" $scene -o "$scratch/refused/f-%d-%d.exr" $tiny --frames 0-1
usage_error "-D time with --frames refused" "-D time and --frames both set" $scene -o "$out" $tiny --frames 0-1 -D time=1
usage_error "-D frame with --frames refused" "-D frame and --frames both set" "$scratch/frame-scene.txt" -o "$out" --frames 0-1 -D frame=1

# (g) Output name patterns without --frames: formatted with -D frame=N, else with 0;
# %% is a percent sign. One rule for every output name.
dir=$scratch/names
mkdir -p "$dir"
"$program" render $scene -o "$dir/c-%d.exr" $tiny --quiet
files_are "without --frames, -o c-%d.exr writes c-0.exr" "$dir" "c-0.exr"
rm -f "$dir"/*
"$program" render "$scratch/frame-scene.txt" -o "$dir/d-%03d.exr" -D frame=3 --quiet
files_are "without --frames, -D frame=3 -o d-%03d.exr writes d-003.exr" "$dir" "d-003.exr"
if [ -f "$dir/d-003.exr" ]; then
    same "the -D frame=3 render named d-003.exr is frame 3" "$dir/d-003.exr" "$scratch/fs-3.exr"
fi
rm -f "$dir"/*
"$program" render "$scratch/frame-scene.txt" -o "$dir/e-%d.exr" -D "frame=2*2" --quiet
files_are "-D frame=2*2 (an expression) names e-4.exr" "$dir" "e-4.exr"
rm -f "$dir"/*
"$program" render $scene -o "$dir/p-100%%.exr" $tiny --quiet
files_are "without --frames, %% is a percent sign" "$dir" "p-100%.exr"
usage_error "-D frame=2.5 with a pattern refused" "-D frame=2.5 is 2.5, not a frame number" \
    "$scratch/frame-scene.txt" -o "$scratch/refused/f-%d.exr" -D frame=2.5
usage_error "a %s in the output refused without --frames" "exactly one %d" $scene -o "$scratch/refused/f-%s.exr" $tiny
# A name without a conversion ignores $frame, whatever its value.
rm -f "$dir"/*
"$program" render "$scratch/frame-scene.txt" -o "$dir/plain.exr" -D frame=2.5 --quiet
files_are "a name without a pattern is kept as it is, whatever -D frame is" "$dir" "plain.exr"

finish
