#!/bin/sh
# test-display.sh: render --display HOST:PORT against a fake tev viewer on the loopback
# interface (tests/render/tools/fake_tev.py, which decodes tev's packets: their lengths,
# types, image and channel names, tiles and float values): the image is created once with
# the output's name, size and channels R, G, B, and the last values it received are the
# written image's pixels; a port where nothing listens, and a viewer that hangs up after
# its first packets, are one warning each and the render goes on; a malformed address is
# exit 2; a sweep shows each row as its own image. Needs python3 (else SKIP). About 12 s
# on an idle machine.
#   usage: sh tests/render/test-display.sh PROGRAM SCRATCH_DIR
here=$(dirname "$0")
. "$here/lib.sh"
if ! command -v python3 >/dev/null 2>&1; then
    echo "SKIP display: no python3 for the fake tev viewer"
    exit 0
fi
scene=scenes/three-balls.txt
small="--size 40x20 --spp 8 --quiet"

# start_viewer [OPTIONS]: the fake viewer in the background ($viewer its pid), its port
# in $port once it listens, what it saw in $scratch/tev.out when the client is gone.
start_viewer() {
    rm -f "$scratch/port" "$scratch/tev.out"
    python3 "$here/tools/fake_tev.py" "$scratch/port" "$scratch/tev.out" "$@" &
    viewer=$!
    tries=0
    while [ ! -s "$scratch/port" ] && [ "$tries" -lt 100 ]; do sleep 0.1; tries=$((tries + 1)); done
    port=$(cat "$scratch/port" 2>/dev/null)
}

start_viewer
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/shown.exr" $small --display "127.0.0.1:$port" 2>"$scratch/stderr"
code=$?
wait "$viewer"
if [ "$code" = 0 ] && [ ! -s "$scratch/stderr" ]; then pass "a render with a viewer: exit 0, no warning"
else fail "a render with a viewer: exit 0, no warning" "exit $code: $(head -c 300 "$scratch/stderr")"; fi
created=$(grep '^create ' "$scratch/tev.out")
if [ "$created" = "create $scratch/shown.exr 40 20 R G B" ]; then pass "CreateImage once: the output's name, size, R G B"
else fail "CreateImage once: the output's name, size, R G B" "'$created'"; fi
if grep -q '^error' "$scratch/tev.out"; then fail "every packet decodes" "$(grep '^error' "$scratch/tev.out")"
else pass "every packet decodes (lengths, types, fields)"; fi
updates=$(sed -n 's/^updates //p' "$scratch/tev.out")
if [ "${updates:-0}" -ge 3 ] && [ $((updates % 3)) = 0 ]; then pass "UpdateImage per channel ($updates packets)"
else fail "UpdateImage per channel" "$updates packets"; fi
# The last values the viewer holds are the written image: per channel means, and pixels.
stats_of "$scratch/shown.exr"
for c in R G B; do
    shown=$(awk -v c="$c" '$1 == "pixel" && $3 == c { s += $6; n++ } END { if (n == 800) printf "%.9g", s / n }' \
        "$scratch/tev.out")
    if within "$shown" "$(stat_mean "$c")" 1e-6; then pass "channel $c's mean in the viewer is the image's"
    else fail "channel $c's mean in the viewer is the image's" "viewer '$shown', image $(stat_mean "$c")"; fi
done
for xy in "0 0" "17 9" "39 19"; do
    x=${xy% *} y=${xy#* }
    viewer_value=$(awk -v x="$x" -v y="$y" '$1 == "pixel" && $3 == "G" && $4 == x && $5 == y { print $6 }' \
        "$scratch/tev.out")
    image_value=$(channel_mean "$scratch/shown.exr" G "$x,$y,$((x + 1)),$((y + 1))")
    if within "$viewer_value" "$image_value" 1e-6; then pass "pixel ($x, $y) in the viewer is the image's"
    else fail "pixel ($x, $y) in the viewer is the image's" "viewer '$viewer_value', image '$image_value'"; fi
done

# A sweep shows each row's image as it renders: one CreateImage per row, named by its
# output, and the viewer's last values of each are that row's written image.
printf 'light_x\n1\n-1\n' >"$scratch/rows.tsv"
start_viewer
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/row-%d.exr" $small --sweep "$scratch/rows.tsv" --display "127.0.0.1:$port" \
    2>"$scratch/stderr"
code=$?
wait "$viewer"
created=$(grep '^create ' "$scratch/tev.out" | tr '\n' ';')
if [ "$code" = 0 ] && [ "$created" = "create $scratch/row-0.exr 40 20 R G B;create $scratch/row-1.exr 40 20 R G B;" ]
then pass "a sweep creates one image per row in the viewer, named by its output"
else fail "a sweep creates one image per row in the viewer, named by its output" "exit $code, '$created'"; fi
for row in 0 1; do
    shown=$(awk -v name="$scratch/row-$row.exr" '$1 == "pixel" && $2 == name && $3 == "R" { s += $6; n++ }
        END { if (n == 800) printf "%.9g", s / n }' "$scratch/tev.out")
    if within "$shown" "$(channel_mean "$scratch/row-$row.exr" R)" 1e-6; then pass "row $row's image in the viewer is the written one"
    else fail "row $row's image in the viewer is the written one" "viewer R mean '$shown'"; fi
done

# Nothing listening: a port just closed. One warning, the image written, exit 0.
closed=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1]); s.close()')
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/alone.exr" $small --display "127.0.0.1:$closed" 2>"$scratch/stderr"
code=$?
warnings=$(grep -c 'warning' "$scratch/stderr")
if [ "$code" = 0 ] && [ "$warnings" = 1 ] && [ -f "$scratch/alone.exr" ] &&
   grep -q "is not there (connection refused); the render goes on without it" "$scratch/stderr"; then
    pass "--display to a closed port renders with one warning"
else fail "--display to a closed port renders with one warning" "exit $code, $warnings warnings: $(head -c 300 "$scratch/stderr")"; fi
same "the image without a viewer is the image with one" "$scratch/alone.exr" "$scratch/shown.exr"

# A viewer that goes away after two packets, during a sweep of two rows: one warning.
printf 'light_x\n1\n-1\n' >"$scratch/rows.tsv"
start_viewer --close-after 2
# shellcheck disable=SC2086
"$program" render "$scene" -o "$scratch/gone-%d.exr" $small --sweep "$scratch/rows.tsv" \
    --display "localhost:$port" 2>"$scratch/stderr"
code=$?
wait "$viewer"
warnings=$(grep -c 'warning' "$scratch/stderr")
if [ "$code" = 0 ] && [ "$warnings" = 1 ] && [ -f "$scratch/gone-0.exr" ] && [ -f "$scratch/gone-1.exr" ]; then
    pass "a viewer that goes away is one warning, and every row is rendered"
else fail "a viewer that goes away is one warning" "exit $code, $warnings warnings: $(head -c 300 "$scratch/stderr")"; fi

mkdir -p "$scratch/out"
expect_refusal "--display without a port" "is not HOST:PORT" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/x.exr" --display localhost
expect_refusal "--display with port 0" "is not HOST:PORT" "$scratch/out" \
    "$program" render "$scene" -o "$scratch/out/x.exr" --display localhost:0
finish
