/* test_pack.c: the packed scene (pack.h): header and record layout round trip, BVH leaf
 * order, and the packed traversal (packed_traverse.h: the shader's algorithm, in C)
 * against brute force. */
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
#include "tracer_interface.h"
#include "scene_parse.h"
#include "packed_traverse.h"
#include "support.h"
#include "pack_test_scenes.h"

static void header_and_materials_round_trip(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 37, 1);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed_uint(&packed, 0, 0), PACKED_MAGIC);
    assert_int_equal(packed_uint(&packed, 0, 1), PACKED_LAYOUT_VERSION);
    assert_int_equal(packed_uint(&packed, 0, 2), packed.material_offset);
    assert_int_equal(packed_uint(&packed, 0, 3), 5); /* four materials and the default */
    assert_int_equal(packed_uint(&packed, 1, 0), packed.primitive_offset);
    assert_int_equal(packed_uint(&packed, 1, 1), 37);
    assert_int_equal(packed_uint(&packed, 1, 2), packed.node_offset);
    assert_int_equal(packed_uint(&packed, 1, 3), packed.node_count);
    assert_int_equal(packed_uint(&packed, 2, 0), packed.instance_offset);
    assert_int_equal(packed_uint(&packed, 2, 1), 0);
    assert_int_equal(packed_uint(&packed, 2, 2), packed.info_offset);
    assert_int_equal(packed_uint(&packed, 2, 3), 4);
    assert_int_equal(packed.material_offset, PACKED_HEADER_TEXELS);
    assert_int_equal(packed.primitive_offset, packed.material_offset + 5 * PACKED_MATERIAL_STRIDE);
    /* Spheres only: 37 records, their info (four to a texel), no shapes, no vertices. */
    assert_int_equal(packed.info_offset, packed.primitive_offset + 37 * PACKED_PRIMITIVE_STRIDE);
    assert_int_equal(packed.shape_offset, packed.info_offset + (37 + 3) / 4);
    assert_int_equal(packed.shape_texels, 0);
    assert_int_equal(packed.vertex_offset, packed.shape_offset);
    assert_int_equal(packed.vertex_count, 0);
    assert_int_equal(packed.uv_offset, packed.vertex_offset);
    /* Nodes after padding to 2 mod 4 texels: sibling pairs (odd nodes) on 64 bytes. */
    assert_true(packed.node_offset >= packed.uv_offset && packed.node_offset < packed.uv_offset + 4);
    assert_int_equal(packed.node_offset % 4, 2);
    assert_int_equal(packed.light_offset, packed.node_offset + packed.node_count * PACKED_NODE_STRIDE);
    assert_int_equal(packed_uint(&packed, 4, 0), packed.light_offset);
    assert_int_equal(packed_uint(&packed, 4, 1), packed.light_count);
    assert_int_equal(packed_uint(&packed, 4, 3), packed.area_light_count);
    assert_int_equal(packed_uint(&packed, 5, 0), packed.shape_offset);
    assert_int_equal(packed_uint(&packed, 5, 1), packed.vertex_offset);
    assert_int_equal(packed_uint(&packed, 5, 2), packed.uv_offset);
    assert_int_equal(packed_uint(&packed, 5, 3), packed.vertex_count);
    /* A sphere's record is its centre and radius; its info its type and material. */
    for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
        uint32_t info = packed_uint(&packed, packed.info_offset + slot / 4, (int)(slot % 4));
        assert_int_equal(info >> PRIMITIVE_INFO_TYPE_SHIFT, PRIMITIVE_SPHERE);
        assert_true((info & PRIMITIVE_INFO_MATERIAL_MASK) < 4);
        assert_true(packed_float(&packed, packed.primitive_offset + slot, 3) > 0);
    }
    /* More than LIGHT_LOCAL_CHOICE_MAX lights: the light tree's 2n - 1 nodes follow them. */
    assert_true(packed.light_count > LIGHT_LOCAL_CHOICE_MAX);
    assert_int_equal(packed.light_tree_offset, packed.light_offset + packed.light_count * PACKED_LIGHT_STRIDE);
    assert_int_equal(packed_uint(&packed, 6, 1), packed.light_tree_offset);
    /* Still spheres in one level: the threaded walk's lists follow (packed_layout.h). */
    uint32_t after_tree = packed.light_tree_offset + (2 * packed.light_count - 1) * PACKED_LIGHT_TREE_NODE_STRIDE;
    assert_int_equal(packed.threaded_offset, after_tree);
    assert_int_equal(packed_uint(&packed, 6, 2), packed.threaded_offset);
    assert_int_equal(packed_uint(&packed, 6, 3), packed.threaded_items);
    assert_int_equal(packed.texel_count,
                     after_tree + packed.threaded_items * PACKED_THREADED_ORDERS * PACKED_THREADED_ITEM_STRIDE);
    /* The default material is grey Lambertian. */
    uint32_t default_base = packed.material_offset + 4 * PACKED_MATERIAL_STRIDE;
    assert_int_equal(packed_uint(&packed, default_base, 0), MATERIAL_LAMBERTIAN);
    assert_true(packed_float(&packed, default_base, 1) == 0.5f);
    for (int i = 0; i < s.material_count; i++) {
        const scene_material *m = &s.materials[i];
        uint32_t base = packed.material_offset + (uint32_t)i * PACKED_MATERIAL_STRIDE;
        assert_int_equal(packed_uint(&packed, base, 0), m->type);
        for (int c = 0; c < 3; c++) {
            assert_true(packed_float(&packed, base, 1 + c) == m->albedo[c]);
            assert_true(packed_float(&packed, base + 1, c) == m->emission[c]);
        }
        if (m->type != MATERIAL_METAL)   /* texel 1 .w: the metal's fuzz, else the light group */
            assert_int_equal(packed_uint(&packed, base + 1, 3), (uint32_t)m->light_group);
        else
            assert_true(packed_float(&packed, base + 1, 3) == m->fuzz);
        assert_true(packed_float(&packed, base + 2, 0) == m->index_of_refraction);
        assert_int_equal(packed_uint(&packed, base + 2, 1), PACKED_NONE); /* no textures */
    }
    packed_scene_free(&packed);
    scene_free(&s);
}

