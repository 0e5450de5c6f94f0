/* test_gltf_load.c: the glTF shim (core/gltf_load.cpp): what a file becomes (attributes,
 * primitive modes, the node hierarchy and its transforms, cameras, lights, materials,
 * textures and samplers, sparse and quantized accessors) and every refusal of
 * gltf_load.h with its JSON path: malformed JSON, short buffers, indices out of range,
 * cycles, non-finite numbers, missing files, wrong types, a .glb that is not one,
 * required extensions. Each test writes its files into its own scratch directory. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_load.h"
#include "image_io.h"
#include "packed_layout.h"
#include "support.h"

#include "gltf_fixture.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "fast_unwind_on_malloc=0"; }

static gltf_model load_ok(const char *path)
{
    gltf_model model;
    rt_error error = {{0}};
    rt_status status = gltf_load(path, &model, &error);
    if (status != RT_OK)
        print_error("%s\n", error.message);
    assert_int_equal(status, RT_OK);
    return model;
}

/* Loads path, which must be refused as bad input; checks the contract and returns the
 * reason after "PATH: ". */
static const char *refused(const char *path, rt_error *error)
{
    gltf_model model;
    assert_int_equal(gltf_load(path, &model, error), RT_ERROR_INPUT);
    assert_null(model.meshes);
    assert_null(model.placements);
    assert_int_equal(model.mesh_count, 0);
    size_t length = strlen(path);
    assert_int_equal(strncmp(error->message, path, length), 0);
    assert_int_equal(strncmp(error->message + length, ": ", 2), 0);
    return error->message + length + 2;
}

/* The fixture with other nodes (and extra members). */
static const char *with_nodes(scratch *s, const char *nodes, const char *extra)
{
    return gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, NULL, nodes, extra);
}

static void test_quad_loads(void **state)
{
    gltf_model m = load_ok(with_nodes(*state, NULL, ""));
    assert_int_equal(m.mesh_count, 1);
    const gltf_mesh *mesh = &m.meshes[0];
    assert_int_equal(mesh->vertex_count, 4);
    assert_int_equal(mesh->triangle_count, 2);
    assert_memory_equal(mesh->positions, quad_positions, sizeof quad_positions);
    for (int i = 0; i < 6; i++)
        assert_int_equal(mesh->indices[i], quad_indices[i]);
    for (int v = 0; v < 4; v++) {
        assert_close(mesh->normals[3 * v + 2], 1, 0);   /* made unit length */
        assert_close(mesh->uvs[2 * v], quad_uvs[2 * v], 0);
        assert_close(mesh->uvs[2 * v + 1], 1 - quad_uvs[2 * v + 1], 0);   /* v up */
    }
    assert_null(mesh->colors);
    assert_int_equal(mesh->triangle_materials[0], -1);
    assert_int_equal(m.placement_count, 1);
    assert_int_equal(m.placements[0].mesh, 0);
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++)
            assert_close(m.placements[0].object_to_world[r][k], r == k, 0);
    assert_int_equal(m.warning_count, 0);
    assert_int_equal(m.camera_count, 0);
    assert_int_equal(m.light_count, 0);
    gltf_model_free(&m);
}

static void test_strips_fans_and_points(void **state)
{
    scratch *s = *state;
    /* The 4 quad vertices without indices: a strip, a fan, points, lines. */
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"mode\": 5}, "
                         "{\"attributes\": {\"POSITION\": 0}, \"mode\": 6}, {\"attributes\": {\"POSITION\": 0}, "
                         "\"mode\": 0}, {\"attributes\": {\"POSITION\": 0}, \"mode\": 3}]}]";
    gltf_model m = load_ok(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""));
    const gltf_mesh *mesh = &m.meshes[0];
    assert_int_equal(mesh->triangle_count, 4);
    assert_null(mesh->normals);   /* none given: flat shading */
    /* Strip: (0 1 2), (1 3 2); fan: (1 2 0), (2 3 0); the fan's vertices follow the strip's. */
    static const uint32_t expected[12] = {0, 1, 2, 1, 3, 2, 5, 6, 4, 6, 7, 4};
    for (int i = 0; i < 12; i++)
        assert_int_equal(mesh->indices[i], expected[i]);
    assert_int_equal(m.warning_count, 1);
    assert_string_equal(m.warnings[0], "meshes[0].primitives[2]: points and lines are not rendered: this primitive "
                                       "and 1 more are skipped");
    gltf_model_free(&m);

    rt_error e;
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"mode\": 9}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].mode: 9 is not a primitive mode (0 to 6)");
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"mode\": 4}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0]: 4 vertices (or indices) are not a whole number of triangles");
}

