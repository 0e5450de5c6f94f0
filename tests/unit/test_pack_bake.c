/* test_pack_bake.c: placements baked into the world (core/pack_collect.c, "which
 * placements bake"): the packed records of a baked placement are its shapes moved by
 * its transform (quad corners and edges, a box's six quads, triangle corners with their
 * normals and uvs, sphere centres and radii, moving sphere centres), and the rule keeps
 * instances where it says: mirrors, stretched spheres, turned spheres whose material shows
 * their orientation, vertex normals and normal maps under more than a similarity,
 * volumes, objects whose copies would pass the budget, and everything with
 * pack_options.keep_instances. Scenes from text, their images given stand-in pixels. */
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
#include "packed_traverse.h"
#include "scene_parse.h"

#define BIT(tag) (1u << (tag))

/* Parses text into *s and gives every image 1x1 grey pixels (nothing is read from disk). */
static void load_text(const char *text, scene *s)
{
    rt_error error = {0};
    if (scene_load_string(text, "bake.txt", NULL, s, &error) != RT_OK)
        fail_msg("%s", error.message);
    for (int i = 0; i < s->image_count; i++) {
        s->images[i].width = 1;
        s->images[i].height = 1;
        s->images[i].pixels = malloc(4 * sizeof(float));
        assert_non_null(s->images[i].pixels);
        for (int k = 0; k < 4; k++)
            s->images[i].pixels[k] = 0.5f;
    }
}

/* Packs s with options (NULL: defaults); fails the test on an error. */
static void pack(const scene *s, const pack_options *options, packed_scene *packed)
{
    rt_error error = {0};
    if (pack_scene(s, options, packed, &error) != RT_OK)
        fail_msg("%s", error.message);
}

/* out = m p, with or without m's translation, in double. */
static void apply(const float m[3][4], const float p[3], bool translate, double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = (double)m[r][0] * p[0] + (double)m[r][1] * p[1] + (double)m[r][2] * p[2] + (translate ? m[r][3] : 0);
}

static double distance3(const double a[3], const float b[3])
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* The world primitive of type whose first point (corner, centre, first vertex) is within
 * 1e-4 of expected and, when edges is not NULL, whose two edges (quads: data[1], data[2])
 * are within 1e-5 of edges[0] and edges[1]; fails the test when there is none. */
static packed_primitive find_primitive(const packed_scene *packed, uint32_t type, const double expected[3],
                                       const double (*edges)[3])
{
    for (uint32_t slot = 0; slot < packed->primitive_count; slot++) {
        packed_primitive primitive = packed_primitive_at(packed, slot);
        if (primitive.type != type)
            continue;
        float first[3];
        if (type == PRIMITIVE_TRIANGLE)
            packed_vertex_position(packed, primitive.vertices[0], first);
        else
            memcpy(first, primitive.data[0], sizeof first);
        if (distance3(expected, first) < 1e-4
            && (edges == NULL || (distance3(edges[0], primitive.data[1]) < 1e-5
                                  && distance3(edges[1], primitive.data[2]) < 1e-5)))
            return primitive;
    }
    fail_msg("no packed primitive of type %u at (%g, %g, %g)", type, expected[0], expected[1], expected[2]);
    return (packed_primitive){0};
}

/* Every shape of a group turned, scaled uniformly and moved is baked: the records are
 * the shapes moved by the instance's transform, and nothing is instanced. */