static void every_sphere_packed_once_in_leaf_order(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 500, 2);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    int seen[500] = {0};
    for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
        packed_primitive primitive = packed_primitive_at(&packed, slot);
        assert_int_equal(primitive.type, PRIMITIVE_SPHERE);
        int match = -1;
        for (int i = 0; i < s.sphere_count; i++)
            if (memcmp(primitive.data[0], s.spheres[i].center, 3 * sizeof(float)) == 0
                && primitive.data[0][3] == s.spheres[i].radius)
                match = i;
        assert_true(match >= 0);
        assert_int_equal(primitive.material, s.spheres[match].material);
        seen[match]++;
    }
    for (int i = 0; i < 500; i++)
        assert_int_equal(seen[i], 1);
    /* Leaves cover the slots exactly once; children stay inside the node array. */
    int covered[500] = {0};
    for (uint32_t n = 0; n < packed.node_count; n++) {
        uint32_t base = packed.node_offset + n * PACKED_NODE_STRIDE;
        uint32_t first = packed_uint(&packed, base, 3), count = packed_uint(&packed, base + 1, 3);
        if (count == 0) {
            assert_true(first + 1 < packed.node_count);
            assert_true(first > n);
        } else {
            for (uint32_t k = first; k < first + count; k++)
                covered[k]++;
        }
    }
    for (int i = 0; i < 500; i++)
        assert_int_equal(covered[i], 1);
    packed_scene_free(&packed);
    scene_free(&s);
}

static void packed_traversal_matches_brute_force(void **state)
{
    (void)state;
    for (uint64_t seed = 10; seed < 14; seed++) {
        scene s;
        random_scene(&s, 50 + (int)seed * 40, seed);
        packed_scene packed;
        assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
        int hits = 0;
        for (int r = 0; r < 4000; r++) {
            double origin[3], direction[3];
            float origin_f[3], direction_f[3];
            random_ray(r, origin, direction, origin_f, direction_f);
            double best = INFINITY;
            uint32_t best_slot = UINT32_MAX;
            for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
                packed_primitive primitive = packed_primitive_at(&packed, slot);
                double t = sphere_hit(primitive.data[0], origin, direction);
                if (t < best) {
                    best = t;
                    best_slot = slot;
                }
            }
            packed_hit found;
            bool hit_something = packed_intersect_nearest(&packed, origin_f, direction_f, 0, INFINITY, &found);
            uint32_t slot = hit_something ? found.primitive : UINT32_MAX;
            float t_hit = found.t;
            if (best_slot == UINT32_MAX) {
                assert_int_equal(slot, UINT32_MAX);
                continue;
            }
            hits++;
            assert_int_not_equal(slot, UINT32_MAX);
            assert_true(fabs(t_hit - best) <= 1e-4 * (1 + best));
            if (slot != best_slot) {
                /* Only a tie within float precision may pick another sphere. */
                double other = sphere_hit(packed_primitive_at(&packed, slot).data[0], origin, direction);
                assert_true(fabs(other - best) <= 1e-4 * (1 + best));
            }
        }
        assert_true(hits > 500);
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

static void empty_scene_packs_and_misses(void **state)
{
    (void)state;
    scene s;
    scene_defaults(&s);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.primitive_count, 0);
    assert_int_equal(packed.node_count, 0);
    /* The header and the default material, then the padding that puts the (empty) node
     * section at 2 mod 4 texels (pack.c, plan_layout). */
    uint32_t texels = PACKED_HEADER_TEXELS + PACKED_MATERIAL_STRIDE;
    assert_int_equal(packed.texel_count, texels + (6 - texels % 4) % 4);
    float origin[3] = {0, 0, 0}, direction[3] = {0, 0, 1};
    packed_hit hit;
    assert_false(packed_intersect_nearest(&packed, origin, direction, 0, INFINITY, &hit));
    packed_scene_free(&packed);
}


/* ---- two-level scenes: instances, triangles, quads, moving spheres, a mesh ---------- */

/* A rotation about a random axis, a scale (non-uniform unless uniform), a translation. */
static void random_placement(float m[3][4], bool uniform)
{
    double axis[3] = {random_unit() - 0.5, random_unit() - 0.5, random_unit() - 0.5};
    double length = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (int i = 0; i < 3; i++)
        axis[i] /= length;
    double angle = random_unit() * 6.28, c = cos(angle), s = sin(angle), k = 1 - c;
    double r[3][3] = {
        {c + axis[0] * axis[0] * k, axis[0] * axis[1] * k - axis[2] * s, axis[0] * axis[2] * k + axis[1] * s},
        {axis[1] * axis[0] * k + axis[2] * s, c + axis[1] * axis[1] * k, axis[1] * axis[2] * k - axis[0] * s},
        {axis[2] * axis[0] * k - axis[1] * s, axis[2] * axis[1] * k + axis[0] * s, c + axis[2] * axis[2] * k},
    };
    double scale[3] = {0.5 + random_unit(), 0.5 + random_unit(), 0.5 + random_unit()};
    if (uniform)
        scale[1] = scale[2] = scale[0];
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 3; column++)
            m[row][column] = (float)(r[row][column] * scale[column]);
        m[row][3] = (float)(random_unit() * 16 - 8);
    }
}

static void random_rotation_scale(float m[3][4])
{
    random_placement(m, false);
}

