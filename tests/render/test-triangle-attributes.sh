#!/bin/sh
# test-triangle-attributes.sh: a scene `triangle` with `normals` and `uvs` clauses is
# shaded exactly as the same triangle of an OBJ mesh with the same vn and vt (both go
# through the packed vertex section); without them it is flat and uses edge coordinates,
# which must show: the smooth, textured quad below differs from the flat one. Also in a
# placed group, the corner normals move with the triangle.
#   usage: sh tests/render/test-triangle-attributes.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

earth="$(pwd)/scenes/assets/earth.ppm"
cat >"$scratch/quad.obj" <<'OBJ'
v -1 0 0
v 1 0 0
v 1 2 0
v -1 2 0
vn -0.6 0 0.8
vn 0.6 0 0.8
vn 0.6 0.3 0.74161985
vn -0.6 0.3 0.74161985
vt 0 0
vt 2 0
vt 2 3
vt 0 3
f 1/1/1 2/2/2 3/3/3
f 1/1/1 3/3/3 4/4/4
OBJ
# scene KIND: the quad as an OBJ mesh, as smooth scene triangles, or as flat ones; a
# fuzzy textured metal shows both the shading normal and the uv.
scene() {
    cat <<SCENE
set turn 0
render size 48 48 spp 16 depth 4 seed 3
camera from 0 1 4 at 0 1 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.3 0.5 1
texture earth image "$earth"
material m metal @earth fuzz 0.3
group {
    rotate 0 1 0 \$turn
SCENE
    case $1 in
        mesh) echo '    mesh "quad.obj" m' ;;
        smooth)
            echo '    triangle -1 0 0  1 0 0  1 2 0  normals -0.6 0 0.8  0.6 0 0.8  0.6 0.3 0.74161985  uvs 0 0  2 0  2 3  m'
            echo '    triangle -1 0 0  1 2 0  -1 2 0  normals -0.6 0 0.8  0.6 0.3 0.74161985  -0.6 0.3 0.74161985  uvs 0 0  2 3  0 3  m' ;;
        flat)
            echo '    triangle -1 0 0  1 0 0  1 2 0  m'
            echo '    triangle -1 0 0  1 2 0  -1 2 0  m' ;;
    esac
    echo '}'
}
for kind in mesh smooth flat; do
    scene $kind >"$scratch/$kind.txt"
done
for turn in 0 25; do
    ok=true
    for kind in mesh smooth flat; do
        "$program" render "$scratch/$kind.txt" -o "$scratch/$kind-$turn.exr" -D turn=$turn --quiet 2>"$scratch/err" ||
            { fail "render $kind (turn $turn)" "$(cat "$scratch/err")"; ok=false; }
    done
    $ok || continue
    if "$program" diff "$scratch/smooth-$turn.exr" "$scratch/mesh-$turn.exr" --fail 0 --failpercent 0 \
            >"$scratch/diff" 2>&1; then
        pass "turned $turn: triangles with normals and uvs shade as the mesh with vn and vt"
    else
        fail "turned $turn: triangles with normals and uvs shade as the mesh" "$(tr '\n' ' ' <"$scratch/diff")"
    fi
    if "$program" diff "$scratch/flat-$turn.exr" "$scratch/mesh-$turn.exr" --quiet >/dev/null 2>&1; then
        fail "turned $turn: flat triangles differ from smooth ones" "the images agree: normals or uvs were ignored"
    else
        pass "turned $turn: flat triangles differ from smooth ones"
    fi
done
finish
