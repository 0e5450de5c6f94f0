#!/bin/sh
# test-scene-model.sh: the scene model end to end (groups, transforms, instances, meshes,
# volumes, textures) checked against what must be true whatever the noise.
#   usage: sh tests/render/test-scene-model.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"
here=$(cd "$(dirname "$0")" && pwd)

# furnace NAME BODY: a white-sky furnace around BODY (statements placing convex shapes of
# material grey, albedo 0.5, centred at the origin within radius ~1). A convex diffuse
# body scatters a camera ray once and the ray escapes, so every pixel on it is exactly
# 0.5: rays that re-hit the surface they left (wrong normals, a wrong transform) darken it.
furnace() {
    name=$1 body=$2
    cat >"$scratch/$name.txt" <<SCENE
render size 48 48 spp 8 depth 64 seed 1
camera from 0 0 5 at 0 0 0 up 0 1 0 fov 30
sky constant 1 1 1
material grey lambertian 0.5 0.5 0.5
$body
SCENE
    if "$program" render "$scratch/$name.txt" -o "$scratch/$name.exr" --quiet 2>"$scratch/$name.err"; then
        range=$(channel_range "$scratch/$name.exr" G 21,21,27,27)
        if within "${range% *}" 0.5 0.001 && within "${range#* }" 0.5 0.001; then
            pass "furnace: $name renders exactly the albedo at its centre ($range)"
        else
            fail "furnace: $name" "centre pixels $range, expected 0.5"
        fi
    else
        fail "furnace: $name" "render failed: $(cat "$scratch/$name.err")"
    fi
}

cp "$here/scenes/octahedron.obj" "$scratch/octahedron.obj"
furnace ellipsoid-in-transformed-group "group material grey {
    scale 1.2 0.8 0.6
    rotate 1 2 3 40
    translate 0 0 0.2
    sphere 0 0 0 1
}"
furnace nested-groups "group {
    rotate 0 0 1 30
    group material grey {
        scale 1 0.7 1
        rotate 1 0 0 60
        sphere 0 0 0 1
    }
}"
furnace mesh-octahedron "mesh \"octahedron.obj\" grey"
furnace mesh-in-transformed-group "group material grey {
    scale 0.9 1.3 0.8
    rotate 0 1 1 25
    mesh \"octahedron.obj\"
}"
furnace box-quads "box -0.8 -0.8 -0.8 0.8 0.8 0.8 grey"
furnace instanced-named-group "group unit material grey {
    scale 0.001
    sphere 0 0 0 1
}
instance unit {
    scale 1000
    rotate 0 1 0 10
}"

# A mesh placed twice by instances renders the same as the same triangles written out
# twice (the second already moved): instancing changes the cost, not the image.
# two_octahedra_scene: the scene both are placed in.
two_octahedra_scene() {
    cat <<'SCENE'
render size 64 48 spp 16 depth 8 seed 2
camera from 0 1 6 at 0 0 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.5 0.7 1
material red lambertian 0.8 0.3 0.2
material ground lambertian 0.5 0.5 0.5
sphere 0 -1001 0 1000 ground
SCENE
}
# octahedron_copy DX: a group of octahedron.obj's triangles written out one by one
# (material red), moved DX in x.
octahedron_copy() {
    echo "group {"
    echo "    translate $1 0 0"
    awk '$1 == "v" { v[++n] = $2 " " $3 " " $4 }
         $1 == "f" { print "    triangle " v[$2] "  " v[$3] "  " v[$4] "  red" }' "$scratch/octahedron.obj"
    echo "}"
}
{
    two_octahedra_scene
    cat <<'SCENE'
group left {
    translate -1.2 0 0
    mesh "octahedron.obj" red
}
instance left {
    translate 2.4 0 0
}
SCENE
} >"$scratch/instanced.txt"
{
    two_octahedra_scene
    octahedron_copy -1.2
    octahedron_copy 1.2
} >"$scratch/copies.txt"
if "$program" render "$scratch/instanced.txt" -o "$scratch/instanced.exr" --quiet &&
   "$program" render "$scratch/copies.txt" -o "$scratch/copies.exr" --quiet; then
    if "$program" diff "$scratch/instanced.exr" "$scratch/copies.exr" --fail 0 --failpercent 0 >"$scratch/d.txt"; then
        pass "a mesh instanced twice renders as two copies ($(grep '^max error' "$scratch/d.txt"))"
    else
        fail "a mesh instanced twice renders as two copies" "$(tr '\n' ' ' <"$scratch/d.txt")"
    fi
else
    fail "a mesh instanced twice renders as two copies" "a render failed"
fi