static void test_node_transforms_and_instancing(void **state)
{
    /* A root with T R S (translate 1 2 3, 90 degrees about +Z, scale 2), a child mesh node
     * with a translation and one with a matrix (a translation by 0 0 5). */
    const char *nodes =
        "\"nodes\": [{\"translation\": [1, 2, 3], \"rotation\": [0, 0, 0.7071067811865476, 0.7071067811865476], "
        "\"scale\": [2, 2, 2], \"children\": [1, 2], \"name\": \"root\"}, {\"mesh\": 0, \"translation\": [1, 0, 0], "
        "\"name\": \"a\"}, {\"mesh\": 0, \"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1], \"name\": "
        "\"b\"}], \"scenes\": [{\"nodes\": [0]}]";
    gltf_model m = load_ok(with_nodes(*state, nodes, ""));
    assert_int_equal(m.placement_count, 2);
    assert_int_equal(m.placements[0].mesh, 0);
    assert_int_equal(m.placements[1].mesh, 0);
    assert_string_equal(m.placements[0].node_name, "a");
    /* root: x' = R(2 x) + t with R turning +X to +Y. Node a's origin (1 0 0) goes to
     * (1, 4, 3); its x axis to (0, 2, 0). */
    const double (*a)[4] = m.placements[0].object_to_world;
    assert_close(a[0][3], 1, 1e-12);
    assert_close(a[1][3], 4, 1e-12);
    assert_close(a[2][3], 3, 1e-12);
    assert_close(a[0][0], 0, 1e-12);
    assert_close(a[1][0], 2, 1e-12);
    assert_close(a[0][1], -2, 1e-12);
    const double (*b)[4] = m.placements[1].object_to_world;
    assert_close(b[2][3], 3 + 10, 1e-12);   /* 0 0 5 scaled by 2 */
    gltf_model_free(&m);
}

static void test_which_scene_is_drawn(void **state)
{
    scratch *s = *state;
    rt_error e;
    const char *nodes = "\"nodes\": [{\"mesh\": 0}, {\"mesh\": 0, \"translation\": [5, 0, 0]}], \"scenes\": "
                        "[{\"nodes\": [0]}, {\"nodes\": [1]}], \"scene\": 1";
    gltf_model m = load_ok(with_nodes(s, nodes, ""));
    assert_int_equal(m.placement_count, 1);
    assert_close(m.placements[0].object_to_world[0][3], 5, 0);
    gltf_model_free(&m);
    /* No scenes: every node that is no node's child. */
    nodes = "\"nodes\": [{\"mesh\": 0, \"children\": [1]}, {\"mesh\": 0}, {\"mesh\": 0}]";
    m = load_ok(with_nodes(s, nodes, ""));
    assert_int_equal(m.placement_count, 3);
    gltf_model_free(&m);
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}], "
                                              "\"scene\": 3", ""), &e),
                        "scene: scene 3 does not exist (the file has 1)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"children\": [1]}, {\"mesh\": 0}], \"scenes\": "
                                              "[{\"nodes\": [1]}]", ""), &e),
                        "scenes[0].nodes: node 1 is a child of nodes[0], not a root");
    /* No mesh placed: a warning. */
    m = load_ok(with_nodes(s, "\"nodes\": [{}], \"scenes\": [{\"nodes\": [0]}]", ""));
    assert_int_equal(m.placement_count, 0);
    assert_int_equal(m.warning_count, 1);
    assert_string_equal(m.warnings[0], "scene: its nodes place no mesh with triangles; nothing of the file is drawn");
    gltf_model_free(&m);
}

