/* test_scene_gltf.c: a glTF model in the scene (core/scene_gltf.c and the gltf
 * statement): its materials as pbr materials with their textures and images (decoded by
 * scene_load_assets, sampler wrap modes into the packed image record), its meshes as
 * objects placed by its nodes through the blocks around the statement (groups, named
 * groups and instances, read once however often named), glTF's default material, the
 * errors with the statement's position; and a glTF file as a scene by itself (camera and
 * size, lights in glTF's units, sky, --camera, orthographic refused, a camera framing the
 * model when the file has none). */
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
#include "pack.h"
#include "packed_layout.h"
#include "scene.h"
#include "scene_assets.h"
#include "scene_gltf.h"
#include "scene_parse.h"
#include "support.h"

#include "gltf_fixture.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "fast_unwind_on_malloc=0"; }

/* The quad with two materials (one textured through a clamp/mirror sampler from a PNG
 * data URI), placed by two nodes; written as m.gltf. */
static const char *textured_quad(scratch *s)
{
    rt_image image = make_image(2, 2, 3, 0.5f);
    rt_error e;
    assert_int_equal(image_write(in_scratch(s, "t.png"), &image, NULL, &e), RT_OK);
    image_free(&image);
    FILE *f = fopen(in_scratch(s, "t.png"), "rb");
    unsigned char png[4096];
    size_t size = fread(png, 1, sizeof png, f);
    fclose(f);
    char *encoded = base64_of(png, size);
    char extra[8192];
    snprintf(extra, sizeof extra,
             "\"images\": [{\"uri\": \"data:image/png;base64,%s\"}],\n"
             "\"samplers\": [{\"wrapS\": 33071, \"wrapT\": 33648}],\n"
             "\"textures\": [{\"source\": 0, \"sampler\": 0}, {\"source\": 0}],\n"
             "\"materials\": [{\"name\": \"paint\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 1, 1], "
             "\"baseColorTexture\": {\"index\": 0}, \"metallicRoughnessTexture\": {\"index\": 1}, \"metallicFactor\": "
             "0.5, \"roughnessFactor\": 0.25}, \"normalTexture\": {\"index\": 1}, \"emissiveFactor\": [1, 1, 1], "
             "\"emissiveTexture\": {\"index\": 1}}, {\"alphaMode\": \"BLEND\"}]",
             encoded);
    free(encoded);
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1, "
                         "\"TEXCOORD_0\": 2}, \"indices\": 3, \"material\": 0}, {\"attributes\": {\"POSITION\": 0}, "
                         "\"indices\": 3}]}]";
    const char *nodes = "\"nodes\": [{\"mesh\": 0}, {\"mesh\": 0, \"translation\": [3, 0, 0]}], \"scenes\": "
                        "[{\"nodes\": [0, 1]}]";
    return gltf_text(s, "m.gltf", NULL, 0, NULL, NULL, meshes, nodes, extra);
}

static void load_scene_ok(const char *path, scene *out)
{
    rt_error e = {{0}};
    rt_status status = scene_load_file(path, NULL, out, &e);
    if (status == RT_OK)
        status = scene_load_assets(out, &e);
    if (status != RT_OK)
        print_error("%s\n", e.message);
    assert_int_equal(status, RT_OK);
}

