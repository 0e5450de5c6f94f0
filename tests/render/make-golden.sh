#!/bin/sh
# make-golden.sh: re-renders every golden image listed in golden-scenes.txt into golden/.
# Run by `make golden` only, never by the tests. Commit new goldens only with a reason:
# what changed in the renderer and why the new image is right.
#   usage: sh tests/render/make-golden.sh PROGRAM
set -eu
program=$1
here=$(dirname "$0")
. "$here/golden-options.sh"
mkdir -p golden
grep -v '^#' "$here/golden-scenes.txt" | while read -r name scene extra; do
    [ -n "$name" ] || continue
    # shellcheck disable=SC2086
    "$program" render "$scene" -o "golden/$name.exr" $golden_render_options $extra
    echo "golden: golden/$name.exr from $scene"
done