static void test_node_graph_errors(void **state)
{
    scratch *s = *state;
    rt_error e;
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"children\": [1]}, {\"children\": [2]}, {\"children\": "
                                              "[1]}], \"scenes\": [{\"nodes\": [0]}]", ""), &e),
                        "nodes[2].children: node 1 is already a child of nodes[0] (a node has at most one parent)");
    /* A cycle, also where no scene reaches it. */
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"children\": [1]}, {\"children\": [0]}], \"scenes\": "
                                              "[{\"nodes\": [0]}]", ""), &e),
                        "nodes[0].children: node 1 is an ancestor of nodes[0] (the node hierarchy has a cycle)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"mesh\": 0}, {\"children\": [2]}, {\"children\": [3]}, "
                                              "{\"children\": [1]}], \"scenes\": [{\"nodes\": [0]}]", ""), &e),
                        "nodes[1].children: node 2 is an ancestor of nodes[1] (the node hierarchy has a cycle)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"children\": [1]}, {\"mesh\": 0}], \"scenes\": "
                                              "[{\"nodes\": [1]}]", ""), &e),
                        "scenes[0].nodes: node 1 is a child of nodes[0], not a root");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"children\": [0]}], \"scenes\": [{\"nodes\": []}]", ""),
                                &e),
                        "nodes[0].children: the node is its own child (the node hierarchy has a cycle)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"children\": [7]}]", ""), &e),
                        "nodes[0].children: node 7 does not exist (the file has 1)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"mesh\": 4}]", ""), &e),
                        "nodes[0].mesh: mesh 4 does not exist (the file has 1)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"camera\": 0}]", ""), &e),
                        "nodes[0].camera: camera 0 does not exist (the file has 0)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"mesh\": 0, \"rotation\": [0, 0, 0, 0]}]", ""), &e),
                        "nodes[0].rotation: the quaternion has no length");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"mesh\": 0, \"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, "
                                              "1, 0, 0, 0, 0, 2]}]", ""), &e),
                        "nodes[0].matrix: the last row must be 0 0 0 1 (a glTF node matrix is affine)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"mesh\": 0, \"scale\": [1e300, 1e300, 1e300]}]", ""), &e),
                        "nodes[0]: its transform (with its parents') is too large for the renderer's 32-bit floats");
}

static void test_cameras_and_lights(void **state)
{
    scratch *s = *state;
    const char *nodes =
        "\"nodes\": [{\"mesh\": 0}, {\"camera\": 0, \"name\": \"eye\", \"translation\": [0, 1, 5]}, {\"camera\": 1}, "
        "{\"translation\": [1, 2, 3], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}}, "
        "{\"rotation\": [-0.7071067811865476, 0, 0, 0.7071067811865476], \"extensions\": {\"KHR_lights_punctual\": "
        "{\"light\": 0}}}], \"scenes\": [{\"nodes\": [0, 1, 2, 3, 4]}]";
    const char *extra =
        "\"cameras\": [{\"name\": \"persp\", \"type\": \"perspective\", \"perspective\": {\"yfov\": 0.5, "
        "\"aspectRatio\": 1.5, \"znear\": 0.1}}, {\"type\": \"orthographic\", \"orthographic\": {\"xmag\": 1, "
        "\"ymag\": 1, \"znear\": 0.1, \"zfar\": 10}}],\n\"extensionsUsed\": [\"KHR_lights_punctual\"],\n"
        "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"directional\", \"intensity\": 3, "
        "\"name\": \"sun\"}, {\"type\": \"spot\", \"color\": [1, 0.5, 0.25], \"intensity\": 40, \"spot\": "
        "{\"innerConeAngle\": 0.25, \"outerConeAngle\": 0.5}}]}}";
    gltf_model m = load_ok(with_nodes(s, nodes, extra));
    assert_int_equal(m.camera_count, 2);
    assert_string_equal(m.cameras[0].name, "persp");
    assert_string_equal(m.cameras[0].node_name, "eye");
    assert_false(m.cameras[0].orthographic);
    assert_close(m.cameras[0].yfov, 0.5, 0);
    assert_close(m.cameras[0].aspect_ratio, 1.5, 0);
    assert_close(m.cameras[0].camera_to_world[2][3], 5, 0);
    assert_true(m.cameras[1].orthographic);
    assert_int_equal(m.light_count, 2);
    assert_int_equal(m.lights[0].type, GLTF_LIGHT_SPOT);
    assert_close(m.lights[0].intensity, 40, 0);
    assert_close(m.lights[0].color[1], 0.5, 0);
    assert_close(m.lights[0].inner_cone, 0.25, 1e-7);
    assert_close(m.lights[0].outer_cone, 0.5, 1e-7);
    assert_close(m.lights[0].light_to_world[1][3], 2, 0);
    assert_int_equal(m.lights[1].type, GLTF_LIGHT_DIRECTIONAL);
    assert_string_equal(m.lights[1].name, "sun");
    assert_close(m.lights[1].color[0], 1, 0);   /* white without a colour */
    /* Turned -90 degrees about X: its -Z points down (-Y). */
    assert_close(-m.lights[1].light_to_world[1][2], -1, 1e-12);
    gltf_model_free(&m);

    rt_error e;
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 5}}}]",
                                           "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": "
                                           "\"point\"}]}}"), &e),
                        "nodes[0].extensions.KHR_lights_punctual.light: light 5 does not exist (the file has 1)");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                           "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": "
                                           "\"spot\", \"spot\": {\"innerConeAngle\": 0.5, \"outerConeAngle\": 0.4}}]}}"),
                                &e),
                        "extensions.KHR_lights_punctual.lights[0].spot: innerConeAngle 0.5 must be less than "
                        "outerConeAngle 0.400000006");
    assert_string_equal(refused(with_nodes(s, "\"nodes\": [{\"camera\": 0}]", "\"cameras\": [{\"type\": "
                                           "\"perspective\", \"perspective\": {\"yfov\": 4, \"znear\": 0.1}}]"), &e),
                        "cameras[0].perspective.yfov: 4 must be between 0 and pi radians (both excluded)");
}