static void test_statement_adds_materials_and_meshes(void **state)
{
    scratch *s = *state;
    textured_quad(s);
    scene sc;
    load_scene_ok(write_file(s, "scene.txt", "gltf \"m.gltf\"\n"), &sc);
    /* Materials: the file's two, then glTF's default for the primitive without one. */
    assert_int_equal(sc.material_count, 2 + 1);
    const scene_material *paint = &sc.materials[0];
    assert_string_equal(paint->name, "m.gltf:paint");
    assert_string_equal(sc.materials[1].name, "m.gltf:materials[1]");
    assert_string_equal(sc.materials[2].name, "m.gltf:default");
    assert_int_equal(paint->type, MATERIAL_PBR);
    assert_close(paint->albedo[2], 1, 0);
    assert_close(paint->metallic, 0.5, 0);
    assert_close(paint->roughness, 0.25, 0);
    assert_close(paint->index_of_refraction, 1.5, 0);
    assert_true(paint->one_sided);
    assert_false(paint->vertex_colors);
    assert_int_equal(paint->alpha_mode, SCENE_ALPHA_OPAQUE);
    assert_int_equal(sc.materials[1].alpha_mode, SCENE_ALPHA_MASK);   /* BLEND is imported as MASK */
    assert_close(sc.materials[1].alpha_cutoff, 0.5, 0);
    assert_close(sc.materials[2].metallic, 1, 0);
    assert_close(sc.materials[2].roughness, 1, 0);
    /* Images: the one PNG as colour with the clamp/mirror sampler (base colour), colour
     * repeating (emission: another sampler) and data repeating (metallic-roughness, normal
     * map): three scene images, two image textures. */
    assert_int_equal(sc.image_count, 3);
    assert_int_equal(sc.texture_count, 2);
    const scene_image *base = &sc.images[sc.textures[paint->albedo_texture].image];
    assert_false(base->data);
    assert_int_equal(base->wrap[0], IMAGE_WRAP_CLAMP);
    assert_int_equal(base->wrap[1], IMAGE_WRAP_MIRROR);
    assert_int_equal(sc.textures[paint->emission_texture].type, TEXTURE_IMAGE);
    assert_true(sc.images[paint->metallic_roughness_texture].data);
    assert_int_equal(paint->normal_map, paint->metallic_roughness_texture);
    assert_int_equal(base->width, 2);
    /* The PNG holds 0.5 sRGB-encoded (188): decoded for colour, as stored for data. */
    assert_close(base->pixels[0], image_srgb_decode(188 / 255.0f), 1e-6);
    assert_close(sc.images[paint->normal_map].pixels[0], 188 / 255.0, 1e-6);
    assert_null(base->encoded);   /* the bytes are freed once decoded */
    assert_string_equal(base->path, "images[0]");
    assert_contains(base->position, "scene.txt:1:1: glTF '");
    /* One mesh, one object, two placements; triangle materials per primitive. */
    assert_int_equal(sc.mesh_count, 1);
    assert_int_equal(sc.object_count, 1);
    assert_int_equal(sc.instance_count, 2);
    assert_int_equal(sc.meshes[0].triangle_count, 4);
    assert_int_equal(sc.meshes[0].triangle_materials[0], 0);
    assert_int_equal(sc.meshes[0].triangle_materials[3], 2);
    assert_close(sc.instances[1].object_to_world[0][3], 3, 0);

    /* The wrap modes reach the packed image record. */
    packed_scene packed;
    rt_error e;
    assert_int_equal(pack_scene(&sc, NULL, &packed, &e), RT_OK);
    int image = sc.textures[paint->albedo_texture].image;
    uint32_t wrap = packed.texels[4 * (packed.image_offset + (uint32_t)image) + 3];
    assert_int_equal(wrap, IMAGE_WRAP_CLAMP | IMAGE_WRAP_MIRROR << IMAGE_WRAP_V_SHIFT);
    assert_int_equal(packed.texels[4 * (packed.image_offset + (uint32_t)paint->normal_map) + 3], 0);
    packed_scene_free(&packed);
    scene_free(&sc);
}

/* COLOR_0 reaches the mesh, and the material a coloured mesh uses multiplies by it. */
static void test_vertex_colours(void **state)
{
    scratch *s = *state;
    unsigned char bytes[QUAD_BYTES + 16];
    quad_buffer(bytes);
    const unsigned char colours[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 51, 51, 51, 255};
    memcpy(bytes + QUAD_BYTES, colours, sizeof colours);
    const char *views = "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, "
                        "\"byteOffset\": 48, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": "
                        "32}, {\"buffer\": 0, \"byteOffset\": 128, \"byteLength\": 12}, {\"buffer\": 0, \"byteOffset\": "
                        "144, \"byteLength\": 16}]";
    const char *accessors =
        "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, "
        "{\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, {\"bufferView\": 2, "
        "\"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"}, {\"bufferView\": 3, \"componentType\": 5123, "
        "\"count\": 6, \"type\": \"SCALAR\"}, {\"bufferView\": 4, \"componentType\": 5121, \"normalized\": true, "
        "\"count\": 4, \"type\": \"VEC4\"}]";
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"COLOR_0\": 4}, "
                         "\"indices\": 3, \"material\": 0}]}, {\"primitives\": [{\"attributes\": {\"POSITION\": 0}, "
                         "\"indices\": 3, \"material\": 1}]}]";
    const char *nodes = "\"nodes\": [{\"mesh\": 0}, {\"mesh\": 1}], \"scenes\": [{\"nodes\": [0, 1]}]";
    const char *path = gltf_text(s, "c.gltf", bytes, sizeof bytes, views, accessors, meshes, nodes,
                                 "\"materials\": [{\"name\": \"painted\"}, {\"name\": \"plain\"}]");
    scene sc;
    rt_error e = {{0}};
    assert_int_equal(scene_gltf_load_file(path, NULL, &sc, &e), RT_OK);
    assert_int_equal(sc.mesh_count, 2);
    assert_non_null(sc.meshes[0].colors);
    assert_close(sc.meshes[0].colors[0], 1, 0);
    assert_close(sc.meshes[0].colors[3 * 3 + 1], 0.2, 1e-7);   /* linear, as glTF defines COLOR_0 */
    assert_null(sc.meshes[1].colors);
    assert_true(sc.materials[0].vertex_colors);
    assert_false(sc.materials[1].vertex_colors);
    scene_free(&sc);
}