/* Object-space hit of one scene shape, in double; direction need not be unit length. */
static double shape_hit(const scene_shape *shape, double time, const double o[3], const double d[3])
{
    if (shape->type == SHAPE_SPHERE || shape->type == SHAPE_MOVING_SPHERE) {
        double center[3], oc[3], a = 0, b = 0, c = 0;
        for (int i = 0; i < 3; i++) {
            center[i] = shape->points[0][i];
            if (shape->type == SHAPE_MOVING_SPHERE)
                center[i] += time * (shape->points[1][i] - shape->points[0][i]);
            oc[i] = o[i] - center[i];
            a += d[i] * d[i];
            b += oc[i] * d[i];
            c += oc[i] * oc[i];
        }
        c -= (double)shape->radius * shape->radius;
        double discriminant = b * b - a * c;
        if (discriminant < 0)
            return INFINITY;
        double t0 = (-b - sqrt(discriminant)) / a, t1 = (-b + sqrt(discriminant)) / a;
        return t0 > 0 ? t0 : t1 > 0 ? t1 : INFINITY;
    }
    double corner[3], e1[3], e2[3];
    for (int i = 0; i < 3; i++) {
        corner[i] = shape->points[0][i];
        e1[i] = shape->type == SHAPE_TRIANGLE ? shape->points[1][i] - shape->points[0][i] : shape->points[1][i];
        e2[i] = shape->type == SHAPE_TRIANGLE ? shape->points[2][i] - shape->points[0][i] : shape->points[2][i];
    }
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double denominator = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    if (fabs(denominator) < 1e-30)
        return INFINITY;
    double t = (n[0] * (corner[0] - o[0]) + n[1] * (corner[1] - o[1]) + n[2] * (corner[2] - o[2])) / denominator;
    if (!(t > 0))
        return INFINITY;
    double p[3], w[3];
    for (int i = 0; i < 3; i++)
        p[i] = o[i] + t * d[i] - corner[i];
    /* Barycentric-like coordinates on the plane: solve p = a e1 + b e2. */
    double e11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], e22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    double e12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    double p1 = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2], p2 = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
    double det = e11 * e22 - e12 * e12;
    double a = (p1 * e22 - p2 * e12) / det, b = (p2 * e11 - p1 * e12) / det;
    (void)w;
    bool inside = shape->type == SHAPE_QUAD ? (a >= 0 && a <= 1 && b >= 0 && b <= 1) : (a >= 0 && b >= 0 && a + b <= 1);
    return inside ? t : INFINITY;
}

/* What brute_force_of() looks at. */
typedef enum brute_force_set {
    ALL_SHAPES,       /* everything */
    BLOCKERS,         /* all but one world sphere (a shadow ray's light) and volume instances */
    VOLUME_SHAPES,    /* the shapes of volume instances */
} brute_force_set;

/* Brute force over the scene in double: world spheres, and every instance's shapes and
 * mesh triangles in object coordinates, of the set (skip_sphere: the world sphere that
 * BLOCKERS leaves out). Returns the nearest t (INFINITY: none). */
static double brute_force_of(const scene *s, double time, const double o[3], const double d[3], brute_force_set set,
                             int skip_sphere)
{
    double best = INFINITY;
    for (int i = 0; i < s->sphere_count && set != VOLUME_SHAPES; i++) {
        if (set == BLOCKERS && i == skip_sphere)
            continue;
        scene_shape shape = {.type = SHAPE_SPHERE, .radius = s->spheres[i].radius};
        memcpy(shape.points[0], s->spheres[i].center, sizeof shape.points[0]);
        best = fmin(best, shape_hit(&shape, time, o, d));
    }
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        if ((set == BLOCKERS && instance->volume) || (set == VOLUME_SHAPES && !instance->volume))
            continue;
        /* Invert the affine placement in double. */
        const float (*m)[4] = instance->object_to_world;
        double a[3][3], inverse[3][3];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                a[r][c] = m[r][c];
        double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                     + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
                inverse[r][c] = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
            }
        double object_origin[3], object_direction[3];
        for (int r = 0; r < 3; r++) {
            object_origin[r] = 0;
            object_direction[r] = 0;
            for (int c = 0; c < 3; c++) {
                object_origin[r] += inverse[r][c] * (o[c] - m[c][3]);
                object_direction[r] += inverse[r][c] * d[c];
            }
        }
        const scene_object *object = &s->objects[instance->object];
        if (object->mesh >= 0) {
            const scene_mesh *mesh = &s->meshes[object->mesh];
            for (int t = 0; t < mesh->triangle_count; t++) {
                scene_shape shape = {.type = SHAPE_TRIANGLE};
                for (int k = 0; k < 3; k++)
                    memcpy(shape.points[k], mesh->positions + 3 * mesh->indices[3 * t + k], 3 * sizeof(float));
                best = fmin(best, shape_hit(&shape, time, object_origin, object_direction));
            }
        }
        for (int k = 0; k < object->shape_count; k++)
            best = fmin(best, shape_hit(&s->shapes[object->first_shape + k], time, object_origin, object_direction));
    }
    return best;
}

/* The nearest t of anything in the scene (INFINITY: none). */
static double brute_force(const scene *s, double time, const double o[3], const double d[3])
{
    return brute_force_of(s, time, o, d, ALL_SHAPES, -1);
}

/* A random shape within a few units of the origin. */
static scene_shape random_shape(int type)
{
    scene_shape shape = {.type = type, .material = (int)(random_unit() * 3) - 1};
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            shape.points[k][i] = (float)(random_unit() * 6 - 3);
    if (type == SHAPE_QUAD || type == SHAPE_MOVING_SPHERE)
        for (int k = 1; k < 3; k++)
            for (int i = 0; i < 3; i++)
                shape.points[k][i] *= 0.3f;
    shape.radius = (float)(0.1 + random_unit());
    return shape;
}

/* similar: object 1's placements are similarities (its spheres can be baked), else
 * stretched (they cannot). */