static void test_materials(void **state)
{
    scratch *s = *state;
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 3, "
                         "\"material\": 1}, {\"attributes\": {\"POSITION\": 0}, \"indices\": 3}]}]";
    const char *extra =
        "\"materials\": [{}, {\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.25, 1, 0.5], "
        "\"metallicFactor\": 0.25, \"roughnessFactor\": 0.75}, \"emissiveFactor\": [1, 0.5, 0], \"alphaMode\": "
        "\"MASK\", \"alphaCutoff\": 0.3, \"doubleSided\": true, \"extensions\": {\"KHR_materials_emissive_strength\": "
        "{\"emissiveStrength\": 4}, \"KHR_materials_transmission\": {\"transmissionFactor\": 0.5}, "
        "\"KHR_materials_ior\": {\"ior\": 1.33}}}]";
    gltf_model m = load_ok(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, extra));
    assert_int_equal(m.material_count, 2);
    const gltf_material *d = &m.materials[0], *l = &m.materials[1];
    /* glTF's defaults. */
    assert_close(d->base_color[0], 1, 0);
    assert_close(d->metallic, 1, 0);
    assert_close(d->roughness, 1, 0);
    assert_close(d->ior, 1.5, 0);
    assert_int_equal(d->alpha_mode, GLTF_ALPHA_OPAQUE);
    assert_close(d->alpha_cutoff, 0.5, 0);
    assert_int_equal(d->base_color_texture.image, -1);
    assert_string_equal(l->name, "lamp");
    assert_close(l->base_color[3], 0.5, 0);
    assert_close(l->metallic, 0.25, 0);
    assert_close(l->roughness, 0.75, 0);
    assert_close(l->emissive[0], 4, 0);
    assert_close(l->emissive[1], 2, 0);
    assert_close(l->transmission, 0.5, 0);
    assert_close(l->ior, 1.33, 1e-6);
    assert_int_equal(l->alpha_mode, GLTF_ALPHA_MASK);
    assert_close(l->alpha_cutoff, 0.3, 1e-7);
    assert_true(l->double_sided);
    assert_int_equal(m.meshes[0].triangle_materials[0], 1);
    assert_int_equal(m.meshes[0].triangle_materials[2], -1);
    gltf_model_free(&m);

    rt_error e;
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, NULL, NULL,
                                          "\"materials\": [{\"pbrMetallicRoughness\": {\"metallicFactor\": 1.5}}]"), &e),
                        "materials[0].pbrMetallicRoughness.metallicFactor: 1.5 is outside [0, 1]");
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, NULL, NULL,
                                          "\"materials\": [{\"alphaMode\": \"SOMETIMES\"}]"), &e),
                        "materials[0].alphaMode: 'SOMETIMES' is not OPAQUE, MASK or BLEND");
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 3, \"material\": 2}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].material: material 2 does not exist (the file has 0)");
}

/* Writes a 2x2 PNG into the scratch and returns its bytes (malloc'd) and size. */
static unsigned char *png_bytes(scratch *s, size_t *size)
{
    const float colour[3] = {1, 0.5f, 0};
    rt_image image = make_image(2, 2, 3, 0);
    for (int i = 0; i < 4; i++)
        memcpy(image.pixels + 3 * i, colour, sizeof colour);
    rt_error e;
    assert_int_equal(image_write(in_scratch(s, "t.png"), &image, NULL, &e), RT_OK);
    image_free(&image);
    FILE *f = fopen(in_scratch(s, "t.png"), "rb");
    unsigned char *bytes = malloc(4096);
    *size = fread(bytes, 1, 4096, f);
    fclose(f);
    return bytes;
}