static void baked_records_are_the_moved_shapes(void **state)
{
    (void)state;
    scene s;
    load_text("material grey lambertian 0.5 0.5 0.5\n"
              "group material grey {\n"
              "    rotate 1 2 3 40\n"
              "    scale 1.5\n"
              "    translate 4 -2 7\n"
              "    quad 0 0 0  1 0 0  0 2 0\n"
              "    box -1 -1 -1  1 2 3\n"
              "    triangle 0 0 1  1 0 1  0 1 1  normals 0 0 1  0.6 0 0.8  0 0.6 0.8  uvs 0 0  1 0  0.5 1\n"
              "    sphere 1 2 3 0.5\n"
              "    moving_sphere 0 0 0  0 1 0  0.25\n"
              "}\n",
              &s);
    assert_int_equal(s.instance_count, 1);
    const scene_instance *instance = &s.instances[0];
    const float (*m)[4] = instance->object_to_world;
    packed_scene packed;
    pack(&s, NULL, &packed);
    assert_int_equal(packed.instance_count, 0);
    assert_int_equal(packed.summary.primitive_types & BIT(PRIMITIVE_INSTANCE), 0);
    /* The inverse transpose of a rotation scaled by 1.5 is the rotation over 1.5. */
    const scene_object *object = &s.objects[instance->object];
    int quads = 0;
    for (int k = 0; k < object->shape_count; k++) {
        const scene_shape *shape = &s.shapes[object->first_shape + k];
        double first[3];
        apply(m, shape->points[0], true, first);
        if (shape->type == SHAPE_QUAD) {
            /* Corner moved, edges turned and scaled: the box's six quads too. */
            double edges[2][3];
            apply(m, shape->points[1], false, edges[0]);
            apply(m, shape->points[2], false, edges[1]);
            find_primitive(&packed, PRIMITIVE_QUAD, first, (const double (*)[3])edges);
            quads++;
        } else if (shape->type == SHAPE_TRIANGLE) {
            packed_primitive triangle = find_primitive(&packed, PRIMITIVE_TRIANGLE, first, NULL);
            assert_true(triangle.has_uvs);
            for (int c = 0; c < 3; c++) {
                double corner[3], normal[3];
                float position[3], stored_normal[3];
                apply(m, shape->points[c], true, corner);
                apply(m, shape->normals[c], false, normal);
                double length = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
                for (int i = 0; i < 3; i++)
                    normal[i] /= length;
                packed_vertex_position(&packed, triangle.vertices[c], position);
                assert_true(distance3(corner, position) < 1e-5);
                assert_true(packed_vertex_normal(&packed, triangle.vertices[c], stored_normal));
                assert_true(distance3(normal, stored_normal) < 1e-4);
                uint32_t v = triangle.vertices[c], uv_texel = packed.uv_offset + v / 2;
                assert_true(packed_float(&packed, uv_texel, (int)(2 * (v % 2))) == shape->uvs[c][0]);
                assert_true(packed_float(&packed, uv_texel, (int)(2 * (v % 2) + 1)) == shape->uvs[c][1]);
            }
        } else if (shape->type == SHAPE_SPHERE) {
            packed_primitive sphere = find_primitive(&packed, PRIMITIVE_SPHERE, first, NULL);
            assert_float_equal(sphere.data[0][3], 1.5 * shape->radius, 1e-6);
        } else {
            packed_primitive moving = find_primitive(&packed, PRIMITIVE_MOVING_SPHERE, first, NULL);
            double later[3];
            apply(m, shape->points[1], true, later);
            assert_true(distance3(later, moving.data[1]) < 1e-5);
            assert_float_equal(moving.data[0][3], 1.5 * shape->radius, 1e-6);
        }
    }
    assert_int_equal(quads, 7);
    assert_int_equal(packed.primitive_count, 10);   /* 7 quads, a triangle, two spheres */
    /* Shapes without a material of their own take the group's: concrete in the world. */
    for (uint32_t slot = 0; slot < packed.primitive_count; slot++)
        assert_int_equal(packed_primitive_at(&packed, slot).material, 0);
    packed_scene_free(&packed);
    scene_free(&s);
}

/* One scene and how many instances the packer must keep. */
typedef struct rule_case {
    const char *what;
    const char *text;
    pack_options options;
    uint32_t instances;
} rule_case;

#define MATERIALS                                                                                                      \
    "material grey lambertian 0.5 0.5 0.5\nmaterial glass dielectric 1.5\nmaterial lamp emissive 1 1 1\n"              \
    "texture map image \"map.png\"\ntexture board checker 0.5 0 0 0  1 1 1\ntexture mixed checker 0.5 @map 1 1 1\n"    \
    "material mapped lambertian @map\nmaterial checkered lambertian @board\nmaterial mixed_cells lambertian @mixed\n"  \
    "material bumpy lambertian 0.5 0.5 0.5 normal_map \"bumps.png\"\n"
#define BOX "    box 0 0 0  1 2 1 grey\n"
#define SMOOTH "    triangle 0 0 0  1 0 0  0 1 0  normals 0 0 1  0 0 1  0 0 1 grey\n"

/* Blocks of scene text, one statement a line. */
#define TURNED "group {\n rotate 0 1 0 30\n"
#define CORNELL "group {\n rotate 0 1 0 15\n translate 265 0 295\n"
#define SHEARED "group {\n matrix 1 0.5 0 0  0 1 0 0  0 0 2 0\n"
#define STRETCHED "group {\n scale 1 3 1\n"
#define BLOCK_TWICE "group block {\n translate 1 0 0\n" BOX "}\ninstance block {\n translate 5 0 0\n}\n"

