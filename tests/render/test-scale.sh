#!/bin/sh
# test-scale.sh: a 1.3-million-triangle mesh (an icosphere of subdivision 8, generated
# here) loads, builds its BVH and renders, and its image is the sphere it approximates:
# a diffuse furnace, exactly the albedo where the camera sees the mesh.
#   usage: sh tests/render/test-scale.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

if ! cc -std=c11 -O2 scenes/generators/assets.c -lm -o "$scratch/assets" 2>"$scratch/cc.err"; then
    fail "build the mesh generator" "$(cat "$scratch/cc.err")"
    finish
    exit 1
fi
"$scratch/assets" "$scratch" 8 >/dev/null
cat >"$scratch/big.txt" <<'SCENE'
render size 32 32 spp 4 depth 16 seed 1
camera from 0 0 4 at 0 0 0 up 0 1 0 fov 30
sky constant 1 1 1
material grey lambertian 0.5 0.5 0.5
group material grey {
    rotate 0 1 0 20
    mesh "icosphere-8.obj"
}
SCENE
if "$program" render "$scratch/big.txt" -o "$scratch/big.exr" --verbose 2>"$scratch/big.err" >/dev/null; then
    summary=$(grep "rtspheres: scene:" "$scratch/big.err")
    triangles=$(echo "$summary" | sed -n 's/.*(\([0-9]*\) triangles).*/\1/p')
    if [ "$triangles" = 1310720 ]; then pass "1,310,720 triangles loaded, built and rendered: $summary"
    else fail "a 1.3M-triangle mesh" "summary: $summary"; fi
    range=$(channel_range "$scratch/big.exr" G 12,12,20,20)
    if within "${range% *}" 0.5 0.001 && within "${range#* }" 0.5 0.001; then
        pass "the 1.3M-triangle sphere is a correct furnace ($range)"
    else fail "the 1.3M-triangle sphere furnace" "centre $range, expected 0.5"; fi
else
    fail "a 1.3M-triangle mesh" "render failed: $(tail -3 "$scratch/big.err")"
fi
finish