static void test_textures_samplers_and_transforms(void **state)
{
    scratch *s = *state;
    size_t png_size = 0;
    unsigned char *png = png_bytes(s, &png_size);
    char *encoded = base64_of(png, png_size);
    char extra[8192];
    snprintf(extra, sizeof extra,
             "\"images\": [{\"uri\": \"data:image/png;base64,%s\"}, {\"uri\": \"t.png\", \"name\": \"file\"}],\n"
             "\"samplers\": [{\"wrapS\": 33071, \"wrapT\": 33648}],\n"
             "\"textures\": [{\"source\": 0, \"sampler\": 0}, {\"source\": 1}],\n"
             "\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\": "
             "{\"KHR_texture_transform\": {\"offset\": [0.5, 0], \"scale\": [2, 3]}}}, \"metallicRoughnessTexture\": "
             "{\"index\": 1}}, \"normalTexture\": {\"index\": 1, \"texCoord\": 1}, \"emissiveTexture\": {\"index\": 0, "
             "\"extensions\": {\"KHR_texture_transform\": {\"scale\": [2, 3], \"offset\": [0.5, 0]}}}}]",
             encoded);
    free(encoded);
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 2}, "
                         "\"indices\": 3, \"material\": 0}]}]";
    gltf_model m = load_ok(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, extra));
    assert_int_equal(m.image_count, 2);
    assert_int_equal(m.images[0].size, png_size);
    assert_memory_equal(m.images[0].bytes, png, png_size);
    assert_memory_equal(m.images[1].bytes, png, png_size);   /* the external file, read */
    assert_string_equal(m.images[1].name, "file");
    const gltf_material *mat = &m.materials[0];
    assert_int_equal(mat->base_color_texture.image, 0);
    assert_int_equal(mat->base_color_texture.wrap_u, IMAGE_WRAP_CLAMP);
    assert_int_equal(mat->base_color_texture.wrap_v, IMAGE_WRAP_MIRROR);
    assert_int_equal(mat->metallic_roughness_texture.image, 1);
    assert_int_equal(mat->metallic_roughness_texture.wrap_u, IMAGE_WRAP_REPEAT);
    assert_int_equal(mat->normal_texture.image, 1);
    assert_int_equal(mat->emissive_texture.image, 0);
    /* The base colour's transform (u' = 2u + 0.5, v' = 3v), then v up: vertex 1 has glTF
     * uv (1, 1): (2.5, 3) and v = 1 - 3. */
    assert_close(m.meshes[0].uvs[2], 2.5, 1e-6);
    assert_close(m.meshes[0].uvs[3], -2, 1e-6);
    /* The metallic-roughness and normal textures have no transform: they differ. And the
     * normal texture asks for TEXCOORD_1. */
    assert_int_equal(m.warning_count, 2);
    assert_string_equal(m.warnings[0], "materials[0].normalTexture: uses TEXCOORD_1; only TEXCOORD_0 is read, so it "
                                       "is used");
    assert_string_equal(m.warnings[1], "materials[0]: its textures have different KHR_texture_transforms; the first "
                                       "one's applies to all");
    gltf_model_free(&m);
    free(png);

    /* A rotation of a quarter turn: u' = v, v' = -u (glTF's [cos sin; -sin cos]); vertex 1
     * has glTF uv (1, 1): (1, -1), then v up: 1 - (-1). */
    const char *rotated = "\"images\": [{\"uri\": \"t.png\"}], \"textures\": [{\"source\": 0}], \"materials\": "
                          "[{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\": "
                          "{\"KHR_texture_transform\": {\"rotation\": 1.5707963267948966}}}}}]";
    m = load_ok(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, rotated));
    assert_close(m.meshes[0].uvs[2], 1, 1e-6);
    assert_close(m.meshes[0].uvs[3], 2, 1e-6);
    gltf_model_free(&m);

    rt_error e;
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, NULL, NULL,
                                          "\"materials\": [{\"emissiveTexture\": {\"index\": 3}}]"), &e),
                        "materials[0].emissiveTexture.index: texture 3 does not exist (the file has 0)");
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, NULL, NULL,
                                          "\"images\": [{\"uri\": \"t.png\"}], \"samplers\": [{\"wrapS\": 7}], "
                                          "\"textures\": [{\"source\": 0, \"sampler\": 0}], \"materials\": "
                                          "[{\"emissiveTexture\": {\"index\": 0}}]"), &e),
                        "samplers[0]: wrapS and wrapT must be 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) or 33648 "
                        "(MIRRORED_REPEAT)");
    char missing[1024];
    snprintf(missing, sizeof missing, "images[0]: cannot read '%s': No such file or directory",
             in_scratch(s, "none.png"));
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, NULL, NULL,
                                          "\"images\": [{\"uri\": \"none.png\"}]"), &e),
                        missing);
}

