#!/bin/sh
# test-info.sh: `rtspheres info` names the renderer, an OpenGL 4.5 (or later) context and
# the EGL devices with the numbers --device takes, marking the one used; --device beyond
# the list is refused (exit 2) by info and render alike, naming the number asked for and
# how many devices there are.
#   usage: sh tests/render/test-info.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

# field NAME: the value of the "NAME: value" line of the last info output.
field() {
    sed -n "s/^$1: *//p" "$scratch/info.out" | head -n 1
}

name=info-runs
if ! "$program" info >"$scratch/info.out" 2>"$scratch/info.err"; then
    fail "$name" "exit $?: $(head -c 300 "$scratch/info.err")"
elif [ -z "$(field 'GL renderer')" ]; then
    fail "$name" "no renderer named: $(head -c 300 "$scratch/info.out")"
else
    pass "$name"
fi

# The context a render gets is desktop OpenGL 4.5 core (a driver may give a later one).
name=info-gl-4.5
version=$(field 'GL version')
major=$(echo "$version" | sed -n 's/^\([0-9]*\)\.\([0-9]*\).*/\1/p')
minor=$(echo "$version" | sed -n 's/^\([0-9]*\)\.\([0-9]*\).*/\2/p')
if [ -z "$major" ] || [ $((major * 10 + minor)) -lt 45 ]; then
    fail "$name" "GL version '$version'"
elif ! grep -q '^GLSL version: *[4-9]\.[0-9]' "$scratch/info.out"; then
    fail "$name" "no GLSL version: $(grep GLSL "$scratch/info.out")"
else
    pass "$name"
fi

# The device list: a count, then "device N:" per device with its extensions; at most one
# marked '*' (none when the surfaceless platform is used), and the platform line agrees.
name=info-device-list
count=$(sed -n 's/^EGL devices: *\([0-9][0-9]*\) (.*/\1/p' "$scratch/info.out")
marked=$(grep -c '^  \* device [0-9]' "$scratch/info.out")
platform=$(field 'EGL platform')
if grep -q '^EGL devices: *none' "$scratch/info.out"; then
    count=0
    pass "$name"    # no EGL_EXT_platform_device driver here: nothing to list
elif [ -z "$count" ]; then
    fail "$name" "no 'EGL devices:' line: $(head -c 400 "$scratch/info.out")"
elif ! grep -q '^  [ *] device 0: ' "$scratch/info.out"; then
    fail "$name" "device 0 not listed: $(grep -A3 '^EGL devices' "$scratch/info.out")"
elif [ "$(grep -c '^  [ *] device [0-9][0-9]*: ' "$scratch/info.out")" != "$count" ] ||
     [ "$(grep -c '^      extensions: ' "$scratch/info.out")" != "$count" ]; then
    fail "$name" "$count devices announced, listed: $(grep -A8 '^EGL devices' "$scratch/info.out")"
elif [ "$marked" -gt 1 ]; then
    fail "$name" "$marked devices marked as used"
elif [ "$marked" = 1 ] && ! echo "$platform" | grep -q '^device [0-9]* of '; then
    fail "$name" "a device is marked but the platform is '$platform'"
elif [ "$marked" = 0 ] && ! echo "$platform" | grep -q '^surfaceless'; then
    fail "$name" "no device marked but the platform is '$platform'"
else
    pass "$name"
fi

# --device 0 (when there is a device) uses device 0, and info marks it.
name=info-device-0
if [ "$count" = 0 ]; then
    pass "$name"    # nothing to choose
elif ! "$program" info --device 0 >"$scratch/info.out" 2>"$scratch/info.err"; then
    # A device that is listed may still fail to give a context; then the message says why.
    if grep -q 'GPU: ' "$scratch/info.err"; then pass "$name"; else fail "$name" "$(head -c 300 "$scratch/info.err")"; fi
elif ! grep -q '^  \* device 0: ' "$scratch/info.out" || ! field 'EGL platform' | grep -q "^device 0 of $count "; then
    fail "$name" "device 0 not the one used: $(head -n 6 "$scratch/info.out")"
else
    pass "$name"
fi

# devices_phrase: how the refusal counts the devices.
case $count in
    0) devices_phrase="there are no EGL devices" ;;
    1) devices_phrase="there is 1 EGL device" ;;
    *) devices_phrase="there are $count EGL devices" ;;
esac

# A number past the list: exit 2, naming the number asked for (not N + 1) and the count;
# render writes nothing.
name=render-device-99
rm -f "$scratch/out.png"
"$program" render scenes/three-balls.txt -o "$scratch/out.png" --size 8x8 --spp 1 --quiet --device 99 \
    >"$scratch/render.out" 2>"$scratch/render.err"
status=$?
if [ "$status" != 2 ]; then
    fail "$name" "exit $status, expected 2: $(head -c 300 "$scratch/render.err")"
elif ! grep -q -- "--device 99 asked for, but $devices_phrase" "$scratch/render.err"; then
    fail "$name" "message: $(head -c 300 "$scratch/render.err")"
elif [ -e "$scratch/out.png" ]; then
    fail "$name" "an output was written"
else
    pass "$name"
fi

name=info-device-past-the-end
"$program" info --device "$count" >"$scratch/info.out" 2>"$scratch/info.err"
status=$?
if [ "$status" != 2 ]; then
    fail "$name" "exit $status, expected 2: $(head -c 300 "$scratch/info.err")"
elif ! grep -q -- "--device $count asked for, but $devices_phrase" "$scratch/info.err"; then
    fail "$name" "message: $(head -c 300 "$scratch/info.err")"
else
    pass "$name"
fi

name=info-device-not-a-number
"$program" info --device one >/dev/null 2>"$scratch/info.err"
status=$?
if [ "$status" != 2 ] || ! grep -q "device number" "$scratch/info.err"; then
    fail "$name" "exit $status: $(head -c 300 "$scratch/info.err")"
else
    pass "$name"
fi

finish