static void instanced_scene_placed(scene *s, uint64_t seed, bool similar)
{
    random_scene(s, 40, seed);
    /* Object 0: mixed shapes, placed with the identity (copied into the top level). */
    /* Object 1: mixed shapes, placed three times with transforms, the second glass. */
    /* Object 2: a mesh (a random triangle soup sharing vertices), placed twice. */
    for (int o = 0; o < 2; o++) {
        scene_object object = {.first_shape = s->shape_count, .mesh = -1};
        for (int k = 0; k < 24; k++) {
            scene_shape shape = random_shape(k % 4);
            assert_true(scene_add_shape(s, &shape) >= 0);
            object.shape_count++;
        }
        assert_true(scene_add_object(s, &object) >= 0);
    }
    scene_mesh mesh = {.default_material = -1, .vertex_count = 30, .triangle_count = 40};
    mesh.positions = malloc(3 * 30 * sizeof(float));
    mesh.indices = malloc(3 * 40 * sizeof(uint32_t));
    for (int i = 0; i < 90; i++)
        mesh.positions[i] = (float)(random_unit() * 4 - 2);
    for (int i = 0; i < 120; i++)
        mesh.indices[i] = (uint32_t)(random_unit() * 30);
    int mesh_index = scene_add_mesh(s, &mesh);
    scene_object mesh_object = {.mesh = mesh_index};
    assert_true(scene_add_object(s, &mesh_object) >= 0);

    scene_instance identity = {.object = 0, .material = 1};
    scene_identity_transform(identity.object_to_world);
    assert_true(scene_add_instance(s, &identity) >= 0);
    for (int k = 0; k < 3; k++) {
        scene_instance placed = {.object = 1, .material = k % 2 ? 2 : -1};
        random_placement(placed.object_to_world, similar);
        assert_true(scene_add_instance(s, &placed) >= 0);
    }
    for (int k = 0; k < 2; k++) {
        scene_instance placed = {.object = 2, .material = -1};
        random_rotation_scale(placed.object_to_world);
        assert_true(scene_add_instance(s, &placed) >= 0);
    }
}

static void instanced_scene(scene *s, uint64_t seed)
{
    instanced_scene_placed(s, seed, false);
}

/* A random ray for the brute-force tests: an origin in the 30-unit cube around the scene
 * and a unit direction, in float (of, df) and the same values in double (o, d). */
static void random_test_ray(double o[3], double d[3], float of[3], float df[3])
{
    random_ray(1, o, d, of, df);   /* ray 1: not one of the axis-aligned ones */
}

/* The packed traversal of one packed scene s finds the brute-force nearest hit (in
 * double, every placed shape in its object's coordinates) for random rays. */
static void traversal_matches_brute_force(const scene *s, const packed_scene *packed, uint64_t seed)
{
    int hits = 0, grazes = 0;
    for (int r = 0; r < 3000; r++) {
        double o[3], d[3];
        float of[3], df[3];
        random_test_ray(o, d, of, df);
        double time = random_unit();
        double expected = brute_force(s, (float)time, o, d);
        packed_hit hit;
        bool found = packed_intersect_nearest(packed, of, df, (float)time, INFINITY, &hit);
        if (expected == INFINITY) {
            /* A miss by a hair in double may be a graze in float: rare, never more. */
            if (found) {
                assert_true(hit.t > 0);
                grazes++;
            }
            continue;
        }
        hits++;
        if (!found)
            fail_msg("seed %llu ray %d: brute force hits at %g, packed traversal misses", (unsigned long long)seed, r,
                     expected);
        if (fabs(hit.t - expected) > 2e-4 * (1 + expected))
            fail_msg("seed %llu ray %d: packed t %g, brute force %g", (unsigned long long)seed, r, hit.t, expected);
    }
    assert_true(hits > 300);
    assert_true(grazes <= 3);   /* of 3000 rays */
}

/* Placements instanced or baked, the packed traversal agrees with brute force: every
 * placement but the identity one instanced (keep_instances); the mesh's two placements
 * baked and object 1 instanced (its spheres stretched); object 1 baked too (turned and
 * scaled uniformly), its glass placement as well. */
static void instanced_traversal_matches_brute_force(void **state)
{
    (void)state;
    const struct {
        bool similar, keep_instances;
        uint32_t instances, triangles;
    } modes[] = {
        {false, true, 5, 6 + 6 + 40},              /* 6 world + 6 object + mesh once */
        {false, false, 3, 6 + 6 + 2 * 40},         /* the mesh twice in the world */
        {true, false, 0, 6 + 3 * 6 + 2 * 40},      /* object 1 three times in the world (glass too) */
    };
    for (int mode = 0; mode < 3; mode++) {
        for (uint64_t seed = 20; seed < 24; seed++) {
            scene s;
            instanced_scene_placed(&s, seed, modes[mode].similar);
            packed_scene packed;
            rt_error error;
            pack_options options = {.keep_instances = modes[mode].keep_instances};
            assert_int_equal(pack_scene(&s, &options, &packed, &error), RT_OK);
            assert_int_equal(packed.instance_count, modes[mode].instances);
            assert_int_equal(packed.triangle_count, modes[mode].triangles);
            traversal_matches_brute_force(&s, &packed, seed);
            packed_scene_free(&packed);
            scene_free(&s);
        }
    }
}

/* The shader's shadow rays (packed_shadow_blocked, mirrored from glsl/traverse.glsl)
 * against brute force on instanced scenes with two volume instances: towards a world sphere
 * (the light, passable) or nothing, up to a random t_max. With the volume passable too,
 * whatever passes nearest is P and the nearest blocker B: B before P must block; when
 * the ray is not blocked, its hit is P (none when P is beyond t_max). As a plain shadow
 * ray (volumes not passable), it is blocked exactly when a blocker or volume comes before
 * the light and t_max. Near-ties within float precision are skipped. */