static void test_accessor_bounds(void **state)
{
    scratch *s = *state;
    rt_error e;
    const char *accessors =
        "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 5, \"type\": \"VEC3\"}, "
        "{\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, {\"bufferView\": 2, "
        "\"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"}, {\"bufferView\": 3, \"componentType\": 5123, "
        "\"count\": 6, \"type\": \"SCALAR\"}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, accessors, NULL, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 0 reads past the end of buffer view 0 "
                        "(of buffer 0): it needs bytes 0 to 60, the view has 48");
    const char *views =
        "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": "
        "48, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 32}, {\"buffer\": 0, "
        "\"byteOffset\": 128, \"byteLength\": 100}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, views, NULL, NULL, NULL, ""), &e),
                        "bufferViews[3]: reads past the end of buffer 0: it needs bytes 128 to 228, the buffer has "
                        "144");
    /* A stride the positions do not fit. */
    views = "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48, \"byteStride\": 8}, "
            "{\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 96, "
            "\"byteLength\": 32}, {\"buffer\": 0, \"byteOffset\": 128, \"byteLength\": 12}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, views, NULL, NULL, NULL, ""), &e),
                        "bufferViews[0]: byteStride 8 must be a multiple of 4 from 12 to 252 for accessor 0");
    /* Indices out of range. */
    uint16_t bad[6] = {0, 1, 2, 0, 2, 9};
    unsigned char bytes[QUAD_BYTES];
    quad_buffer(bytes);
    memcpy(bytes + 128, bad, sizeof bad);
    assert_string_equal(refused(gltf_text(s, "m.gltf", bytes, QUAD_BYTES, NULL, NULL, NULL, NULL, ""), &e),
                        "meshes[0].primitives[0].indices: index 9 (element 5 of accessor 3) is out of range: the "
                        "primitive has 4 vertices");
    /* A NaN among the positions. */
    quad_buffer(bytes);
    float nan = NAN;
    memcpy(bytes + 16, &nan, sizeof nan);
    assert_string_equal(refused(gltf_text(s, "m.gltf", bytes, QUAD_BYTES, NULL, NULL, NULL, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 0 element 1 is not a finite number");
    /* An accessor that does not exist, and a buffer view that does not. */
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 9}}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 9 does not exist (the file has 4)");
    accessors = "\"accessors\": [{\"bufferView\": 8, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}]";
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"mode\": 6}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, accessors, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 0 names buffer view 8, which does not "
                        "exist (the file has 4)");
}

