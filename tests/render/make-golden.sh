#!/bin/sh
# make-golden.sh: re-renders every golden image of the suite golden-scenes.txt into golden/
# (`rtspheres check --update-all`: the cases' own render options, with variance layers).
# Run by `make golden` only, never by the tests. Commit new goldens only with a reason:
# what changed in the renderer and why the new image is right.
#   usage: sh tests/render/make-golden.sh PROGRAM
set -eu
program=$1
here=$(dirname "$0")
mkdir -p golden
"$program" check "$here/golden-scenes.txt" --update-all