static void shadow_rays_match_brute_force(void **state)
{
    (void)state;
    for (uint64_t seed = 40; seed < 43; seed++) {
        scene s;
        instanced_scene(&s, seed);
        for (int i = 1; i <= 2; i++) { /* two of object 1's transformed placements */
            s.instances[i].volume = true;
            s.instances[i].density = 0.5f;
        }
        packed_scene packed;
        assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
        int blocked_count = 0, through = 0, to_volume = 0;
        for (int r = 0; r < 3000; r++) {
            double o[3], d[3];
            float of[3], df[3];
            random_test_ray(o, d, of, df);
            float t_max = (float)(random_unit() * 40);
            /* The light: a world sphere (world primitives keep the scene's order first). */
            int light = r % 2 ? (int)(random_unit() * s.sphere_count) : -1;
            uint32_t light_slot = PACKED_NONE;
            for (uint32_t slot = 0; light >= 0 && slot < packed.primitive_count; slot++) {
                packed_primitive primitive = packed_primitive_at(&packed, slot);
                if (primitive.type == PRIMITIVE_SPHERE && primitive.data[0][3] == s.spheres[light].radius
                    && memcmp(primitive.data[0], s.spheres[light].center, sizeof s.spheres[light].center) == 0)
                    light_slot = slot;
            }
            if (light >= 0)
                assert_int_not_equal(light_slot, PACKED_NONE);
            double t_light = INFINITY;
            if (light >= 0) {
                scene_shape shape = {.type = SHAPE_SPHERE, .radius = s.spheres[light].radius};
                memcpy(shape.points[0], s.spheres[light].center, sizeof shape.points[0]);
                t_light = shape_hit(&shape, 0, o, d);
            }
            double blocker = brute_force_of(&s, 0, o, d, BLOCKERS, light);
            double volume = brute_force_of(&s, 0, o, d, VOLUME_SHAPES, -1);
            double passable = fmin(t_light, volume);
            double tolerance = 2e-4 * (1 + fmin(fmin(blocker, passable), t_max));
            if (fabs(blocker - passable) < tolerance || fabs(blocker - t_max) < tolerance
                || fabs(passable - t_max) < tolerance || fabs(t_light - volume) < tolerance)
                continue;
            packed_hit hit;
            bool blocked = packed_shadow_blocked(&packed, of, df, 0, t_max, light_slot, true, &hit);
            if (blocker < passable && blocker < t_max && !blocked)
                fail_msg("seed %llu ray %d: a blocker at %g before %g, not blocked", (unsigned long long)seed, r,
                         blocker, fmin(passable, (double)t_max));
            if (blocked) {
                assert_true(blocker < t_max);
                blocked_count++;
            } else if (passable < t_max) {
                assert_true(fabs(hit.t - passable) <= tolerance);
                assert_true(hit.instance != PACKED_NONE || hit.primitive == light_slot);
                to_volume += hit.instance != PACKED_NONE;
            } else {
                assert_true(hit.t == t_max && hit.primitive == PACKED_NONE);
                through++;
            }
            /* A plain shadow ray: anything but the light blocks. */
            double first = fmin(blocker, volume);
            bool plain = packed_shadow_blocked(&packed, of, df, 0, t_max, light_slot, false, &hit);
            assert_int_equal(plain, first < t_light && first < t_max);
        }
        assert_true(blocked_count > 150 && through > 200 && to_volume > 20);
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

/* A mesh with degenerate triangles (a repeated corner, three collinear corners) and
 * duplicated ones (the same three vertices twice, or in another order), placed with the
 * identity and with a transform: the packed traversal finds the brute-force nearest hit
 * (computed in double on the scene's own data) for random rays, never a degenerate one. */
static void degenerate_and_duplicate_triangles(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 0, 90);
    enum { VERTICES = 60, RANDOM = 120, DUPLICATES = 30, DEGENERATE = 30 };
    int triangles = RANDOM + DUPLICATES + DEGENERATE;
    scene_mesh mesh = {.default_material = -1, .vertex_count = VERTICES + 3, .triangle_count = triangles};
    mesh.positions = malloc(3 * (VERTICES + 3) * sizeof(float));
    mesh.indices = malloc(3 * (size_t)triangles * sizeof(uint32_t));
    for (int i = 0; i < 3 * VERTICES; i++)
        mesh.positions[i] = (float)(random_unit() * 6 - 3);
    /* Three collinear vertices at the end. */
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            mesh.positions[3 * (VERTICES + k) + i] = (float)(k - 1) * (i == 0 ? 2.0f : 0.5f);
    int t = 0;
    for (; t < RANDOM; t++)
        for (int k = 0; k < 3; k++)
            mesh.indices[3 * t + k] = (uint32_t)(random_unit() * VERTICES);
    for (int d = 0; d < DUPLICATES; d++, t++) {
        int original = (int)(random_unit() * RANDOM);
        for (int k = 0; k < 3; k++) /* the same corners, turned by d (same plane, same hit) */
            mesh.indices[3 * t + k] = mesh.indices[3 * original + (k + d) % 3];
    }
    for (int d = 0; d < DEGENERATE; d++, t++) {
        uint32_t a = (uint32_t)(random_unit() * VERTICES), b = (uint32_t)(random_unit() * VERTICES);
        if (d % 2 == 0) {
            mesh.indices[3 * t] = a, mesh.indices[3 * t + 1] = a, mesh.indices[3 * t + 2] = b;
        } else {
            for (int k = 0; k < 3; k++)
                mesh.indices[3 * t + k] = (uint32_t)(VERTICES + k);
        }
    }
    int mesh_index = scene_add_mesh(&s, &mesh);
    scene_object object = {.mesh = mesh_index};
    assert_true(scene_add_object(&s, &object) >= 0);
    scene_instance here = {.object = 0, .material = 0};
    scene_identity_transform(here.object_to_world);
    scene_instance there = {.object = 0, .material = 0};
    random_rotation_scale(there.object_to_world);
    assert_true(scene_add_instance(&s, &here) >= 0 && scene_add_instance(&s, &there) >= 0);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    int hits = 0, grazes = 0;
    for (int r = 0; r < 4000; r++) {
        float of[3], df[3];
        double o[3], d[3], length = 0;
        for (int i = 0; i < 3; i++) {
            d[i] = random_unit() * 2 - 1;
            length += d[i] * d[i];
        }
        for (int i = 0; i < 3; i++) {
            of[i] = (float)(random_unit() * 16 - 8);
            df[i] = (float)(d[i] / sqrt(length));
            o[i] = of[i];
            d[i] = df[i];
        }
        double expected = brute_force(&s, 0, o, d);
        packed_hit hit;
        bool found = packed_intersect_nearest(&packed, of, df, 0, INFINITY, &hit);
        if (expected == INFINITY) {
            grazes += found;
            continue;
        }
        hits++;
        assert_true(found);
        if (fabs(hit.t - expected) > 2e-4 * (1 + expected))
            fail_msg("ray %d: packed t %g, brute force %g", r, hit.t, expected);
        if (hit.instance == PACKED_NONE) {
            /* A world copy: never a degenerate triangle (no area, no hit). */
            packed_primitive primitive = packed_primitive_at(&packed, hit.primitive);
            float n[3] = {primitive.data[1][1] * primitive.data[2][2] - primitive.data[1][2] * primitive.data[2][1],
                          primitive.data[1][2] * primitive.data[2][0] - primitive.data[1][0] * primitive.data[2][2],
                          primitive.data[1][0] * primitive.data[2][1] - primitive.data[1][1] * primitive.data[2][0]};
            assert_true(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0);
        }
    }
    assert_true(hits > 400);
    assert_true(grazes <= 4);
    packed_scene_free(&packed);
    scene_free(&s);
}

static void instance_records_and_materials(void **state)
{
    (void)state;
    scene s;
    instanced_scene(&s, 30);
    packed_scene packed;
    pack_options options = {.keep_instances = true};
    assert_int_equal(pack_scene(&s, &options, &packed, NULL), RT_OK);
    /* Each instance (every placement but the identity one) points at a root inside the
     * node array, and its matrix inverts the placement: world_to_object *
     * object_to_world = identity. */
    int packed_index = 0;
    for (int i = 0; i < s.instance_count; i++) {
        const scene_instance *instance = &s.instances[i];
        if (instance->object == 0)
            continue;
        uint32_t base = packed.instance_offset + (uint32_t)packed_index++ * PACKED_INSTANCE_STRIDE;
        /* texel 0 holds the (first, count) of the object's root node record */
        uint32_t first = packed_uint(&packed, base, 0), count = packed_uint(&packed, base, 3);
        bool root_found = false;
        for (uint32_t n = 0; n < packed.node_count && !root_found; n++) {
            uint32_t node = packed.node_offset + n * PACKED_NODE_STRIDE;
            root_found = packed_uint(&packed, node, 3) == first && packed_uint(&packed, node + 1, 3) == count;
        }
        assert_true(root_found);
        assert_true(count == 0 ? first + 1 < packed.node_count : first + count <= packed.primitive_count);
        assert_int_equal(packed_uint(&packed, base, 1),
                         instance->material >= 0 ? (uint32_t)instance->material : PACKED_NONE);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double sum = 0;
                for (int k = 0; k < 3; k++)
                    sum += packed_float(&packed, base + 1 + r, k) * instance->object_to_world[k][c];
                assert_float_equal(sum, r == c ? 1.0 : 0.0, 1e-4);
            }
        /* And the translation: a point placed in the world comes back. */
        const float point[3] = {0.3f, -1.7f, 2.2f};
        float world[3];
        for (int r = 0; r < 3; r++)
            world[r] = instance->object_to_world[r][0] * point[0] + instance->object_to_world[r][1] * point[1]
                       + instance->object_to_world[r][2] * point[2] + instance->object_to_world[r][3];
        for (int r = 0; r < 3; r++) {
            double back = packed_float(&packed, base + 1 + r, 3);
            for (int k = 0; k < 3; k++)
                back += packed_float(&packed, base + 1 + r, k) * world[k];
            assert_float_equal(back, point[r], 1e-4 * (1 + fabs(world[0]) + fabs(world[1]) + fabs(world[2])));
        }
    }
    /* Every record decodes to a known type. */
    for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
        packed_primitive primitive = packed_primitive_at(&packed, slot);
        assert_true(primitive.type < PRIMITIVE_TYPE_COUNT);
    }
    packed_scene_free(&packed);
    scene_free(&s);
}

