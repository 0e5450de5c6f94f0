/* test_pack.c: the packed scene (pack.h): header and record layout round trip, BVH leaf
 * order, and the packed traversal (the shader's algorithm, in C) against brute force. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pack.h"

/* splitmix64: a small deterministic generator for test data. */
static uint64_t random_state;
static double random_unit(void)
{
    uint64_t z = (random_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) / 9007199254740992.0;
}

static void add_material(scene *s, const char *name, int type, float r, float g, float b)
{
    scene_material m = {0};
    snprintf(m.name, sizeof m.name, "%s", name);
    m.type = type;
    m.albedo[0] = r, m.albedo[1] = g, m.albedo[2] = b;
    m.fuzz = 0.25f;
    m.index_of_refraction = 1.5f;
    m.emission[0] = 4 * r, m.emission[1] = 4 * g, m.emission[2] = 4 * b;
    assert_true(scene_add_material(s, &m) >= 0);
}

static void random_scene(scene *s, int sphere_count, uint64_t seed)
{
    scene_defaults(s);
    random_state = seed;
    add_material(s, "a", MATERIAL_LAMBERTIAN, 0.1f, 0.2f, 0.3f);
    add_material(s, "b", MATERIAL_METAL, 0.4f, 0.5f, 0.6f);
    add_material(s, "c", MATERIAL_DIELECTRIC, 1, 1, 1);
    add_material(s, "d", MATERIAL_EMISSIVE, 0.7f, 0.8f, 0.9f);
    for (int i = 0; i < sphere_count; i++) {
        scene_sphere sphere = {
            .center = {(float)(random_unit() * 20 - 10), (float)(random_unit() * 20 - 10),
                       (float)(random_unit() * 20 - 10)},
            .radius = (float)(0.05 + random_unit() * 1.5),
            .material = i % 4,
        };
        assert_true(scene_add_sphere(s, &sphere) >= 0);
    }
}

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
    assert_int_equal(packed_uint(&packed, 0, 3), 4);
    assert_int_equal(packed_uint(&packed, 1, 0), packed.primitive_offset);
    assert_int_equal(packed_uint(&packed, 1, 1), 37);
    assert_int_equal(packed_uint(&packed, 1, 2), packed.node_offset);
    assert_int_equal(packed_uint(&packed, 1, 3), packed.node_count);
    assert_int_equal(packed.material_offset, PACKED_HEADER_TEXELS);
    assert_int_equal(packed.primitive_offset, packed.material_offset + 4 * PACKED_MATERIAL_STRIDE);
    assert_int_equal(packed.node_offset, packed.primitive_offset + 37 * PACKED_PRIMITIVE_STRIDE);
    assert_int_equal(packed.texel_count, packed.node_offset + packed.node_count * PACKED_NODE_STRIDE);
    for (int i = 0; i < s.material_count; i++) {
        const scene_material *m = &s.materials[i];
        uint32_t base = packed.material_offset + (uint32_t)i * PACKED_MATERIAL_STRIDE;
        assert_int_equal(packed_uint(&packed, base, 0), m->type);
        for (int c = 0; c < 3; c++) {
            assert_true(packed_float(&packed, base, 1 + c) == m->albedo[c]);
            assert_true(packed_float(&packed, base + 1, c) == m->emission[c]);
        }
        assert_true(packed_float(&packed, base + 1, 3) == m->fuzz);
        assert_true(packed_float(&packed, base + 2, 0) == m->index_of_refraction);
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
            if (memcmp(primitive.sphere, s.spheres[i].center, 3 * sizeof(float)) == 0
                && primitive.sphere[3] == s.spheres[i].radius)
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

/* Nearest hit of a sphere in double precision, or INFINITY. */
static double sphere_hit(const float sphere[4], const double origin[3], const double direction[3])
{
    double oc[3], b = 0, c = 0;
    for (int i = 0; i < 3; i++) {
        oc[i] = origin[i] - sphere[i];
        b += oc[i] * direction[i];
        c += oc[i] * oc[i];
    }
    c -= (double)sphere[3] * sphere[3];
    double discriminant = b * b - c;
    if (discriminant < 0)
        return INFINITY;
    double root = sqrt(discriminant);
    if (-b - root > 0)
        return -b - root;
    if (-b + root > 0)
        return -b + root;
    return INFINITY;
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
            double origin[3], direction[3], length = 0;
            for (int i = 0; i < 3; i++) {
                origin[i] = random_unit() * 30 - 15;
                direction[i] = random_unit() * 2 - 1;
                if (r % 10 == 0 && i != r % 3)
                    direction[i] = 0; /* axis-aligned rays: zero direction components */
                length += direction[i] * direction[i];
            }
            if (length == 0)
                continue;
            length = sqrt(length);
            float origin_f[3], direction_f[3];
            for (int i = 0; i < 3; i++) {
                direction[i] /= length;
                origin_f[i] = (float)origin[i];
                direction_f[i] = (float)direction[i];
                origin[i] = origin_f[i];
                direction[i] = direction_f[i];
            }
            double best = INFINITY;
            uint32_t best_slot = UINT32_MAX;
            for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
                packed_primitive primitive = packed_primitive_at(&packed, slot);
                double t = sphere_hit(primitive.sphere, origin, direction);
                if (t < best) {
                    best = t;
                    best_slot = slot;
                }
            }
            float t_hit;
            uint32_t slot = packed_intersect_nearest(&packed, origin_f, direction_f, INFINITY, &t_hit);
            if (best_slot == UINT32_MAX) {
                assert_int_equal(slot, UINT32_MAX);
                continue;
            }
            hits++;
            assert_int_not_equal(slot, UINT32_MAX);
            assert_true(fabs(t_hit - best) <= 1e-4 * (1 + best));
            if (slot != best_slot) {
                /* Only a tie within float precision may pick another sphere. */
                double other = sphere_hit(packed_primitive_at(&packed, slot).sphere, origin, direction);
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
    assert_int_equal(packed.texel_count, PACKED_HEADER_TEXELS);
    float origin[3] = {0, 0, 0}, direction[3] = {0, 0, 1}, t;
    assert_int_equal(packed_intersect_nearest(&packed, origin, direction, INFINITY, &t), UINT32_MAX);
    packed_scene_free(&packed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(header_and_materials_round_trip),
        cmocka_unit_test(every_sphere_packed_once_in_leaf_order),
        cmocka_unit_test(packed_traversal_matches_brute_force),
        cmocka_unit_test(empty_scene_packs_and_misses),
    };
    return cmocka_run_group_tests_name("pack", tests, NULL, NULL);
}