static void test_statement_places_through_blocks(void **state)
{
    scratch *s = *state;
    textured_quad(s);
    scene sc;
    load_scene_ok(write_file(s, "scene.txt",
                             "material red lambertian 0.8 0.1 0.1\n"
                             "group pair {\n    translate 0 10 0\n    gltf \"m.gltf\"\n}\n"
                             "instance pair {\n    translate 0 0 5\n}\n"
                             "group material red {\n    scale 2\n    gltf \"m.gltf\"\n}\n"),
                  &sc);
    /* Read once: one mesh and its object, six placements. */
    assert_int_equal(sc.mesh_count, 1);
    assert_int_equal(sc.object_count, 1);
    assert_int_equal(sc.instance_count, 6);
    for (int i = 0; i < 6; i++)
        assert_int_equal(sc.instances[i].object, 0);
    /* The group, the instance of it, the scaled group (whose material fills only -1). */
    assert_close(sc.instances[1].object_to_world[0][3], 3, 0);
    assert_close(sc.instances[1].object_to_world[1][3], 10, 0);
    assert_close(sc.instances[3].object_to_world[2][3], 5, 0);
    assert_close(sc.instances[3].object_to_world[1][3], 10, 0);
    assert_close(sc.instances[5].object_to_world[0][3], 6, 0);
    assert_close(sc.instances[5].object_to_world[0][0], 2, 0);
    assert_int_equal(sc.instances[5].material, 0);
    assert_int_equal(sc.material_count, 1 + 3);
    scene_free(&sc);
}

