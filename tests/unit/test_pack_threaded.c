/* test_pack_threaded.c: the threaded walk (packed_layout.h "threaded walk", written by
 * core/pack_geometry.c): which scenes get it, that each octant's list is the BVH in depth
 * first order with every sphere and quad once and skips that jump over whole subtrees,
 * and that its walk (packed_traverse.h packed_threaded_walk, glsl/traverse.glsl
 * trace_threaded in C) finds the brute-force nearest hit (what the stack's walk finds,
 * with quads) and the blockers of shadow rays. */
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
#include "tracer_interface.h"
#include "support.h"
#include "pack_test_scenes.h"

/* The first texel of octant's list. */
static uint32_t list_of(const packed_scene *packed, int octant)
{
    return packed->threaded_offset + (uint32_t)octant * packed->threaded_items * packed_threaded_stride(packed);
}

static void header_names_the_lists(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 300, 3);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    uint32_t interior = 0;
    for (uint32_t n = 0; n < packed.node_count; n++)
        interior += packed_uint(&packed, packed.node_offset + n * PACKED_NODE_STRIDE + 1, 3) == 0;
    /* Every interior node's box but the root's, and every sphere. */
    assert_true(interior > 1);
    assert_int_equal(packed.threaded_items, interior - 1 + 300);
    assert_int_equal(packed_uint(&packed, PACKED_HEADER_THREADED_OFFSET / 4, PACKED_HEADER_THREADED_OFFSET % 4),
                     packed.threaded_offset);
    assert_int_equal(packed_uint(&packed, PACKED_HEADER_THREADED_ITEMS / 4, PACKED_HEADER_THREADED_ITEMS % 4),
                     packed.threaded_items);
    /* The lists lie inside the packed scene, after the node section. */
    assert_true(packed.threaded_offset >= packed.node_offset + packed.node_count * PACKED_NODE_STRIDE);
    assert_true((uint64_t)packed.threaded_offset
                    + (uint64_t)PACKED_THREADED_ORDERS * packed.threaded_items * packed_threaded_stride(&packed)
                <= packed.texel_count);
    packed_scene_free(&packed);
    scene_free(&s);
}

/* Adds shape as an object of its own placed with the identity, which the packer copies
 * into the top level (pack_collect.c). */
static void add_placed(scene *s, scene_shape shape)
{
    scene_object object = {.first_shape = s->shape_count, .shape_count = 1, .mesh = -1};
    assert_true(scene_add_shape(s, &shape) >= 0);
    int index = scene_add_object(s, &object);
    assert_true(index >= 0);
    scene_instance placed = {.object = index, .material = -1};
    scene_identity_transform(placed.object_to_world);
    assert_true(scene_add_instance(s, &placed) >= 0);
}

/* Adds a shape of type (a unit quad or a sphere of radius 0.5 at the origin), placed. */
static void add_placed_shape(scene *s, int type)
{
    scene_shape shape = {.type = type, .material = 0, .radius = 0.5f};
    shape.points[1][0] = 1;
    shape.points[2][1] = 1;
    add_placed(s, shape);
}

/* Adds count random quads, each placed. */
static void add_random_quads(scene *s, int count)
{
    for (int q = 0; q < count; q++) {
        scene_shape shape = {.type = SHAPE_QUAD, .material = q % 3};
        for (int i = 0; i < 3; i++) {
            shape.points[0][i] = (float)(random_unit() * 20 - 10);
            shape.points[1][i] = (float)(random_unit() * 4 - 2);
            shape.points[2][i] = (float)(random_unit() * 4 - 2);
        }
        add_placed(s, shape);
    }
}

/* Whether the box of item (texels box_base, box_base + 1: its near and far corners for
 * octant) holds the primitive item at base: a sphere's box, or a quad's four corners
 * (within float rounding of the sums). */
static bool box_holds(const packed_scene *packed, int octant, uint32_t box_base, uint32_t base)
{
    uint32_t tag = packed_uint(packed, base + 1, 3);
    for (int k = 0; k < 3; k++) {
        float near = packed_float(packed, box_base, k), far = packed_float(packed, box_base + 1, k);
        bool negative = (octant >> k) & 1;
        float lo = negative ? far : near, hi = negative ? near : far;
        if (tag & THREADED_SPHERE) {
            float centre = packed_float(packed, base, k), radius = packed_float(packed, base + 1, 0);
            if (!(lo <= centre - radius && hi >= centre + radius))
                return false;
            continue;
        }
        float q = packed_float(packed, base, k), u = packed_float(packed, base + 1, k), v = packed_float(packed, base + 2, k);
        float corners[4] = {q, q + u, q + v, q + u + v}, slack = 1e-5f * (1 + fabsf(q) + fabsf(u) + fabsf(v));
        for (int c = 0; c < 4; c++)
            if (!(lo <= corners[c] + slack && hi >= corners[c] - slack))
                return false;
    }
    return true;
}

