#!/bin/sh
# test-large-pages.sh: core/large_pages.h from the outside: the GL driver, loaded by EGL,
# allocates through rtspheres' posix_memalign (so that its textures get the huge-page
# advice), and the advice changes no pixel.
#   usage: sh tests/render/test-large-pages.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

scene=scenes/weekend.txt

# glibc's loader lists every symbol binding with LD_DEBUG=bindings: the driver's calls of
# posix_memalign must bind to the program, not to libc.
bindings="$scratch/bindings"
if LD_DEBUG=bindings LD_DEBUG_OUTPUT="$bindings" "$program" render "$scene" -o "$scratch/tiny.exr" --size 16x16 \
    --spp 1 --quiet 2>"$scratch/tiny.err"; then
    driver_lines=$(cat "$bindings".* 2>/dev/null | grep "normal symbol \`posix_memalign'" | grep -E '/dri/|gallium')
    if ! cat "$bindings".* 2>/dev/null | grep -q 'binding file'; then
        echo "SKIP the driver's posix_memalign: this dynamic loader lists no bindings (LD_DEBUG, glibc's)"
    elif [ -z "$driver_lines" ]; then
        echo "SKIP the driver's posix_memalign: this GL driver does not allocate with it (a GPU's textures are not ours)"
    elif echo "$driver_lines" | grep -v " to [^ ]*rtspheres \[" >/dev/null; then
        fail "the driver's posix_memalign" "binds elsewhere: $(echo "$driver_lines" | grep -v ' to [^ ]*rtspheres \[' | head -2)"
    else
        pass "the GL driver allocates through rtspheres' posix_memalign ($(echo "$driver_lines" | head -1 |
            sed 's/.*binding file \([^ ]*\) .*/\1/'))"
    fi
else
    fail "a render with LD_DEBUG" "$(tail -3 "$scratch/tiny.err")"
fi
rm -f "$bindings".*

# The heap is advised at the program's start (before any library's constructor), unless
# RTSPHERES_NO_HUGE_PAGES=1 was in its environment: seen in /proc/PID/smaps during a render.
# heap_flags [VAR=VALUE]: prints the VmFlags of the render's [heap] mappings, or nothing when
# the render ended before they could be read.
heap_flags() {
    env "$@" "$program" render "$scene" -o "$scratch/heap.exr" --size 640x360 --spp 16 --quiet 2>/dev/null &
    lib_pid=$!
    lib_flags=
    lib_tries=0
    while [ -z "$lib_flags" ] && [ "$lib_tries" -lt 100 ] && kill -0 "$lib_pid" 2>/dev/null; do
        lib_flags=$(awk '/\[heap\]/ { heap = 1; next } /^[0-9a-f]+-[0-9a-f]+ / { heap = 0 }
            heap && /^VmFlags:/ { print }' "/proc/$lib_pid/smaps" 2>/dev/null)
        [ -n "$lib_flags" ] || sleep 0.05
        lib_tries=$((lib_tries + 1))
    done
    wait "$lib_pid"
    echo "$lib_flags"
}
flags_on=$(heap_flags RTSPHERES_UNUSED=1)
flags_off=$(heap_flags RTSPHERES_NO_HUGE_PAGES=1)
if [ -z "$flags_on" ] || [ -z "$flags_off" ]; then
    fail "the heap's advice" "no [heap] mapping seen in /proc/PID/smaps during a render"
elif ! echo "$flags_on" | grep -q ' hg'; then
    # The advice fails where the kernel has no transparent huge pages; /sys says whether it
    # has them (a chroot may not mount it).
    if [ -r /sys/kernel/mm/transparent_hugepage/enabled ]; then
        fail "the heap's advice" "not advised: $(echo "$flags_on" | head -2 | tr '\n' ' ')"
    else
        echo "SKIP the heap's advice: not advised, and no /sys/kernel/mm/transparent_hugepage to say whether this kernel has huge pages"
    fi
elif echo "$flags_off" | grep -q ' hg'; then
    fail "RTSPHERES_NO_HUGE_PAGES=1" "the heap is advised all the same: $(echo "$flags_off" | tr '\n' ' ')"
else
    pass "the heap is on huge pages from the start, and not with RTSPHERES_NO_HUGE_PAGES=1"
fi

# 512x512: each state texture (4 MB) is over LARGE_PAGES_MIN_BYTES, so it is advised.
render_options="--size 512x512 --spp 2 --max-depth 8"
if render "$scratch/advised.exr" && RTSPHERES_NO_HUGE_PAGES=1 render "$scratch/plain.exr"; then
    same "huge pages change no pixel (512x512, with and without RTSPHERES_NO_HUGE_PAGES=1)" \
        "$scratch/advised.exr" "$scratch/plain.exr"
else
    fail "renders with and without huge pages" "a render failed"
fi
finish