static void test_sparse_and_quantized_accessors(void **state)
{
    scratch *s = *state;
    /* Positions as normalized UNSIGNED_SHORT (KHR_mesh_quantization), a sparse accessor
     * moving vertex 2 to (0 0 1) (its values of the accessor's type), COLOR_0 as normalized
     * UNSIGNED_BYTE VEC4. Bytes: 0 positions (4 x 8, padded), 32 sparse index (uint8), 36
     * sparse value (3 x 2), 48 colours (4 x 4), 64 indices (6 x 2). */
    unsigned char b[80] = {0};
    uint16_t positions[4][4] = {{0, 0, 0}, {65535, 0, 0}, {65535, 65535, 0}, {0, 65535, 0}};
    memcpy(b, positions, sizeof positions);
    b[32] = 2;
    uint16_t value[3] = {0, 0, 65535};
    memcpy(b + 36, value, sizeof value);
    unsigned char colours[4][4] = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {51, 51, 51, 0}};
    memcpy(b + 48, colours, sizeof colours);
    memcpy(b + 64, quad_indices, sizeof quad_indices);
    const char *views =
        "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 32, \"byteStride\": 8}, {\"buffer\": 0, "
        "\"byteOffset\": 32, \"byteLength\": 1}, {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 6}, "
        "{\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 16}, {\"buffer\": 0, \"byteOffset\": 64, "
        "\"byteLength\": 12}]";
    const char *accessors =
        "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5123, \"normalized\": true, \"count\": 4, \"type\": "
        "\"VEC3\", \"sparse\": {\"count\": 1, \"indices\": {\"bufferView\": 1, \"componentType\": 5121}, \"values\": "
        "{\"bufferView\": 2}}}, {\"bufferView\": 3, \"componentType\": 5121, \"normalized\": true, \"count\": 4, "
        "\"type\": \"VEC4\"}, {\"bufferView\": 4, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]";
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"COLOR_0\": 1}, "
                         "\"indices\": 2}]}]";
    gltf_model m = load_ok(gltf_text(s, "m.gltf", b, sizeof b, views, accessors, meshes, NULL,
                                     "\"extensionsUsed\": [\"KHR_mesh_quantization\"], \"extensionsRequired\": "
                                     "[\"KHR_mesh_quantization\"]"));
    const gltf_mesh *mesh = &m.meshes[0];
    assert_close(mesh->positions[3], 1, 0);
    assert_close(mesh->positions[3 * 2], 0, 0);   /* the sparse value */
    assert_close(mesh->positions[3 * 2 + 2], 1, 0);
    assert_close(mesh->positions[3 * 3 + 1], 1, 0);
    assert_non_null(mesh->colors);
    assert_close(mesh->colors[0], 1, 0);
    assert_close(mesh->colors[3 * 3], 0.2, 1e-7);
    gltf_model_free(&m);

    rt_error e;
    /* The sparse index beyond the accessor. */
    b[32] = 4;
    assert_string_equal(refused(gltf_text(s, "m.gltf", b, sizeof b, views, accessors, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 0's sparse index 4 (element 0) is out "
                        "of range: the accessor has 4 elements");
}

static void test_wrong_types(void **state)
{
    scratch *s = *state;
    rt_error e;
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 2}}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 2 has the wrong type (2 components; "
                        "expected VEC3)");
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 0}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].indices: accessor 0 has the wrong type (3 components; expected "
                        "SCALAR)");
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 2}}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.NORMAL: accessor 2 has the wrong type (2 components; "
                        "expected VEC3)");
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"NORMAL\": 1}}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes: the primitive has no POSITION");
    /* COLOR_0 of integers that are not normalized; a count other than POSITION's. */
    const char *accessors =
        "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, "
        "{\"bufferView\": 1, \"componentType\": 5121, \"count\": 4, \"type\": \"VEC4\"}, {\"bufferView\": 2, "
        "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC2\"}]";
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"COLOR_0\": 1}, \"mode\": 6}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, accessors, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.COLOR_0: accessor 1 has integer components that are not "
                        "normalized");
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 2}, \"mode\": 6}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, accessors, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.TEXCOORD_0: accessor 2 has 3 elements, POSITION has 4");
    accessors = "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5125, \"count\": 4, \"type\": \"VEC3\"}]";
    meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"mode\": 6}]}]";
    assert_string_equal(refused(gltf_text(s, "m.gltf", NULL, 0, NULL, accessors, meshes, NULL, ""), &e),
                        "meshes[0].primitives[0].attributes.POSITION: accessor 0 has component type UNSIGNED_INT "
                        "(5125), which this attribute cannot have");
}

static void test_extensions(void **state)
{
    scratch *s = *state;
    rt_error e;
    assert_string_equal(refused(with_nodes(s, NULL, "\"extensionsUsed\": [\"KHR_draco_mesh_compression\"], "
                                                    "\"extensionsRequired\": [\"KHR_draco_mesh_compression\"]"), &e),
                        "extensionsRequired[0]: the extension 'KHR_draco_mesh_compression' is required but not "
                        "supported (rtspheres reads KHR_lights_punctual, KHR_materials_emissive_strength, "
                        "KHR_materials_transmission, KHR_materials_ior, KHR_texture_transform and "
                        "KHR_mesh_quantization)");
    gltf_model m = load_ok(with_nodes(s, NULL, "\"extensionsUsed\": [\"KHR_materials_unlit\", "
                                               "\"KHR_materials_emissive_strength\", \"EXT_meshopt_compression\"]"));
    assert_int_equal(m.warning_count, 1);
    assert_string_equal(m.warnings[0], "extensionsUsed: optional extensions that are ignored: KHR_materials_unlit, "
                                       "EXT_meshopt_compression");
    gltf_model_free(&m);
}

