#!/bin/sh
# test-sky-controls.sh: a sky's intensity and rotation do what they say, on an
# environment map and a sky box seen directly (no geometry): intensity 2 doubles every
# pixel exactly; rotate 360 is rotate 0 (to float rounding); rotate 90 turns the sky
# (right-handed about +Y: what was at +X comes to -Z, in front of the camera), so a
# camera turned to look at +X in the unturned sky sees the same picture.
#   usage: sh tests/render/test-sky-controls.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

assets="$(pwd)/scenes/assets"
# sky_scene KIND: a camera looking along -Z (set look_x to turn it) at a sky of KIND.
sky_scene() {
    case $1 in
        environment) sky="sky environment \"$assets/earth.ppm\" intensity \$intensity rotate \$turn" ;;
        box) sky="sky box \"$assets/skybox/px.ppm\" \"$assets/skybox/nx.ppm\" \"$assets/skybox/py.ppm\" \"$assets/skybox/ny.ppm\" \"$assets/skybox/pz.ppm\" \"$assets/skybox/nz.ppm\" intensity \$intensity rotate \$turn" ;;
    esac
    printf '%s\n' "set intensity 1" "set turn 0" "set look_x 0" "set look_z -1" "render size 48 27 spp 4 depth 2 seed 1" \
        "camera from 0 0 0 at \$look_x 0.2 \$look_z up 0 1 0 fov 60" "$sky"
}
for kind in environment box; do
    sky_scene $kind >"$scratch/$kind.txt"
    render() {
        label=$1
        shift
        "$program" render "$scratch/$kind.txt" -o "$scratch/$kind-$label.exr" --quiet "$@" 2>>"$scratch/$kind.err"
    }
    if render base && render bright -D intensity=2 && render full-turn -D turn=360 && render quarter -D turn=90 &&
       render camera-turned -D look_x=1 -D look_z=0; then
        base=$(channel_mean "$scratch/$kind-base.exr" G)
        bright=$(channel_mean "$scratch/$kind-bright.exr" G)
        if within "$bright" "$(awk -v b="$base" 'BEGIN { printf "%.9g", 2 * b }')" 1e-6; then
            pass "$kind: intensity 2 doubles the sky ($base -> $bright)"
        else fail "$kind: intensity 2 doubles the sky" "$base -> $bright"; fi
        if "$program" diff "$scratch/$kind-full-turn.exr" "$scratch/$kind-base.exr" --fail 1e-4 --failpercent 0 \
                >/dev/null 2>&1; then
            pass "$kind: rotate 360 is rotate 0"
        else fail "$kind: rotate 360 is rotate 0" "the images differ"; fi
        if "$program" diff "$scratch/$kind-quarter.exr" "$scratch/$kind-base.exr" --failpercent 10 >/dev/null 2>&1; then
            fail "$kind: rotate 90 turns the sky" "the image hardly changed"
        else pass "$kind: rotate 90 turns the sky"; fi
        if "$program" diff "$scratch/$kind-quarter.exr" "$scratch/$kind-camera-turned.exr" --fail 0.02 \
                --failpercent 2 >"$scratch/$kind.diff" 2>&1; then
            pass "$kind: rotate 90 shows what a camera turned to +X sees"
        else fail "$kind: rotate 90 shows what a camera turned to +X sees" "$(tr '\n' ' ' <"$scratch/$kind.diff")"; fi
    else
        fail "$kind sky renders" "$(head -c 300 "$scratch/$kind.err")"
    fi
done
finish