static void singular_instance_is_an_error(void **state)
{
    (void)state;
    scene s;
    instanced_scene(&s, 31);
    memset(s.instances[1].object_to_world, 0, sizeof s.instances[1].object_to_world);
    packed_scene packed;
    rt_error error;
    assert_int_equal(pack_scene(&s, NULL, &packed, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "cannot be inverted"));
    assert_null(packed.texels);
    scene_free(&s);
}

/* Vertex normals are stored octahedron-encoded in 32 bits: any unit vector comes back
 * within 1e-4 radians (two 16-bit fractions), the axes exactly. */
static void normals_survive_the_encoding(void **state)
{
    (void)state;
    random_state = 77;
    const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int i = 0; i < 6; i++) {
        float back[3];
        packed_decode_normal(packed_encode_normal(axes[i]), back);
        for (int c = 0; c < 3; c++)
            assert_float_equal(back[c], axes[i][c], 1e-6);
    }
    double worst = 0;
    for (int i = 0; i < 100000; i++) {
        float n[3], back[3];
        double z = 2 * random_unit() - 1, phi = 2 * M_PI * random_unit(), r = sqrt(1 - z * z);
        n[0] = (float)(r * cos(phi)), n[1] = (float)(r * sin(phi)), n[2] = (float)z;
        packed_decode_normal(packed_encode_normal(n), back);
        /* The chord |n - back| is the angle for angles this small (acos of a float dot
         * product near 1 would measure float rounding instead). */
        double dx = (double)n[0] - back[0], dy = (double)n[1] - back[1], dz = (double)n[2] - back[2];
        double angle = sqrt(dx * dx + dy * dy + dz * dz);
        if (angle > worst)
            worst = angle;
        assert_true(packed_encode_normal(n) != VERTEX_NO_NORMAL);
    }
    assert_true(worst < 1e-4);
}

/* Triangles are three vertex indices: a mesh placed with the identity (copied into the
 * top level) and with a transform (its own BVH, with keep_instances) shares one set of
 * vertices; records, normals, uvs and the uvs flag decode to the mesh's. Baked (the
 * default), the second placement has vertices of its own, moved, with the same normals
 * (a uniform scale) and uvs. */