/* Every list of packed (scene s) is its BVH depth first, the root's box left out: each
 * primitive once, as its record (a sphere) or shape record (a quad) holds it; skips nested
 * and past their own subtree; each box holding its subtree's primitives; and the octants'
 * orders differ. */
static void check_lists(const packed_scene *packed)
{
    uint32_t items = packed->threaded_items, stride = packed_threaded_stride(packed);
    assert_true(items > packed->primitive_count);
    uint32_t *seen = calloc(packed->primitive_count, sizeof *seen);
    uint32_t *open_until = malloc(items * sizeof *open_until);   /* skips of the boxes around an item */
    assert_non_null(seen);
    assert_non_null(open_until);
    bool lists_differ = false;
    for (int octant = 0; octant < PACKED_THREADED_ORDERS; octant++) {
        uint32_t list = list_of(packed, octant);
        memset(seen, 0, packed->primitive_count * sizeof *seen);
        /* No item for the root's box: the first item's subtree is not the whole list. */
        assert_true(packed_uint(packed, list, 3) < items);
        int depth = 0;
        for (uint32_t item = 0; item < items; item++) {
            uint32_t base = list + item * stride;
            while (depth > 0 && open_until[depth - 1] == item)
                depth--;
            uint32_t skip = packed_uint(packed, base, 3), tag = packed_uint(packed, base + 1, 3);
            /* Nested: an item's subtree ends within every subtree around it. */
            assert_true(skip > item && skip <= items);
            if (depth > 0)
                assert_true(skip <= open_until[depth - 1]);
            if (tag & (THREADED_SPHERE | THREADED_QUAD)) {
                uint32_t slot = tag & THREADED_SLOT_MASK;
                assert_true(slot < packed->primitive_count);
                assert_int_equal(skip, item + 1);
                seen[slot]++;
                packed_primitive primitive = packed_primitive_at(packed, slot);
                if (tag & THREADED_SPHERE) {
                    /* The sphere as its record holds it. */
                    assert_int_equal(primitive.type, PRIMITIVE_SPHERE);
                    for (int k = 0; k < 3; k++)
                        assert_true(packed_float(packed, base, k) == primitive.data[0][k]);
                    assert_true(packed_float(packed, base + 1, 0) == primitive.data[0][3]);
                } else {
                    /* The quad's corner and edges as its shape record holds them. */
                    assert_int_equal(primitive.type, PRIMITIVE_QUAD);
                    for (int t = 0; t < 3; t++)
                        for (int k = 0; k < 3; k++)
                            assert_true(packed_float(packed, base + (uint32_t)t, k) == primitive.data[t][k]);
                }
            } else {
                assert_int_equal(tag, 0);
                assert_true(skip > item + 2);   /* two children at least */
                /* The corners in the order the octant's rays meet them: min first where
                 * they go up the axis, max first where they go down. */
                for (int k = 0; k < 3; k++) {
                    float near = packed_float(packed, base, k), far = packed_float(packed, base + 1, k);
                    assert_true((octant >> k) & 1 ? near >= far : near <= far);
                }
                for (uint32_t inner = item + 1; inner < skip; inner++) {
                    uint32_t inner_base = list + inner * stride;
                    if (packed_uint(packed, inner_base + 1, 3) & (THREADED_SPHERE | THREADED_QUAD))
                        assert_true(box_holds(packed, octant, base, inner_base));
                }
                open_until[depth++] = skip;
            }
        }
        for (uint32_t slot = 0; slot < packed->primitive_count; slot++)
            assert_int_equal(seen[slot], 1);
        if (octant > 0)
            lists_differ |= memcmp(&packed->texels[4 * list_of(packed, 0)], &packed->texels[4 * list],
                                   (size_t)items * stride * 16) != 0;
    }
    assert_true(lists_differ);
    free(open_until);
    free(seen);
}

static void every_list_is_the_tree_depth_first(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 500, 5);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed_threaded_stride(&packed), PACKED_THREADED_ITEM_STRIDE);
    check_lists(&packed);
    packed_scene_free(&packed);
    scene_free(&s);
    /* Spheres and quads: three texels an item. */
    random_scene(&s, 200, 6);
    add_random_quads(&s, 60);
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed_threaded_stride(&packed), PACKED_THREADED_QUAD_ITEM_STRIDE);
    assert_int_equal(packed.primitive_count, 260);
    check_lists(&packed);
    packed_scene_free(&packed);
    scene_free(&s);
}

