/* test_pack_lights.c: the packed light records (pack.h, core/packed_layout.h "lights"):
 * emissive world spheres become lights with power-proportional choice probabilities, the
 * emitters of placed objects become lights too, and scenes of more than
 * LIGHT_LOCAL_CHOICE_MAX lights get a light tree whose trails lead to each light. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack.h"
#include "scene_parse.h"
#include "packed_traverse.h"
#include "support.h"
#include "pack_test_scenes.h"
#include "tracer_interface.h"

/* Every emissive world sphere is a light, knows its light index, and the selection
 * probabilities (cdf steps) are proportional to emission luminance x area. */
static void emissive_spheres_become_lights(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 60, 40);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    int emissive = 0;
    double total_power = 0;
    for (int i = 0; i < s.sphere_count; i++)
        if (s.materials[s.spheres[i].material].type == MATERIAL_EMISSIVE) {
            emissive++;
            const float *e = s.materials[s.spheres[i].material].emission;
            total_power += (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]) * s.spheres[i].radius * s.spheres[i].radius;
        }
    assert_int_equal(packed.light_count, emissive);
    float previous = 0;
    for (uint32_t l = 0; l < packed.light_count; l++) {
        uint32_t base = packed.light_offset + l * PACKED_LIGHT_STRIDE;
        assert_int_equal(packed_uint(&packed, base, 0), LIGHT_SPHERE);
        uint32_t slot = packed_uint(&packed, base, 1);
        packed_primitive primitive = packed_primitive_at(&packed, slot);
        /* Area lights come first and in slot order: the shader's binary search. */
        assert_true(l < packed.area_light_count);
        if (l > 0)
            assert_true(slot > packed_uint(&packed, base - PACKED_LIGHT_STRIDE, 1));
        const float *e = s.materials[primitive.material].emission;
        double power = (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]) * primitive.data[0][3] * primitive.data[0][3];
        float cdf = packed_float(&packed, base + 1, 3);
        assert_float_equal(cdf - previous, power / total_power, 1e-5);
        previous = cdf;
    }
    assert_float_equal(previous, 1.0, 1e-6);
    packed_scene_free(&packed);
    scene_free(&s);
}

/* A scene of many lights gets the light tree section (packed_layout.h "light tree"): the
 * header names it, each light's trail, followed through the packed nodes from the root as
 * the shader follows it (glsl/lights.glsl walk_light_tree), ends at that light's leaf, and
 * the root's intensity is the lights' (luminance x area / 4 for spheres). A scene of at
 * most LIGHT_LOCAL_CHOICE_MAX lights has none, and no trails. */
static void many_lights_get_a_light_tree(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 60, 40);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_true(packed.light_count > LIGHT_LOCAL_CHOICE_MAX);
    assert_int_not_equal(packed.light_tree_offset, PACKED_NONE);
    assert_int_equal(packed_uint(&packed, PACKED_HEADER_LIGHT_TREE_OFFSET / 4, PACKED_HEADER_LIGHT_TREE_OFFSET % 4),
                     packed.light_tree_offset);
    assert_true(packed.light_tree_offset + (2 * packed.light_count - 1) * PACKED_LIGHT_TREE_NODE_STRIDE
                <= packed.texel_count);
    double intensity = 0;
    for (uint32_t l = 0; l < packed.light_count; l++) {
        uint32_t base = packed.light_offset + l * PACKED_LIGHT_STRIDE;
        intensity += packed_float(&packed, base + 2, 3) * 0.25;   /* luminance x area, a sphere's quarter */
        uint32_t trail = packed_uint(&packed, base + 4, 1);
        uint32_t child = packed_uint(&packed, packed.light_tree_offset + 2, 2);
        int level = 0;
        for (; level < LIGHT_TREE_MAX_DEPTH && !(child & LIGHT_TREE_LEAF); level++) {
            uint32_t taken = child + ((trail >> level) & 1u);
            child = packed_uint(&packed, packed.light_tree_offset + taken * PACKED_LIGHT_TREE_NODE_STRIDE + 2, 2);
        }
        assert_true(child & LIGHT_TREE_LEAF);
        assert_int_equal(child & ~LIGHT_TREE_LEAF, l);
        assert_true(level <= (int)packed.light_tree_depth);
    }
    assert_float_equal(packed_float(&packed, packed.light_tree_offset, 3), intensity, 1e-4 * intensity);
    assert_float_equal(packed_float(&packed, packed.light_tree_offset + 1, 3), 0, 0);   /* no sun, no sky */
    packed_scene_free(&packed);
    scene_free(&s);

    random_scene(&s, 6, 40);
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_true(packed.light_count <= LIGHT_LOCAL_CHOICE_MAX);
    assert_int_equal(packed.light_tree_offset, PACKED_NONE);
    for (uint32_t l = 0; l < packed.light_count; l++)
        assert_int_equal(packed_uint(&packed, packed.light_offset + l * PACKED_LIGHT_STRIDE + 4, 1), 0);
    packed_scene_free(&packed);
    scene_free(&s);
}