static void test_statement_errors(void **state)
{
    scratch *s = *state;
    scene sc;
    rt_error e;
    /* A bad file: the statement's position, the file, the JSON path. */
    const char *accessors = "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 9, \"type\": "
                            "\"VEC3\"}, {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": "
                            "\"VEC3\"}, {\"bufferView\": 2, \"componentType\": 5126, \"count\": 4, \"type\": "
                            "\"VEC2\"}, {\"bufferView\": 3, \"componentType\": 5123, \"count\": 6, \"type\": "
                            "\"SCALAR\"}]";
    const char *model = gltf_text(s, "bad.gltf", NULL, 0, NULL, accessors, NULL, NULL, "");
    char expected[1024];
    snprintf(expected, sizeof expected, "scene.txt:2:10: glTF '%s': meshes[0].primitives[0].attributes.POSITION: "
                                        "accessor 0 reads past the end of buffer view 0", model);
    const char *path = write_file(s, "scene.txt", "group {\n    gltf \"bad.gltf\"\n}\n");
    assert_int_equal(scene_load_file(path, NULL, &sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, expected);
    path = write_file(s, "scene.txt", "gltf \"none.glb\"\n");
    assert_int_equal(scene_load_file(path, NULL, &sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "scene.txt:1:6: glTF '");
    assert_contains(e.message, "none.glb': No such file or directory");
    path = write_file(s, "scene.txt", "gltf \"none.glb\" red\n");
    assert_int_equal(scene_load_file(path, NULL, &sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "scene.txt:1:17: ");
    /* An embedded image that is not an image: at asset loading, named by the statement. */
    const char *not_png = "\"images\": [{\"uri\": \"data:image/png;base64,aGVsbG8gd29ybGQ=\"}], \"textures\": "
                          "[{\"source\": 0}], \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": "
                          "{\"index\": 0}}}]";
    const char *meshes = "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 3, "
                         "\"material\": 0}]}]";
    gltf_text(s, "text.gltf", NULL, 0, NULL, NULL, meshes, NULL, not_png);
    path = write_file(s, "scene.txt", "\ngltf \"text.gltf\"\n");
    assert_int_equal(scene_load_file(path, NULL, &sc, &e), RT_OK);
    assert_int_equal(scene_load_assets(&sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "scene.txt:2:1: glTF '");
    assert_contains(e.message, "text.gltf': cannot read image 'images[0]': ");
    scene_free(&sc);
}

/* The quad placed by one node, a camera and three lights, as a scene by itself. */
static const char *lit_quad(scratch *s, const char *cameras)
{
    const char *nodes =
        "\"nodes\": [{\"mesh\": 0}, {\"name\": \"eye\", \"camera\": 0, \"translation\": [0.5, 0.5, 4]}, "
        "{\"name\": \"up\", \"camera\": 1, \"translation\": [0, 5, 0], \"rotation\": [-0.7071067811865476, 0, 0, "
        "0.7071067811865476]}, {\"translation\": [1, 2, 3], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}, "
        "{\"translation\": [0, 4, 0], \"rotation\": [-0.7071067811865476, 0, 0, 0.7071067811865476], \"extensions\": "
        "{\"KHR_lights_punctual\": {\"light\": 1}}}, {\"extensions\": {\"KHR_lights_punctual\": {\"light\": 2}}}], "
        "\"scenes\": [{\"nodes\": [0, 1, 2, 3, 4, 5]}]";
    char extra[4096];
    snprintf(extra, sizeof extra,
             "%s,\n\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"color\": [1, 0.5, "
             "0.25], \"intensity\": 20}, {\"type\": \"spot\", \"intensity\": 8, \"spot\": {\"innerConeAngle\": 0.5, "
             "\"outerConeAngle\": 1}}, {\"type\": \"directional\", \"intensity\": 2}]}}",
             cameras);
    return gltf_text(s, "lit.gltf", NULL, 0, NULL, NULL, NULL, nodes, extra);
}

#define TWO_CAMERAS                                                                                          \
    "\"cameras\": [{\"name\": \"front\", \"type\": \"perspective\", \"perspective\": {\"yfov\": 0.6981317007977318, " \
    "\"aspectRatio\": 2, \"znear\": 0.1}}, {\"type\": \"perspective\", \"perspective\": {\"yfov\": 1, \"znear\": " \
    "0.1}}]"

static void test_file_as_a_scene(void **state)
{
    scratch *s = *state;
    const char *path = lit_quad(s, TWO_CAMERAS);
    scene sc;
    rt_error e = {{0}};
    assert_int_equal(scene_gltf_load_file(path, NULL, &sc, &e), RT_OK);
    /* The first camera: at its node, looking down its -Z, fov 40 degrees, size 720x360. */
    assert_close(sc.camera.look_from[2], 4, 0);
    assert_close(sc.camera.look_at[2], 3, 0);
    assert_close(sc.camera.look_at[0], 0.5, 0);
    assert_close(sc.camera.up[1], 1, 0);
    assert_close(sc.camera.vertical_fov_degrees, 40, 1e-4);
    assert_int_equal(sc.render.width, 720);
    assert_int_equal(sc.render.height, 360);
    /* The neutral sky, one instance, the lights in glTF's units. */
    assert_int_equal(sc.sky.type, SKY_CONSTANT);
    assert_close(sc.sky.bottom[1], 0.5, 0);
    assert_int_equal(sc.instance_count, 1);
    assert_int_equal(sc.light_count, 3);
    const scene_light *point = &sc.lights[0], *spot = &sc.lights[1], *sun = &sc.lights[2];
    assert_int_equal(point->type, SCENE_LIGHT_POINT);
    assert_close(point->color[1], 10, 1e-6);   /* colour x candela */
    assert_close(point->position[2], 3, 0);
    assert_int_equal(point->falloff, FALLOFF_INVERSE_SQUARE);
    assert_int_equal(spot->type, SCENE_LIGHT_SPOT);
    assert_close(spot->direction[1], -1, 1e-6);
    assert_close(spot->spot_inner_degrees, 0.5 * 180 / M_PI, 1e-4);
    assert_close(spot->spot_outer_degrees, 180 / M_PI, 1e-4);
    assert_int_equal(sun->type, SCENE_LIGHT_SUN);
    assert_close(sun->direction[2], -1, 0);   /* the way its light travels: its -Z */
    assert_close(sun->color[0], 2, 0);        /* lux as irradiance */
    assert_close(sun->sun_angle_degrees, 0, 0);
    scene_free(&sc);

    /* --camera by the node's name: looking straight down; the size of no aspect ratio. */
    assert_int_equal(scene_gltf_load_file(path, "up", &sc, &e), RT_OK);
    assert_close(sc.camera.look_at[1], 4, 1e-6);
    assert_close(sc.camera.vertical_fov_degrees, 180 / M_PI, 1e-4);
    assert_int_equal(sc.render.width, 640);
    scene_free(&sc);
    assert_int_equal(scene_gltf_load_file(path, "side", &sc, &e), RT_ERROR_INPUT);
    char expected[1024];
    snprintf(expected, sizeof expected, "%s: no camera called 'side' (its scene places 'front', 'up')", path);
    assert_string_equal(e.message, expected);
}

static void test_orthographic_and_missing_cameras(void **state)
{
    scratch *s = *state;
    scene sc;
    rt_error e;
    const char *path = lit_quad(s, "\"cameras\": [{\"name\": \"plan\", \"type\": \"orthographic\", \"orthographic\": "
                                   "{\"xmag\": 1, \"ymag\": 1, \"znear\": 0.1, \"zfar\": 10}}, {\"type\": "
                                   "\"perspective\", \"perspective\": {\"yfov\": 1, \"znear\": 0.1}}]");
    assert_int_equal(scene_gltf_load_file(path, NULL, &sc, &e), RT_ERROR_INPUT);
    char expected[1024];
    snprintf(expected, sizeof expected, "%s: cameras[0] ('plan') is orthographic, which rtspheres does not render "
                                        "(only perspective cameras; choose another with --camera NAME)", path);
    assert_string_equal(e.message, expected);
    assert_int_equal(scene_gltf_load_file(path, "up", &sc, &e), RT_OK);
    scene_free(&sc);

    /* No camera: one on +Z looking at the centre of the placed quad (0.5 0.5 0), far
     * enough for its bounding sphere (radius sqrt(0.5)) to fill 40 degrees. */
    path = gltf_text(s, "plain.gltf", NULL, 0, NULL, NULL, NULL, NULL, "");
    assert_int_equal(scene_gltf_load_file(path, NULL, &sc, &e), RT_OK);
    assert_close(sc.camera.look_at[0], 0.5, 0);
    assert_close(sc.camera.look_at[1], 0.5, 0);
    assert_close(sc.camera.look_from[2], sqrt(0.5) / sin(20 * M_PI / 180), 1e-5);
    assert_int_equal(sc.render.width, 640);
    assert_int_equal(sc.light_count, 0);
    scene_free(&sc);
    assert_int_equal(scene_gltf_load_file(path, "eye", &sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "plain.gltf: no camera called 'eye' (its scene places no camera)");
}

static void test_model_paths(void **state)
{
    (void)state;
    assert_true(scene_gltf_is_model_path("a/b.gltf"));
    assert_true(scene_gltf_is_model_path("B.GLB"));
    assert_false(scene_gltf_is_model_path("gltf"));
    assert_false(scene_gltf_is_model_path("scene.txt"));
    assert_false(scene_gltf_is_model_path(NULL));
}

int main(void)
{
#define T(name) cmocka_unit_test_setup_teardown(name, make_scratch, remove_scratch)
    const struct CMUnitTest tests[] = {
        T(test_statement_adds_materials_and_meshes),
        T(test_vertex_colours),
        T(test_statement_places_through_blocks),
        T(test_statement_errors),
        T(test_file_as_a_scene),
        T(test_orthographic_and_missing_cameras),
        T(test_model_paths),
    };
#undef T
    return cmocka_run_group_tests(tests, NULL, NULL);
}
