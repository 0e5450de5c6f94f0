#!/bin/sh
# test-importers.sh: glTF and PLY files end to end (the files are written by
# scenes/generators/models.c into the scratch directory):
#   - a glTF model placed by two nodes renders exactly as two copies of it placed by the
#     text format's groups, and a glTF file rendered by itself exactly as the same scene
#     (camera, sky) written in the text format around the gltf statement;
#   - the same model as .gltf with an external buffer, with data URIs and as .glb render
#     the same; --camera picks another camera; the skipped points are warned about;
#   - the same mesh as PLY (ASCII, binary little and big endian) and OBJ renders the same;
#   - every bad file of tests/render/scenes/gltf-bad/ (hand-written) and a bad PLY is
#     refused with exit 2, the file and what is wrong, and no image is written.
# About 10 s: 20 renders of 64x32 at 4 spp.
#   usage: sh tests/render/test-importers.sh PROGRAM SCRATCH_DIR
. "$(dirname "$0")/lib.sh"

models="$scratch/models"
if ! cc -std=c11 -O2 scenes/generators/models.c -lm -o "$scratch/models-generator" 2>"$scratch/cc.err" ||
        ! "$scratch/models-generator" "$models" >/dev/null 2>"$scratch/gen.err"; then
    fail "the model generator" "$(cat "$scratch/cc.err" "$scratch/gen.err" | head -c 300)"
    finish
    exit
fi
options="--size 64x32 --spp 4 --max-depth 6 --quiet"

# The golden suite's glTF scene is this generator's model.glb, committed.
if cmp -s "$models/model.glb" scenes/assets/model.glb; then
    pass "scenes/assets/model.glb is scenes/generators/models.c's model.glb byte for byte"
else fail "scenes/assets/model.glb" "differs from the generator's model.glb (regenerate and commit it)"; fi

# render_ok NAME OUTPUT SCENE [OPTIONS...]: renders SCENE to OUTPUT, a failure is one check.
render_ok() {
    lib_name=$1 lib_output=$2 lib_scene=$3
    shift 3
    # shellcheck disable=SC2086 # $options is a list of options
    if "$program" render "$lib_scene" -o "$lib_output" $options "$@" 2>"$scratch/err"; then
        return 0
    fi
    fail "$lib_name" "render of $lib_scene failed: $(head -c 300 "$scratch/err")"
    return 1
}

# ---- two nodes = two copies; a file by itself = its scene in the text format -------------
# pair.gltf: "pair" at 0 0.5 0 holding "left" at -1.25 0 0 and "right" at 1.5 0.25 -0.5
# scaled by 0.5 (scenes/generators/models.c); its camera at 0 1.5 6 looking down -Z with a
# 40-degree field of view; a file by itself has the constant sky of 0.5.
cat >"$models/copies.txt" <<'SCENE'
camera from 0 1.5 6 at 0 1.5 5 up 0 1 0 fov 40
sky constant 0.5 0.5 0.5
group {
    translate 0 0.5 0
    group {
        translate -1.25 0 0
        gltf "single.gltf"
    }
    group {
        scale 0.5
        translate 1.5 0.25 -0.5
        gltf "single.gltf"
    }
}
SCENE
cat >"$models/pair-as-text.txt" <<'SCENE'
camera from 0 1.5 6 at 0 1.5 5 up 0 1 0 fov 40
sky constant 0.5 0.5 0.5
gltf "pair.gltf"
SCENE
if render_ok "pair" "$scratch/pair.exr" "$models/pair.gltf" &&
        render_ok "copies" "$scratch/copies.exr" "$models/copies.txt" &&
        render_ok "pair as text" "$scratch/pair-text.exr" "$models/pair-as-text.txt"; then
    same "a glTF mesh placed by two nodes renders as two copies placed by groups" "$scratch/pair.exr" \
        "$scratch/copies.exr"
    same "a glTF file by itself renders as its camera and sky around the gltf statement" "$scratch/pair.exr" \
        "$scratch/pair-text.exr"