static void test_file_errors(void **state)
{
    scratch *s = *state;
    rt_error e;
    char path[600];
    snprintf(path, sizeof path, "%s", in_scratch(s, "none.gltf"));
    assert_string_equal(refused(path, &e), "No such file or directory");
    assert_string_equal(refused(s->directory, &e), "it is a directory");
    assert_contains(refused(write_file(s, "broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [\n"), &e),
                    "tinygltf: [json.exception.parse_error.101] parse error at line 2");
    assert_contains(refused(write_file(s, "big.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"matrix\": "
                                                      "[1e999]}]}"), &e),
                    "tinygltf: [json.exception.out_of_range.406] number overflow parsing '1e999'");
    assert_string_equal(refused(write_file(s, "text.glb", "{\"asset\": {\"version\": \"2.0\"}}"), &e),
                        "not a binary glTF file (it does not start with 'glTF')");
    /* A GLB header whose lengths do not add up. */
    unsigned char glb[40] = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 40, 0, 0, 0, 200, 0, 0, 0, 'J', 'S', 'O', 'N'};
    assert_contains(refused(scratch_write(s, "short.glb", glb, sizeof glb), &e), "tinygltf: Invalid glTF binary.");
    /* A buffer file that is missing. */
    assert_contains(refused(write_file(s, "external.gltf",
                                       "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"byteLength\": 12, \"uri\": "
                                       "\"gone.bin\"}]}"), &e),
                    "tinygltf: ");
    /* A required property of the wrong type. */
    assert_contains(refused(write_file(s, "type.gltf",
                                       "{\"asset\": {\"version\": \"2.0\"}, \"accessors\": [{\"componentType\": 5126, "
                                       "\"count\": \"four\", \"type\": \"VEC3\"}]}"), &e),
                    "tinygltf: ");
}

/* A GLB of the quad: the JSON chunk and the buffer as its BIN chunk. */
static void test_glb_reads_like_gltf(void **state)
{
    scratch *s = *state;
    char json[4096];
    int n = snprintf(json, sizeof json, "{\"asset\": {\"version\": \"2.0\"}, %s, %s, %s, %s, \"buffers\": "
                                        "[{\"byteLength\": %d}]}", QUAD_VIEWS, QUAD_ACCESSORS, QUAD_MESHES, QUAD_NODES,
                     QUAD_BYTES);
    while (n % 4 != 0)
        json[n++] = ' ';
    unsigned char glb[8192];
    uint32_t header[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + n + 8 + QUAD_BYTES), (uint32_t)n, 0x4E4F534Au};
    memcpy(glb, header, sizeof header);
    memcpy(glb + 20, json, (size_t)n);
    uint32_t bin[2] = {QUAD_BYTES, 0x004E4942u};
    memcpy(glb + 20 + n, bin, sizeof bin);
    quad_buffer(glb + 28 + n);
    gltf_model m = load_ok(scratch_write(s, "quad.glb", glb, (size_t)(28 + n + QUAD_BYTES)));
    assert_int_equal(m.meshes[0].triangle_count, 2);
    assert_memory_equal(m.meshes[0].positions, quad_positions, sizeof quad_positions);
    gltf_model_free(&m);
}

/* Primitives with and without normals in one mesh: the one without gets flat normals on
 * vertices of its own. */
static void test_mixed_normals(void **state)
{
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1}, "
                         "\"indices\": 3}, {\"attributes\": {\"POSITION\": 0}, \"indices\": 3}]}]";
    gltf_model m = load_ok(gltf_text(*state, "m.gltf", NULL, 0, NULL, NULL, meshes, NULL, ""));
    const gltf_mesh *mesh = &m.meshes[0];
    assert_int_equal(mesh->triangle_count, 4);
    assert_int_equal(mesh->vertex_count, 4 + 6);
    assert_non_null(mesh->normals);
    for (int v = 4; v < 10; v++)
        assert_close(mesh->normals[3 * v + 2], 1, 1e-7);   /* the quad faces +Z */
    assert_int_equal(mesh->indices[6], 4);
    gltf_model_free(&m);
}

int main(void)
{
#define T(name) cmocka_unit_test_setup_teardown(name, make_scratch, remove_scratch)
    const struct CMUnitTest tests[] = {
        T(test_quad_loads),
        T(test_strips_fans_and_points),
        T(test_node_transforms_and_instancing),
        T(test_which_scene_is_drawn),
        T(test_node_graph_errors),
        T(test_cameras_and_lights),
        T(test_materials),
        T(test_textures_samplers_and_transforms),
        T(test_accessor_bounds),
        T(test_sparse_and_quantized_accessors),
        T(test_wrong_types),
        T(test_extensions),
        T(test_file_errors),
        T(test_glb_reads_like_gltf),
        T(test_mixed_normals),
    };
#undef T
    return cmocka_run_group_tests(tests, NULL, NULL);
}