# A volume: a dense white medium in a white sky is another furnace (it scatters but does
# not absorb: every path ends in the sky), and a black medium darkens what is behind it.
furnace_volume() {
    name=$1 albedo=$2 expected=$3
    cat >"$scratch/$name.txt" <<SCENE
render size 32 32 spp 16 depth 200 seed 4
camera from 0 0 5 at 0 0 0 up 0 1 0 fov 30
sky constant 1 1 1
volume 2 $albedo $albedo $albedo {
    sphere 0 0 0 1
}
SCENE
    if "$program" render "$scratch/$name.txt" -o "$scratch/$name.exr" --roulette-depth 1000 --quiet; then
        mean=$(channel_mean "$scratch/$name.exr" G 13,13,19,19)
        if [ "$expected" = 1 ] && within "$mean" 1 0.02; then pass "$name: a non-absorbing medium keeps a white furnace white ($mean)"
        elif [ "$expected" = dark ] && awk -v m="$mean" 'BEGIN { exit !(m < 0.2) }'; then
            pass "$name: an absorbing medium is dark ($mean)"
        else fail "$name" "centre mean $mean, expected $expected"; fi
    else
        fail "$name" "render failed"
    fi
}
furnace_volume volume-white 1 1
furnace_volume volume-black 0 dark

# The camera inside fog: the media the camera starts in are found, so fog in front of a
# bright background dims it by about exp(-density * distance).
cat >"$scratch/fog.txt" <<'SCENE'
render size 16 16 spp 64 depth 64 seed 5
camera from 0 0 0 at 0 0 -1 up 0 1 0 fov 10
sky constant 1 1 1
material black lambertian 0 0 0
volume 0.5 0 0 0 {
    sphere 0 0 0 2
}
SCENE
if "$program" render "$scratch/fog.txt" -o "$scratch/fog.exr" --quiet; then
    mean=$(channel_mean "$scratch/fog.exr" G)
    # Absorbing fog (albedo 0), 2 units to the sky: transmittance exp(-1) = 0.368.
    if within "$mean" 0.3679 0.05; then pass "camera inside fog sees the sky dimmed by exp(-1) ($mean)"
    else fail "camera inside fog" "mean $mean, expected 0.368"; fi
else
    fail "camera inside fog" "render failed"
fi

# Bad meshes are errors with the scene position, never crashes.
printf 'v 0 0 0\nv 1 0 0\nf 1 2 9\n' >"$scratch/broken.obj"
printf 'material m lambertian 1 1 1\nmesh "broken.obj" m\n' >"$scratch/broken.txt"
"$program" render "$scratch/broken.txt" -o "$scratch/broken.png" >/dev/null 2>"$scratch/broken.err"
code=$?
if [ "$code" = 2 ] && grep -q "broken.txt:2:" "$scratch/broken.err"; then pass "a malformed OBJ is an error at the mesh statement"
else fail "a malformed OBJ" "exit $code: $(cat "$scratch/broken.err")"; fi
printf 'material m lambertian 1 1 1\nmesh "missing.obj" m\n' >"$scratch/missing.txt"
"$program" render "$scratch/missing.txt" -o "$scratch/missing.png" >/dev/null 2>"$scratch/missing.err"
code=$?
if [ "$code" = 2 ] && grep -q "missing.obj" "$scratch/missing.err"; then pass "a missing OBJ is an error naming it"
else fail "a missing OBJ" "exit $code: $(cat "$scratch/missing.err")"; fi
# An OBJ whose material library is missing renders (its faces get the scene's material)
# and the CLI says so once, not under --quiet.
printf 'mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$scratch/nomtl.obj"
printf 'camera from 0 0 3 at 0 0 0 up 0 1 0 fov 40\nmaterial m lambertian 0.5 0.5 0.5\nmesh "nomtl.obj" m\n' \
    >"$scratch/nomtl.txt"
if "$program" render "$scratch/nomtl.txt" -o "$scratch/nomtl-%d.png" --size 8x8 --spp 1 --frames 0-2 \
        2>"$scratch/nomtl.err" && [ "$(grep -c "warning: .*nomtl.txt:3:.*missing.mtl" "$scratch/nomtl.err")" = 1 ] &&
   "$program" render "$scratch/nomtl.txt" -o "$scratch/nomtl.png" --size 8x8 --spp 1 --quiet 2>"$scratch/quiet.err" &&
   [ ! -s "$scratch/quiet.err" ]; then
    pass "a missing MTL file is one warning with the statement's position, none under --quiet"
else
    fail "missing MTL warning" "$(head -c 300 "$scratch/nomtl.err") / quiet: $(head -c 200 "$scratch/quiet.err")"
fi

finish