fi
# The copies are not all there is: without the right one the image differs.
cat >"$models/one-copy.txt" <<'SCENE'
camera from 0 1.5 6 at 0 1.5 5 up 0 1 0 fov 40
sky constant 0.5 0.5 0.5
group {
    translate -1.25 0.5 0
    gltf "single.gltf"
}
SCENE
if render_ok "one copy" "$scratch/one.exr" "$models/one-copy.txt"; then
    if "$program" diff "$scratch/pair.exr" "$scratch/one.exr" --quiet >/dev/null 2>&1; then
        fail "the pair differs from one copy" "the images agree: the second node was not placed"
    else
        pass "the pair differs from one copy"
    fi
fi

# ---- one model in three containers; cameras; warnings ---------------------------------------
if render_ok "model.gltf" "$scratch/model.exr" "$models/model.gltf" &&
        render_ok "model-embedded.gltf" "$scratch/embedded.exr" "$models/model-embedded.gltf" &&
        render_ok "model.glb" "$scratch/glb.exr" "$models/model.glb"; then
    same "external buffer and data URIs render the same" "$scratch/model.exr" "$scratch/embedded.exr"
    same ".gltf and .glb render the same" "$scratch/model.exr" "$scratch/glb.exr"
fi
if render_ok "--camera top" "$scratch/top.exr" "$models/model.glb" --camera top; then
    if "$program" diff "$scratch/top.exr" "$scratch/glb.exr" --quiet >/dev/null 2>&1; then
        fail "--camera top renders another view" "the images agree"
    else
        pass "--camera top renders another view"
    fi
fi
expect_exit "--camera of a name the file lacks" 2 "model.glb: no camera called 'side' \\(its scene places 'front', 'top'\\)" \
    "$program" render "$models/model.glb" -o "$scratch/x.png" --camera side
expect_exit "--camera with a scene file" 2 "--camera picks a camera of a glTF file" \
    "$program" render "$models/copies.txt" -o "$scratch/x.png" --camera top
expect_exit "-D with a glTF scene" 2 "-D size: a glTF scene \\(.*model.glb'\\) has no variables" \
    "$program" render "$models/model.glb" -o "$scratch/x.png" -D size=2
# shellcheck disable=SC2086
expect_exit "points of a glTF file are warned about once" 0 \
    "warning: .*model.glb: meshes\\[1\\]\\.primitives\\[2\\]: points and lines are not rendered: this primitive is skipped" \
    "$program" render "$models/model.glb" -o "$scratch/warned.png" --size 16x8 --spp 1
count=$(grep -c "points and lines" "$scratch/stderr")
if [ "$count" = 1 ]; then pass "one warning for the points"; else fail "one warning for the points" "$count warnings"; fi

# ---- PLY (three encodings) and OBJ of one mesh -----------------------------------------------
for kind in torus.obj torus-ascii.ply torus-le.ply torus-be.ply; do
    cat >"$models/$kind.txt" <<SCENE
camera from 0 2.5 4 at 0 0 0 up 0 1 0 fov 40
sky gradient 1 1 1  0.4 0.6 1
material clay lambertian 0.7 0.4 0.3
light point 2 3 2 intensity 10
group {
    rotate 1 0 0 20
    mesh "$kind" clay
}
SCENE
    render_ok "$kind" "$scratch/$kind.exr" "$models/$kind.txt" || continue
done
for kind in torus-ascii.ply torus-le.ply torus-be.ply; do
    [ -f "$scratch/$kind.exr" ] && [ -f "$scratch/torus.obj.exr" ] &&
        same "$kind renders exactly as the OBJ of the same mesh" "$scratch/$kind.exr" "$scratch/torus.obj.exr"
done