static void mesh_vertices_are_stored_once(void **state)
{
    (void)state;
    scene s;
    scene_defaults(&s);
    add_material(&s, "grey", MATERIAL_LAMBERTIAN, 0.5f, 0.5f, 0.5f);
    /* A tetrahedron with normals and uvs. */
    scene_mesh mesh = {.default_material = -1, .vertex_count = 4, .triangle_count = 4};
    const float positions[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t indices[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    mesh.positions = malloc(sizeof positions);
    mesh.normals = malloc(sizeof positions);
    mesh.uvs = malloc(8 * sizeof(float));
    mesh.indices = malloc(sizeof indices);
    memcpy(mesh.positions, positions, sizeof positions);
    memcpy(mesh.indices, indices, sizeof indices);
    for (int v = 0; v < 4; v++) {
        float n[3] = {positions[3 * v] - 0.25f, positions[3 * v + 1] - 0.25f, positions[3 * v + 2] - 0.25f};
        float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int c = 0; c < 3; c++)
            mesh.normals[3 * v + c] = n[c] / length;
        mesh.uvs[2 * v] = 0.1f * v, mesh.uvs[2 * v + 1] = 0.2f * v;
    }
    int mesh_index = scene_add_mesh(&s, &mesh);
    scene_object object = {.mesh = mesh_index};
    assert_true(scene_add_object(&s, &object) >= 0);
    scene_instance here = {.object = 0, .material = 0};
    scene_identity_transform(here.object_to_world);
    scene_instance there = {.object = 0, .material = 0,
                            .object_to_world = {{2, 0, 0, 5}, {0, 2, 0, 0}, {0, 0, 2, 0}}};
    assert_true(scene_add_instance(&s, &here) >= 0 && scene_add_instance(&s, &there) >= 0);
    for (int baked = 0; baked < 2; baked++) {
        packed_scene packed;
        pack_options options = {.keep_instances = !baked};
        assert_int_equal(pack_scene(&s, &options, &packed, NULL), RT_OK);
        assert_int_equal(packed.instance_count, baked ? 0 : 1);
        assert_int_equal(packed.triangle_count, 8);
        assert_int_equal(packed.vertex_count, baked ? 8 : 4);   /* instanced: once, for both placements */
        int triangles = 0;
        for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
            packed_primitive primitive = packed_primitive_at(&packed, slot);
            if (primitive.type != PRIMITIVE_TRIANGLE)
                continue;
            triangles++;
            assert_true(primitive.has_uvs);
            for (int k = 0; k < 3; k++) {
                uint32_t v = primitive.vertices[k];
                assert_true(v < packed.vertex_count);
                /* Find the mesh vertex at that position: its normal and uv must match. */
                float position[3], normal[3];
                packed_vertex_position(&packed, v, position);
                assert_true(packed_vertex_normal(&packed, v, normal));
                /* The baked copy's vertices: scaled by 2 and moved by (5, 0, 0). */
                int match = -1;
                for (int m = 0; m < 4; m++) {
                    const float *p = positions + 3 * m;
                    const float moved[3] = {2 * p[0] + 5, 2 * p[1], 2 * p[2]};
                    if (memcmp(position, p, sizeof position) == 0
                        || (baked && memcmp(position, moved, sizeof position) == 0))
                        match = m;
                }
                assert_true(match >= 0);
                for (int c = 0; c < 3; c++)
                    assert_float_equal(normal[c], mesh.normals[3 * match + c], 1e-4);
                uint32_t uv_texel = packed.uv_offset + v / 2;
                assert_true(packed_float(&packed, uv_texel, (int)(2 * (v % 2))) == mesh.uvs[2 * match]);
                assert_true(packed_float(&packed, uv_texel, (int)(2 * (v % 2) + 1)) == mesh.uvs[2 * match + 1]);
            }
        }
        assert_int_equal(triangles, 8);
        packed_scene_free(&packed);
    }
    scene_free(&s);
}