/* Spots are one-sided in the light tree (packed_layout.h "light tree", texel 2 .w): a
 * spot's leaf and a node of spots alone carry LIGHT_TREE_ONE_SIDED, with the spot's
 * direction and outer cone; a node with a point light under it does not. */
static void spots_are_one_sided_in_the_tree(void **state)
{
    (void)state;
    char text[2048] = "";
    for (int k = 0; k < 10; k++) {
        char line[160];
        snprintf(line, sizeof line, "light spot %d 3 0 at %d 0 0 cone 10 20\n", 4 * k, 4 * k);
        strcat(text, line);
    }
    strcat(text, "light point 100 3 0\n");
    scene s;
    rt_error error = {0};
    assert_int_equal(scene_load_string(text, "spots", NULL, &s, &error), RT_OK);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.light_count, 11);
    assert_int_not_equal(packed.light_tree_offset, PACKED_NONE);
    uint32_t one_sided_inner = 0;
    for (uint32_t n = 0; n < 2 * packed.light_count - 1; n++) {
        uint32_t base = packed.light_tree_offset + n * PACKED_LIGHT_TREE_NODE_STRIDE;
        uint32_t child = packed_uint(&packed, base + 2, 2), flags = packed_uint(&packed, base + 2, 3);
        float cos_spread = packed_float(&packed, base + 2, 1);
        if (child & LIGHT_TREE_LEAF) {
            uint32_t light = child & ~LIGHT_TREE_LEAF;
            bool spot = packed_uint(&packed, packed.light_offset + light * PACKED_LIGHT_STRIDE, 0) == LIGHT_SPOT;
            assert_int_equal(flags, spot ? LIGHT_TREE_ONE_SIDED : 0);
            assert_float_equal(cos_spread, spot ? cosf(20 * (float)M_PI / 180) : -1, 1e-6);
        } else {
            one_sided_inner += flags == LIGHT_TREE_ONE_SIDED;
            if (flags == LIGHT_TREE_ONE_SIDED)
                assert_true(cos_spread >= cosf(20 * (float)M_PI / 180) - 1e-4f);   /* all aimed straight down */
        }
    }
    assert_true(one_sided_inner >= 4);   /* the subtrees of spots alone */
    /* The root holds the point light: two-sided, every way. */
    assert_int_equal(packed_uint(&packed, packed.light_tree_offset + 2, 3), 0);
    packed_scene_free(&packed);
    scene_free(&s);
}

/* Emitters of placed objects become lights: the placement is baked into the world (the
 * object's shapes moved by its transform) when something of it emits under it, even
 * with keep_instances, except spheres under more than a similarity, which stay
 * instanced. */