# ---- bad input: exit 2, the file and what is wrong, no image ----------------------------------
bad=tests/render/scenes/gltf-bad
refuse() {
    expect_refusal "$1" "$2" "$scratch/refused" "$program" render "$3" -o "$scratch/refused/out.png" --quiet
}
refuse "malformed JSON" "malformed.gltf: tinygltf: \\[json.exception.parse_error.101\\] parse error at line 19" \
    "$bad/malformed.gltf"
refuse "a buffer too short for its accessor" \
    "short-buffer.gltf: meshes\\[0\\]\\.primitives\\[0\\]\\.attributes\\.POSITION: accessor 0 reads past the end of buffer view 0 \\(of buffer 0\\)" \
    "$bad/short-buffer.gltf"
refuse "an index out of range" \
    "index-range.gltf: meshes\\[0\\]\\.primitives\\[0\\]\\.indices: index 7 \\(element 2 of accessor 1\\) is out of range" \
    "$bad/index-range.gltf"
refuse "a cycle of nodes" "cycle.gltf: nodes\\[1\\]\\.children: node 2 is an ancestor of nodes\\[1\\] \\(the node hierarchy has a cycle\\)" \
    "$bad/cycle.gltf"
refuse "a node with two parents" "two-parents.gltf: nodes\\[2\\]\\.children: node 1 is already a child of nodes\\[0\\]" \
    "$bad/two-parents.gltf"
refuse "a number beyond double" "huge-number.gltf: tinygltf: .*number overflow parsing '1e999'" "$bad/huge-number.gltf"
refuse "a NaN in a buffer" "nan-position.gltf: .*POSITION: accessor 0 element 1 is not a finite number" \
    "$bad/nan-position.gltf"
refuse "an accessor of the wrong type" "wrong-type.gltf: .*POSITION: accessor 0 has the wrong type \\(2 components; expected VEC3\\)" \
    "$bad/wrong-type.gltf"
refuse "a missing buffer file" "missing-buffer.gltf: tinygltf: File not found : missing.bin" "$bad/missing-buffer.gltf"
refuse "a missing glTF file" "none.gltf: No such file or directory" "$bad/none.gltf"
refuse "a .glb that is not one" "not-binary.glb: not a binary glTF file \\(it does not start with 'glTF'\\)" \
    "$bad/not-binary.glb"
refuse "a texture that is not an image" "not-an-image.gltf: cannot read image 'images\\[0\\]'" "$bad/not-an-image.gltf"
refuse "a required extension" "draco.gltf: extensionsRequired\\[0\\]: the extension 'KHR_draco_mesh_compression' is required but not supported" \
    "$bad/draco.gltf"
refuse "an orthographic camera" "orthographic.gltf: cameras\\[0\\] \\('plan'\\) is orthographic, which rtspheres does not render" \
    "$bad/orthographic.gltf"
# Through the gltf statement: the statement's position first.
printf 'sky constant 0.5 0.5 0.5\ngroup {\n    gltf "%s/short-buffer.gltf"\n}\n' "$(pwd)/$bad" >"$scratch/bad-scene.txt"
refuse "a bad model named by a scene" "bad-scene.txt:3:10: glTF '.*short-buffer.gltf': meshes\\[0\\]" "$scratch/bad-scene.txt"
printf 'sky constant 0.5 0.5 0.5\ngltf "%s/not-an-image.gltf"\n' "$(pwd)/$bad" >"$scratch/bad-image.txt"
refuse "a bad image of a model named by a scene" "bad-image.txt:2:1: glTF '.*not-an-image.gltf': cannot read image 'images\\[0\\]'" \
    "$scratch/bad-image.txt"
head -c 1000 "$models/torus-le.ply" >"$scratch/cut.ply"
printf 'material m lambertian 0.5 0.5 0.5\nmesh "cut.ply" m\n' >"$scratch/cut.txt"
refuse "a cut PLY file" "cut.txt:2:6: cannot read mesh '.*cut.ply': the data is too short for the 561 vertex records" \
    "$scratch/cut.txt"
finish
