#!/bin/sh
# test-large-pages.sh: core/large_pages.h from the outside: the GL driver, loaded by EGL,
# allocates through rtspheres' posix_memalign (so that its textures get the huge-page
# advice where it is given), and the advice changes no pixel.
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

# 512x512: each state texture (4 MB) is over LARGE_PAGES_MIN_BYTES, so it is advised.
render_options="--size 512x512 --spp 2 --max-depth 8"
if RTSPHERES_HUGE_PAGES=1 render "$scratch/advised.exr" && RTSPHERES_HUGE_PAGES=0 render "$scratch/plain.exr"; then
    same "huge pages change no pixel (512x512, RTSPHERES_HUGE_PAGES=1 and 0)" \
        "$scratch/advised.exr" "$scratch/plain.exr"
else
    fail "renders with and without huge pages" "a render failed"
fi
finish