static void placed_emitters_become_lights(void **state)
{
    (void)state;
    scene s;
    scene_defaults(&s);
    add_material(&s, "grey", MATERIAL_LAMBERTIAN, 0.5f, 0.5f, 0.5f);
    add_material(&s, "glow", MATERIAL_EMISSIVE, 1, 1, 1);
    /* Object 0: an emissive quad and a grey triangle. Object 1: an emissive sphere.
     * Object 2: a triangle without a material (the placement's). */
    scene_shape quad = {.type = SHAPE_QUAD, .material = 1, .points = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}}};
    scene_shape triangle = {.type = SHAPE_TRIANGLE, .material = 0, .points = {{0, 1, 0}, {1, 1, 0}, {0, 1, 1}}};
    scene_shape sphere = {.type = SHAPE_SPHERE, .material = 1, .radius = 0.5f, .points = {{1, 2, 3}}};
    scene_shape bare = {.type = SHAPE_TRIANGLE, .material = -1, .points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
    scene_object objects[3] = {{.first_shape = 0, .shape_count = 2, .mesh = -1},
                               {.first_shape = 2, .shape_count = 1, .mesh = -1},
                               {.first_shape = 3, .shape_count = 1, .mesh = -1}};
    assert_true(scene_add_shape(&s, &quad) >= 0 && scene_add_shape(&s, &triangle) >= 0);
    assert_true(scene_add_shape(&s, &sphere) >= 0 && scene_add_shape(&s, &bare) >= 0);
    for (int o = 0; o < 3; o++)
        assert_true(scene_add_object(&s, &objects[o]) >= 0);
    /* The quad's object stretched and turned: baked. */
    scene_instance stretched = {.object = 0, .material = -1,
                                .object_to_world = {{0, -2, 0, 5}, {3, 0, 0, 6}, {0, 0, 1, 7}}};
    /* The sphere turned, and moved and scaled by 2: baked (a similarity keeps it a
     * sphere). Stretched: stays an instance. */
    scene_instance turned = {.object = 1, .material = -1,
                             .object_to_world = {{0, -1, 0, 0}, {1, 0, 0, 0}, {0, 0, 1, 0}}};
    scene_instance scaled = {.object = 1, .material = -1,
                             .object_to_world = {{2, 0, 0, 10}, {0, 2, 0, 0}, {0, 0, 2, 0}}};
    scene_instance oval = {.object = 1, .material = -1,
                           .object_to_world = {{1, 0, 0, 0}, {0, 3, 0, 0}, {0, 0, 1, 0}}};
    /* The bare triangle glows only under this placement's material: baked; grey: not,
     * with keep_instances. */
    scene_instance glowing = {.object = 2, .material = 1,
                              .object_to_world = {{1, 0, 0, 0}, {0, 1, 0, 20}, {0, 0, 1, 0}}};
    scene_instance grey = {.object = 2, .material = 0,
                           .object_to_world = {{1, 0, 0, 0}, {0, 1, 0, 30}, {0, 0, 1, 0}}};
    scene_instance placements[6] = {stretched, turned, scaled, oval, glowing, grey};
    for (int i = 0; i < 6; i++)
        assert_true(scene_add_instance(&s, &placements[i]) >= 0);
    packed_scene packed;
    pack_options options = {.keep_instances = true};
    assert_int_equal(pack_scene(&s, &options, &packed, NULL), RT_OK);
    assert_int_equal(packed.instance_count, 2);   /* oval and grey */
    assert_int_equal(packed.light_count, 4);      /* the quad, both spheres, the glowing triangle */
    bool seen_quad = false, seen_sphere = false, seen_turned = false, seen_triangle = false;
    for (uint32_t l = 0; l < packed.light_count; l++) {
        uint32_t base = packed.light_offset + l * PACKED_LIGHT_STRIDE;
        packed_primitive light = packed_primitive_at(&packed, packed_uint(&packed, base, 1));
        assert_int_equal(light.material, 1);
        if (light.type == PRIMITIVE_QUAD) {
            /* Corner (0,0,0) -> (5,6,7); edges (1,0,0) -> (0,3,0) and (0,0,1) -> (0,0,1). */
            const float expected[3][3] = {{5, 6, 7}, {0, 3, 0}, {0, 0, 1}};
            for (int k = 0; k < 3; k++)
                for (int i = 0; i < 3; i++)
                    assert_float_equal(light.data[k][i], expected[k][i], 1e-6);
            seen_quad = true;
        } else if (light.type == PRIMITIVE_SPHERE && light.data[0][3] == 1) {
            /* Centre (1, 2, 3) scaled by 2 and moved by (10, 0, 0); radius 0.5 x 2. */
            assert_float_equal(light.data[0][0], 12, 1e-6);
            assert_float_equal(light.data[0][1], 4, 1e-6);
            assert_float_equal(light.data[0][2], 6, 1e-6);
            seen_sphere = true;
        } else if (light.type == PRIMITIVE_SPHERE) {
            /* Turned a quarter about z: (1, 2, 3) -> (-2, 1, 3), radius kept. */
            assert_float_equal(light.data[0][0], -2, 1e-6);
            assert_float_equal(light.data[0][1], 1, 1e-6);
            assert_float_equal(light.data[0][2], 3, 1e-6);
            assert_float_equal(light.data[0][3], 0.5, 1e-6);
            seen_turned = true;
        } else {
            assert_int_equal(light.type, PRIMITIVE_TRIANGLE);
            assert_float_equal(light.data[0][1], 20, 1e-6);
            seen_triangle = true;
        }
    }
    assert_true(seen_quad && seen_sphere && seen_turned && seen_triangle);
    /* The baked copies are hit where the placed shapes are: the quad's middle, (0.5, 0,
     * 0.5) in the object's coordinates, is (5, 7.5, 7.5) in the world, on the plane x = 5. */
    float origin[3] = {20, 7.5f, 7.5f}, direction[3] = {-1, 0, 0};
    packed_hit hit;
    assert_true(packed_intersect_nearest(&packed, origin, direction, 0, INFINITY, &hit));
    assert_float_equal(hit.t, 15, 1e-4);
    assert_int_equal(hit.instance, PACKED_NONE);
    packed_scene_free(&packed);
    /* By default the grey triangle is baked too (placed once, it costs no memory), and is
     * no light; the oval sphere stays an instance. */
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.instance_count, 1);
    assert_int_equal(packed.light_count, 4);
    packed_scene_free(&packed);
    scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(emissive_spheres_become_lights),
        cmocka_unit_test(placed_emitters_become_lights),
        cmocka_unit_test(many_lights_get_a_light_tree),
        cmocka_unit_test(spots_are_one_sided_in_the_tree),
    };
    return cmocka_run_group_tests_name("pack_lights", tests, NULL, NULL);
}