static const rule_case rule_cases[] = {
    {"a box turned and moved (the Cornell box's blocks)", MATERIALS CORNELL BOX "}\n", {0}, 0},
    {"the same with keep_instances", MATERIALS CORNELL BOX "}\n", {.keep_instances = true}, 1},
    {"a box sheared", MATERIALS SHEARED BOX "}\n", {0}, 0},
    {"a box mirrored", MATERIALS "group {\n scale -1 1 1\n" BOX "}\n", {0}, 1},
    {"a sphere turned and scaled", MATERIALS "group {\n rotate 1 1 0 30\n scale 2\n sphere 0 0 0 1 grey\n}\n", {0}, 0},
    {"a sphere stretched", MATERIALS STRETCHED " sphere 0 0 0 1 grey\n}\n", {0}, 1},
    {"a moving sphere stretched", MATERIALS STRETCHED " moving_sphere 0 0 0  1 0 0  1 grey\n}\n", {0}, 1},
    {"a sphere with an image texture, turned", MATERIALS TURNED " sphere 0 0 0 1 mapped\n}\n", {0}, 1},
    {"a sphere with an image texture, scaled and moved",
     MATERIALS "group {\n scale 2\n translate 1 0 0\n sphere 0 0 0 1 mapped\n}\n", {0}, 0},
    {"a sphere with a normal map, turned", MATERIALS TURNED " sphere 0 0 0 1 bumpy\n}\n", {0}, 1},
    {"a sphere with a solid checker, turned", MATERIALS TURNED " sphere 0 0 0 1 checkered\n}\n", {0}, 0},
    {"a sphere with an image in a checker cell, turned", MATERIALS TURNED " sphere 0 0 0 1 mixed_cells\n}\n", {0}, 1},
    {"a quad with an image texture, sheared", MATERIALS SHEARED " quad 0 0 0  1 0 0  0 1 0 mapped\n}\n", {0}, 0},
    {"a quad with a normal map, stretched", MATERIALS STRETCHED " quad 0 0 0  1 0 0  0 1 0 bumpy\n}\n", {0}, 1},
    {"a quad with a normal map, turned", MATERIALS TURNED " quad 0 0 0  1 0 0  0 1 0 bumpy\n}\n", {0}, 0},
    {"vertex normals stretched", MATERIALS STRETCHED SMOOTH "}\n", {0}, 1},
    {"vertex normals turned and scaled", MATERIALS "group {\n rotate 0 0 1 20\n scale 3\n" SMOOTH "}\n", {0}, 0},
    {"a volume", MATERIALS "volume 0.5 1 1 1 {\n translate 1 0 0\n" BOX "}\n", {0}, 1},
    {"glass, moved: bakes like any other material", MATERIALS "group material glass {\n translate 1 0 0\n box 0 0 0  1 1 1\n}\n", {0}, 0},
    /* Six quads placed twice: one copy beyond the first, 6 primitives. */
    {"within the budget", MATERIALS BLOCK_TWICE, {.bake_budget = 6}, 0},
    /* Placed three times: 12 beyond the first. */
    {"over the budget", MATERIALS BLOCK_TWICE "instance block {\n translate 9 0 0\n}\n", {.bake_budget = 6}, 3},
    /* Emitters bake whatever the budget (they become lights); the identity placement is
     * copied in and counts for nothing. */
    {"emitters over the budget",
     MATERIALS "group block {\n quad 0 0 0  1 0 0  0 1 0 lamp\n}\n"
               "instance block {\n translate 5 0 0\n}\ninstance block {\n translate 9 0 0\n}\n",
     {.bake_budget = 1}, 0},
    {"emitters with keep_instances", MATERIALS TURNED " quad 0 0 0  1 0 0  0 1 0 lamp\n}\n",
     {.keep_instances = true}, 0},
};