/* A quad mesh (two triangles) with vertex colours, and a pbr material; the caller frees it. */
static void coloured_quad(scene *s, bool material_asks)
{
    scene_defaults(s);
    scene_material m = scene_material_defaults();
    m.type = MATERIAL_PBR;
    m.albedo[0] = m.albedo[1] = m.albedo[2] = 1;
    m.vertex_colors = material_asks;
    m.roughness = 1;
    m.index_of_refraction = 1.5f;
    assert_true(scene_add_material(s, &m) == 0);
    scene_mesh mesh = {.default_material = 0, .vertex_count = 4, .triangle_count = 2};
    const float positions[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const float colors[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0.25f, 0.5f, 2};
    const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    mesh.positions = malloc(sizeof positions);
    mesh.colors = malloc(sizeof colors);
    mesh.indices = malloc(sizeof indices);
    memcpy(mesh.positions, positions, sizeof positions);
    memcpy(mesh.colors, colors, sizeof colors);
    memcpy(mesh.indices, indices, sizeof indices);
    int mesh_index = scene_add_mesh(s, &mesh);
    scene_object object = {.mesh = mesh_index};
    assert_true(scene_add_object(s, &object) >= 0);
    scene_instance here = {.object = 0, .material = 0};
    scene_identity_transform(here.object_to_world);
    assert_true(scene_add_instance(s, &here) >= 0);
}

/* Vertex colours are packed (unorm16 pairs, packed_layout.h "colours") only when a pbr
 * material asks for them and a mesh has them, each stored vertex with its own colour,
 * clamped to 0..1; the header names the section, the summary says so. */
static void vertex_colours_are_packed_when_asked_for(void **state)
{
    (void)state;
    for (int asks = 0; asks < 2; asks++) {
        scene s;
        coloured_quad(&s, asks);
        packed_scene packed;
        assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
        assert_int_equal(packed_uint(&packed, PACKED_HEADER_COLOR_OFFSET / 4, PACKED_HEADER_COLOR_OFFSET % 4),
                         asks ? packed.color_offset : PACKED_NONE);
        assert_int_equal(packed.summary.vertex_colors, asks);
        assert_true(packed.summary.pbr);
        if (asks) {
            assert_true(packed.color_offset >= packed.uv_offset + (packed.vertex_count + 1) / 2);
            assert_true(packed.color_offset + (packed.vertex_count + 1) / 2 <= packed.node_offset);
            assert_int_equal(packed.vertex_count, 4);
            for (uint32_t v = 0; v < packed.vertex_count; v++) {
                float position[3];
                packed_vertex_position(&packed, v, position);
                int m = position[0] == 0 ? (position[1] == 0 ? 0 : 3) : (position[1] == 0 ? 1 : 2);
                const float expected[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.25f, 0.5f, 1}};
                uint32_t rg = packed_uint(&packed, packed.color_offset + v / 2, (int)(2 * (v % 2)));
                uint32_t ba = packed_uint(&packed, packed.color_offset + v / 2, (int)(2 * (v % 2) + 1));
                const float got[4] = {(rg & 0xffff) / 65535.0f, (rg >> 16) / 65535.0f, (ba & 0xffff) / 65535.0f,
                                      (ba >> 16) / 65535.0f};
                for (int c = 0; c < 3; c++)
                    assert_float_equal(got[c], expected[m][c], 1e-5);
                assert_float_equal(got[3], 1, 0);
            }
        }
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

/* Parses a scene of two world spheres (the first at x = sphere_x), an object of three
 * spheres placed three times (kept as instances) and a point light of colour red. */
static void bvh_cache_scene(scene *s, float sphere_x, float red)
{
    char text[1024];
    snprintf(text, sizeof text,
             "material m lambertian 0.5 0.5 0.5\n"
             "sphere %g 0 0 0.5 m\n"
             "sphere 2 0 0 0.5 m\n"
             "group rock material m {\n"
             "    sphere 0 1 0 0.2\n"
             "    sphere 0.3 1 0 0.2\n"
             "    sphere 0 1.3 0 0.2\n"
             "}\n"
             "instance rock {\n    translate 1 0 0\n}\n"
             "instance rock {\n    rotate 0 1 0 30\n}\n"
             "light point 1 3 1 color %g 1 1 intensity 4\n",
             sphere_x, red);
    rt_error error = {{0}};
    if (scene_load_string(text, "cache", NULL, s, &error) != RT_OK)
        fail_msg("%s", error.message);
}

/* Packs s with the cache (may be NULL), keeping instances, into *packed. */
static void pack_with_cache(const scene *s, pack_bvh_cache *cache, packed_scene *packed)
{
    pack_options options = pack_options_defaults();
    options.keep_instances = true;
    options.bvh_cache = cache;
    rt_error error = {{0}};
    if (pack_scene(s, &options, packed, &error) != RT_OK)
        fail_msg("%s", error.message);
}

/* The BVH cache (pack.h): a pack with it writes the texels a pack without it writes;
 * trees over the same boxes are taken from the last pack (a light's colour changes no
 * tree, and only the light section's texels), and a moved world sphere rebuilds the top
 * level only, the instanced object's tree still taken. */
static void bvh_cache_takes_trees_over_the_same_boxes(void **state)
{
    (void)state;
    pack_bvh_cache *cache = NULL;
    assert_int_equal(pack_bvh_cache_create(&cache, NULL), RT_OK);
    scene s;
    packed_scene plain, first, again, relit, moved, moved_plain;
    bvh_cache_scene(&s, 0, 1);
    pack_with_cache(&s, NULL, &plain);
    pack_with_cache(&s, cache, &first);
    pack_with_cache(&s, cache, &again);
    scene_free(&s);
    assert_int_equal(plain.bvh_built, 2); /* the top level and the rock */
    assert_int_equal(plain.bvh_reused, 0);
    assert_int_equal(first.bvh_built, 2);
    assert_int_equal(first.bvh_reused, 0);
    assert_int_equal(again.bvh_built, 0);
    assert_int_equal(again.bvh_reused, 2);
    assert_int_equal(first.texel_count, plain.texel_count);
    assert_memory_equal(first.texels, plain.texels, (size_t)plain.texel_count * 16);
    assert_memory_equal(again.texels, plain.texels, (size_t)plain.texel_count * 16);
    assert_int_equal(again.bvh_depth, plain.bvh_depth);

    bvh_cache_scene(&s, 0, 0.25f);
    pack_with_cache(&s, cache, &relit);
    scene_free(&s);
    assert_int_equal(relit.bvh_built, 0);
    assert_int_equal(relit.bvh_reused, 2);
    assert_int_equal(relit.texel_count, plain.texel_count);
    uint32_t light_end = plain.light_offset + plain.light_count * PACKED_LIGHT_STRIDE;
    assert_memory_equal(relit.texels, plain.texels, (size_t)plain.light_offset * 16);
    assert_memory_not_equal(relit.texels + 4 * plain.light_offset, plain.texels + 4 * plain.light_offset,
                            (size_t)(light_end - plain.light_offset) * 16);
    assert_memory_equal(relit.texels + 4 * light_end, plain.texels + 4 * light_end,
                        (size_t)(plain.texel_count - light_end) * 16);

    bvh_cache_scene(&s, -3, 0.25f);
    pack_with_cache(&s, cache, &moved);
    pack_with_cache(&s, NULL, &moved_plain);
    scene_free(&s);
    assert_int_equal(moved.bvh_built, 1);
    assert_int_equal(moved.bvh_reused, 1);
    assert_int_equal(moved.texel_count, moved_plain.texel_count);
    assert_memory_equal(moved.texels, moved_plain.texels, (size_t)moved_plain.texel_count * 16);
    packed_scene *all[] = {&plain, &first, &again, &relit, &moved, &moved_plain};
    for (size_t i = 0; i < sizeof all / sizeof *all; i++)
        packed_scene_free(all[i]);
    pack_bvh_cache_free(cache);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(header_and_materials_round_trip),
        cmocka_unit_test(every_sphere_packed_once_in_leaf_order),
        cmocka_unit_test(packed_traversal_matches_brute_force),
        cmocka_unit_test(empty_scene_packs_and_misses),
        cmocka_unit_test(instanced_traversal_matches_brute_force),
        cmocka_unit_test(shadow_rays_match_brute_force),
        cmocka_unit_test(instance_records_and_materials),
        cmocka_unit_test(singular_instance_is_an_error),
        cmocka_unit_test(normals_survive_the_encoding),
        cmocka_unit_test(mesh_vertices_are_stored_once),
        cmocka_unit_test(vertex_colours_are_packed_when_asked_for),
        cmocka_unit_test(degenerate_and_duplicate_triangles),
        cmocka_unit_test(bvh_cache_takes_trees_over_the_same_boxes),
    };
    return cmocka_run_group_tests_name("pack", tests, NULL, NULL);
}