/* With quads among the spheres, the walk finds what the stack's walk finds (which
 * tests/unit/test_pack.c holds against brute force), bit for bit, and a shadow ray with
 * no light is blocked exactly when something is hit within t_max. */
static void walk_with_quads_matches_the_stack_walk(void **state)
{
    (void)state;
    for (uint64_t seed = 40; seed < 43; seed++) {
        scene s;
        random_scene(&s, 100, seed);
        add_random_quads(&s, 80);
        packed_scene packed;
        assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
        assert_true(packed.threaded_items > 0);
        int quad_hits = 0, sphere_hits = 0, blocked_count = 0, through = 0;
        for (int r = 0; r < 4000; r++) {
            double o[3], d[3];
            float of[3], df[3];
            random_ray(r, o, d, of, df);
            packed_hit hit, stack_hit;
            packed_threaded_walk(&packed, of, df, INFINITY, false, PACKED_NONE, &hit, NULL);
            packed_intersect_nearest(&packed, of, df, 0, INFINITY, &stack_hit);
            assert_true(hit.t == stack_hit.t || (isinf(hit.t) && isinf(stack_hit.t)));
            if (hit.primitive != stack_hit.primitive)   /* a tie: the same t */
                assert_true(hit.t == stack_hit.t);
            if (hit.primitive != PACKED_NONE) {
                bool quad = packed_primitive_type(&packed, hit.primitive) == PRIMITIVE_QUAD;
                quad_hits += quad;
                sphere_hits += !quad;
            }
            float t_max = (float)(random_unit() * 30);
            bool blocked = packed_threaded_walk(&packed, of, df, t_max, true, PACKED_NONE, &hit, NULL);
            if (fabsf(stack_hit.t - t_max) < 1e-4f * (1 + t_max))
                continue;
            assert_int_equal(blocked, stack_hit.t < t_max);
            blocked_count += blocked;
            through += !blocked;
        }
        assert_true(quad_hits > 100 && sphere_hits > 300 && blocked_count > 300 && through > 300);
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

static void walk_finds_the_nearest_hit(void **state)
{
    (void)state;
    for (uint64_t seed = 20; seed < 24; seed++) {
        scene s;
        random_scene(&s, 60 + (int)seed * 30, seed);
        packed_scene packed;
        assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
        int hits = 0;
        uint64_t visited_sum = 0;
        for (int r = 0; r < 4000; r++) {
            double o[3], d[3];
            float of[3], df[3];
            random_ray(r, o, d, of, df);
            double best = INFINITY;
            uint32_t best_slot = PACKED_NONE;
            for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
                double t = sphere_hit(packed_primitive_at(&packed, slot).data[0], o, d);
                if (t < best) {
                    best = t;
                    best_slot = slot;
                }
            }
            packed_hit hit, stack_hit;
            uint32_t visited;
            assert_false(packed_threaded_walk(&packed, of, df, INFINITY, false, PACKED_NONE, &hit, &visited));
            visited_sum += visited;
            packed_intersect_nearest(&packed, of, df, 0, INFINITY, &stack_hit);
            if (best_slot == PACKED_NONE) {
                assert_int_equal(hit.primitive, PACKED_NONE);
                assert_true(isinf(hit.t));
                continue;
            }
            hits++;
            assert_int_not_equal(hit.primitive, PACKED_NONE);
            assert_true(fabs(hit.t - best) <= 1e-4 * (1 + best));
            if (hit.primitive != best_slot) {
                /* Only a tie within float precision may pick another sphere. */
                double other = sphere_hit(packed_primitive_at(&packed, hit.primitive).data[0], o, d);
                assert_true(fabs(other - best) <= 1e-4 * (1 + best));
            }
            /* The same hit as the stack's walk, bit for bit: the same sphere test. */
            assert_true(hit.t == stack_hit.t);
            /* A shorter t_max: nothing nearer than it, or the same hit. */
            packed_hit short_hit;
            float t_max = (float)(best * (0.5 + random_unit()));
            packed_threaded_walk(&packed, of, df, t_max, false, PACKED_NONE, &short_hit, NULL);
            if (best < t_max * (1 - 1e-4))
                assert_true(short_hit.t == hit.t);
            else if (best > t_max * (1 + 1e-4))
                assert_true(short_hit.t == t_max && short_hit.primitive == PACKED_NONE);
        }
        assert_true(hits > 500);
        /* The skips are taken: a ray tests a small part of the list on average. */
        assert_true(visited_sum < (uint64_t)4000 * packed.threaded_items / 4);
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

/* Rays along an axis or in a plane, their zero components +0 or -0: a ray walks the list
 * its inverse direction's signs choose, which its boxes' corners are ordered for, and that
 * inverse takes -0 as +0 (packed_layout.h TRAVERSAL_SMALLEST_DIRECTION); so both find the
 * nearest sphere brute force finds. (With 1 / -0 = -infinity and the list chosen by the
 * direction's own signs, a -0 ray would miss every box it starts inside.) */
static void rays_with_zero_components_find_the_nearest_hit(void **state)
{
    (void)state;
    scene s;
    random_scene(&s, 300, 50);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    int hits = 0, negative_zeros = 0;
    for (int r = 0; r < 6000; r += 10) {   /* random_ray: every tenth ray along an axis */
        for (int variant = 0; variant < 2; variant++) {
            double o[3], d[3];
            float of[3], df[3];
            random_ray(r + variant * 5, o, d, of, df);
            int zero_axis = (r / 10) % 3;   /* one more zero: rays in a plane as well */
            if (variant == 1) {   /* unit again, as sphere_hit wants it */
                df[zero_axis] = 0;
                float length = sqrtf(df[0] * df[0] + df[1] * df[1] + df[2] * df[2]);
                for (int k = 0; k < 3; k++) {
                    df[k] /= length;
                    d[k] = df[k];
                }
            }
            double best = INFINITY;
            for (uint32_t slot = 0; slot < packed.primitive_count; slot++)
                best = fmin(best, sphere_hit(packed_primitive_at(&packed, slot).data[0], o, d));
            packed_hit positive, negative;
            packed_threaded_walk(&packed, of, df, INFINITY, false, PACKED_NONE, &positive, NULL);
            for (int k = 0; k < 3; k++)
                if (df[k] == 0) {
                    df[k] = -0.0f;
                    negative_zeros++;
                }
            packed_threaded_walk(&packed, of, df, INFINITY, false, PACKED_NONE, &negative, NULL);
            assert_true(positive.t == negative.t || (isinf(positive.t) && isinf(negative.t)));
            if (isinf(best)) {
                assert_true(isinf(positive.t));
                continue;
            }
            hits++;
            assert_true(fabs(positive.t - best) <= 1e-4 * (1 + best));
        }
    }
    assert_true(hits > 100 && negative_zeros > 1000);
    packed_scene_free(&packed);
    scene_free(&s);
}

static void shadow_walk_stops_at_blockers_only(void **state)
{
    (void)state;
    for (uint64_t seed = 30; seed < 33; seed++) {
        scene s;
        random_scene(&s, 200, seed);
        packed_scene packed;
        assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
        int blocked_count = 0, through = 0, to_light = 0;
        for (int r = 0; r < 3000; r++) {
            double o[3], d[3];
            float of[3], df[3];
            random_ray(r, o, d, of, df);
            float t_max = (float)(random_unit() * 40);
            uint32_t light_slot = r % 2 ? (uint32_t)(random_unit() * packed.primitive_count) : PACKED_NONE;
            if (light_slot != PACKED_NONE) {
                /* Aimed at the light's centre, as light sampling aims. */
                const float *centre = packed_primitive_at(&packed, light_slot).data[0];
                double length = 0;
                for (int i = 0; i < 3; i++) {
                    d[i] = centre[i] - o[i];
                    length += d[i] * d[i];
                }
                for (int i = 0; i < 3; i++) {
                    df[i] = (float)(d[i] / sqrt(length));
                    d[i] = df[i];
                }
            }
            double light = INFINITY, blocker = INFINITY;
            for (uint32_t slot = 0; slot < packed.primitive_count; slot++) {
                double t = sphere_hit(packed_primitive_at(&packed, slot).data[0], o, d);
                if (slot == light_slot)
                    light = t;
                else
                    blocker = fmin(blocker, t);
            }
            double tolerance = 2e-4 * (1 + fmin(fmin(blocker, light), t_max));
            if (fabs(blocker - light) < tolerance || fabs(blocker - t_max) < tolerance
                || fabs(light - t_max) < tolerance)
                continue;
            packed_hit hit, stack_hit;
            bool blocked = packed_threaded_walk(&packed, of, df, t_max, true, light_slot, &hit, NULL);
            if (blocker < fmin(light, (double)t_max)) {
                /* A blocker before the light and t_max: blocked, as by the stack's walk. */
                assert_true(blocked);
                assert_true(packed_shadow_blocked(&packed, of, df, 0, t_max, light_slot, false, &stack_hit));
                blocked_count++;
            } else if (blocker > t_max) {
                /* Nothing in the way: through, to the light when it is within t_max. */
                assert_false(blocked);
                assert_false(packed_shadow_blocked(&packed, of, df, 0, t_max, light_slot, false, &stack_hit));
                if (light < t_max) {
                    assert_int_equal(hit.primitive, light_slot);
                    assert_true(fabs(hit.t - light) <= tolerance);
                    to_light++;
                } else {
                    assert_true(hit.t == t_max && hit.primitive == PACKED_NONE);
                    through++;
                }
            } else {
                /* A blocker behind the light, within t_max: whether it blocks depends on
                 * which the list meets first (as for the stack's walk and its order,
                 * packed_traverse.h); the tracer's shadow rays end short of the light.
                 * Either way it is what the walk says it met. */
                if (blocked)
                    assert_true(hit.primitive != light_slot && hit.t < t_max && hit.t > light);
                else
                    assert_int_equal(hit.primitive, light_slot);
            }
        }
        assert_true(blocked_count > 150 && through > 150 && to_light > 20);
        packed_scene_free(&packed);
        scene_free(&s);
    }
}

static void only_still_spheres_in_one_level_get_lists(void **state)
{
    (void)state;
    packed_scene packed;
    scene s;
    /* One sphere: the root is a leaf, the list one item. */
    random_scene(&s, 1, 7);
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.threaded_items, 1);
    packed_scene_free(&packed);
    scene_free(&s);
    /* Nothing at all: no lists. */
    scene_defaults(&s);
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.threaded_items, 0);
    assert_int_equal(packed.threaded_offset, 0);
    packed_scene_free(&packed);
    scene_free(&s);
    /* A quad among the spheres: lists of three texels an item. */
    random_scene(&s, 50, 8);
    add_placed_shape(&s, SHAPE_QUAD);
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_true(packed.threaded_items > 51);
    assert_int_equal(packed_threaded_stride(&packed), PACKED_THREADED_QUAD_ITEM_STRIDE);
    packed_scene_free(&packed);
    scene_free(&s);
    /* A moving sphere among them, or a second level: none. */
    random_scene(&s, 50, 8);
    add_placed_shape(&s, SHAPE_MOVING_SPHERE);
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.threaded_items, 0);
    packed_scene_free(&packed);
    scene_free(&s);
    random_scene(&s, 50, 9);
    add_placed_shape(&s, SHAPE_SPHERE);   /* a placed sphere: copied into the top level */
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_true(packed.threaded_items > 51);
    packed_scene_free(&packed);
    pack_options options = pack_options_defaults();
    options.keep_instances = true;
    s.instances[0].object_to_world[0][3] = 2;   /* a placement with a transform: an instance */
    assert_int_equal(pack_scene(&s, &options, &packed, NULL), RT_OK);
    assert_true(packed.instance_count > 0);
    assert_int_equal(packed.threaded_items, 0);
    packed_scene_free(&packed);
    /* Asked for none. */
    options = pack_options_defaults();
    options.no_threaded_walk = true;
    assert_int_equal(pack_scene(&s, &options, &packed, NULL), RT_OK);
    assert_int_equal(packed.threaded_items, 0);
    packed_scene_free(&packed);
    scene_free(&s);
}

static void too_many_spheres_get_no_lists(void **state)
{
    (void)state;
    /* More spheres than lists of PACKED_THREADED_MAX_TEXELS texels hold (8 lists of 2
     * texels an item; a sphere is an item, and so is each interior node). */
    scene s;
    random_scene(&s, PACKED_THREADED_MAX_TEXELS / (PACKED_THREADED_ORDERS * PACKED_THREADED_ITEM_STRIDE) + 1, 11);
    packed_scene packed;
    assert_int_equal(pack_scene(&s, NULL, &packed, NULL), RT_OK);
    assert_int_equal(packed.threaded_items, 0);
    packed_scene_free(&packed);
    scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(header_names_the_lists),
        cmocka_unit_test(every_list_is_the_tree_depth_first),
        cmocka_unit_test(walk_finds_the_nearest_hit),
        cmocka_unit_test(walk_with_quads_matches_the_stack_walk),
        cmocka_unit_test(rays_with_zero_components_find_the_nearest_hit),
        cmocka_unit_test(shadow_walk_stops_at_blockers_only),
        cmocka_unit_test(only_still_spheres_in_one_level_get_lists),
        cmocka_unit_test(too_many_spheres_get_no_lists),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