static void the_rule_keeps_instances_where_it_says(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof rule_cases / sizeof rule_cases[0]; i++) {
        const rule_case *c = &rule_cases[i];
        scene s;
        load_text(c->text, &s);
        packed_scene packed;
        pack(&s, &c->options, &packed);
        if (packed.instance_count != c->instances)
            fail_msg("%s: %u instances, expected %u", c->what, packed.instance_count, c->instances);
        bool second_level = (packed.summary.primitive_types & BIT(PRIMITIVE_INSTANCE)) != 0;
        if (second_level != (c->instances > 0))
            fail_msg("%s: the summary %s instances", c->what, second_level ? "has" : "has no");
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

/* Adds a mesh of triangle_count small triangles (one material-less object) and places
 * it placements times, each moved along x. */
static void add_placed_mesh(scene *s, int triangle_count, int placements)
{
    scene_mesh mesh = {.default_material = -1, .vertex_count = 3 * triangle_count, .triangle_count = triangle_count};
    mesh.positions = malloc(9 * (size_t)triangle_count * sizeof(float));
    mesh.indices = malloc(3 * (size_t)triangle_count * sizeof(uint32_t));
    assert_true(mesh.positions != NULL && mesh.indices != NULL);
    for (int t = 0; t < triangle_count; t++) {
        float x = (float)(t % 256), y = (float)(t / 256);
        const float corners[9] = {x, y, 0, x + 0.5f, y, 0, x, y + 0.5f, 0};
        memcpy(mesh.positions + 9 * (size_t)t, corners, sizeof corners);
        for (int k = 0; k < 3; k++)
            mesh.indices[3 * (size_t)t + k] = (uint32_t)(3 * t + k);
    }
    int mesh_index = scene_add_mesh(s, &mesh);
    scene_object object = {.mesh = mesh_index};
    int object_index = scene_add_object(s, &object);
    assert_true(mesh_index >= 0 && object_index >= 0);
    for (int p = 0; p < placements; p++) {
        scene_instance instance = {.object = object_index, .material = -1};
        scene_identity_transform(instance.object_to_world);
        instance.object_to_world[0][3] = 300.0f * (float)(p + 1);
        assert_true(scene_add_instance(s, &instance) >= 0);
    }
}

/* The default budget, 262,144 primitives beyond the first copy: a mesh of 131,072
 * triangles placed three times bakes (exactly at the budget), one of 131,073 stays
 * instanced; a mesh placed once bakes however large. */
static void the_default_budget(void **state)
{
    (void)state;
    const struct {
        int triangles, placements;
        uint32_t instances, stored_triangles;
    } cases[] = {
        {PACK_DEFAULT_BAKE_BUDGET / 2, 3, 0, 3 * (PACK_DEFAULT_BAKE_BUDGET / 2)},
        {PACK_DEFAULT_BAKE_BUDGET / 2 + 1, 3, 3, PACK_DEFAULT_BAKE_BUDGET / 2 + 1},
        {PACK_DEFAULT_BAKE_BUDGET + 1000, 1, 0, PACK_DEFAULT_BAKE_BUDGET + 1000},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        scene s;
        scene_defaults(&s);
        add_placed_mesh(&s, cases[i].triangles, cases[i].placements);
        packed_scene packed;
        pack(&s, NULL, &packed);
        if (packed.instance_count != cases[i].instances || packed.triangle_count != cases[i].stored_triangles)
            fail_msg("%d triangles placed %d times: %u instances, %u triangles stored; expected %u, %u",
                     cases[i].triangles, cases[i].placements, packed.instance_count, packed.triangle_count,
                     cases[i].instances, cases[i].stored_triangles);
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

/* In a scene of quads alone (boxes and quads, their placements baked: one BVH level),
 * quad k's shape record is at shape_offset + 3k, which the tracer's quad-only variant
 * relies on instead of reading the record (glsl/traverse.glsl leaf_record). */
static void quads_alone_keep_their_shapes_in_slot_order(void **state)
{
    (void)state;
    scene s;
    load_text("material grey lambertian 0.5 0.5 0.5\n"
              "material lamp emissive 4 4 4\n"
              "quad -1 0 -1  2 0 0  0 0 2 grey\n"
              "quad 0 2 0  0.5 0 0  0 0 0.5 lamp\n"
              "group material grey {\n"
              "    rotate 0 1 0 15\n"
              "    translate 0.3 0 0.2\n"
              "    box 0 0 0  0.5 1 0.5\n"
              "}\n"
              "group material grey {\n"
              "    translate -0.4 0 -0.3\n"
              "    box 0 0 0  0.3 0.6 0.3\n"
              "}\n",
              &s);
    packed_scene packed;
    pack(&s, NULL, &packed);
    assert_int_equal(packed.instance_count, 0);
    assert_int_equal(packed.primitive_count, 14);   /* two quads, two boxes of six */
    assert_int_equal(packed.shape_texels, 3 * 14);
    for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
        const uint32_t *record = &packed.texels[4 * (packed.primitive_offset + slot)];
        assert_int_equal(record[3], PRIMITIVE_RECORD_TAG + PRIMITIVE_QUAD);
        assert_int_equal(record[0], packed.shape_offset + PACKED_QUAD_TEXELS * slot);
    }
    packed_scene_free(&packed);
    scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(baked_records_are_the_moved_shapes),
        cmocka_unit_test(quads_alone_keep_their_shapes_in_slot_order),
        cmocka_unit_test(the_rule_keeps_instances_where_it_says),
        cmocka_unit_test(the_default_budget),
    };
    return cmocka_run_group_tests_name("pack_bake", tests, NULL, NULL);
}
