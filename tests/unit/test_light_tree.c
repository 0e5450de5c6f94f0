/* test_light_tree.c: unit tests of the light tree builder (core/light_tree.c).
 *
 * Every tree built here goes through check_tree(), which checks what light_tree.h promises
 * and the shader relies on: 2N - 1 nodes, root 0, each interior node's children contiguous
 * and inside the array, each node reached once, each light in exactly one leaf that copies
 * its bounds, each light's trail and depth leading from the root to its leaf, the depth
 * bound of median splits, boxes and sums exactly those of the children, and every node's
 * cone of normals holding the cone (or its negation: emitters are two-sided) of every light
 * below it, or with one-sided lights (spots) alone below it, each light's cone itself.
 * Then particular cases: where the median split puts the odd light, two far clusters kept
 * apart, finite lights split from infinite ones, the cone union of two flat lights and of
 * spots, determinism and the errors.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "light_tree.h"
#include "support.h"

/* Stores a random unit vector in v (uniform over the sphere: uniform height, uniform
 * longitude). */
static void random_unit(random_source *source, float v[3])
{
    double z = random_float(source, -1, 1), phi = random_float(source, 0, (float)(2 * M_PI));
    double r = sqrt(fmax(0, 1 - z * z));
    double x = r * cos(phi), y = r * sin(phi);
    double length = sqrt(x * x + y * y + z * z);
    v[0] = (float)(x / length);
    v[1] = (float)(y / length);
    v[2] = (float)(z / length);
}

/* ---- lights ---- */

static light_bounds make_point(float x, float y, float z, float intensity)
{
    light_bounds light = {.box = {{x, y, z}, {x, y, z}}, .cos_spread = -1, .intensity = intensity};
    return light;
}

static light_bounds make_sphere(const float centre[3], float radius, float intensity)
{
    light_bounds light = {.cos_spread = -1, .intensity = intensity};
    for (int axis = 0; axis < 3; axis++) {
        light.box.min[axis] = centre[axis] - radius;
        light.box.max[axis] = centre[axis] + radius;
    }
    return light;
}

/* A flat light (or, with cos_spread < 1, a patch whose normals spread that much) of
 * half_size about centre, facing axis. */
static light_bounds make_flat(const float centre[3], float half_size, const float axis[3], float cos_spread,
                              float intensity)
{
    light_bounds light = make_sphere(centre, half_size, intensity);
    memcpy(light.axis, axis, sizeof light.axis);
    light.cos_spread = cos_spread;
    return light;
}

/* A spot light at centre aimed along axis, shining within acos(cos_outer) of it. */
static light_bounds make_spot(const float centre[3], const float axis[3], float cos_outer, float intensity)
{
    light_bounds light = make_flat(centre, 0, axis, cos_outer, intensity);
    light.one_sided = true;
    return light;
}

/* An environment (light from every direction); its box holds what the packer leaves there. */
static light_bounds make_infinite(float irradiance)
{
    light_bounds light = {.box = bvh_box_empty(), .cos_spread = -1, .irradiance = irradiance, .infinite = true};
    return light;
}

/* A sun: light from within acos(cos_radius) of the unit direction towards it. */
static light_bounds make_sun(const float towards[3], float cos_radius, float irradiance)
{
    light_bounds light = make_infinite(irradiance);
    memcpy(light.axis, towards, sizeof light.axis);
    light.cos_spread = cos_radius;
    return light;
}

/* What random_lights() makes. */
typedef enum light_mix {
    MIX_ALL,          /* points, spheres, flat lights, patches, spots */
    MIX_FLAT_NEAR_Z,  /* flat lights facing within 20 degrees of +z or -z */
    MIX_SPOTS,        /* spots aimed every way, cones of 5 to 80 degrees */
} light_mix;

/* Fills lights with count random lights of the given mix in [-extent, extent]^3, then
 * makes infinite_count of them (at random indices) infinite. */
static void random_lights(random_source *source, light_bounds *lights, uint32_t count, light_mix mix,
                          float extent, uint32_t infinite_count)
{
    for (uint32_t i = 0; i < count; i++) {
        float centre[3], axis[3];
        for (int k = 0; k < 3; k++)
            centre[k] = random_float(source, -extent, extent);
        float intensity = random_float(source, 0, 10);
        if (mix == MIX_FLAT_NEAR_Z) {
            double tilt = random_float(source, 0, (float)(20 * M_PI / 180));
            double phi = random_float(source, 0, (float)(2 * M_PI));
            double sign = random_below(source, 2) ? 1 : -1;
            axis[0] = (float)(sin(tilt) * cos(phi));
            axis[1] = (float)(sin(tilt) * sin(phi));
            axis[2] = (float)(sign * cos(tilt));
            lights[i] = make_flat(centre, random_float(source, 0, 0.5f), axis, 1, intensity);
            continue;
        }
        if (mix == MIX_SPOTS) {
            random_unit(source, axis);
            float outer = random_float(source, (float)(5 * M_PI / 180), (float)(80 * M_PI / 180));
            lights[i] = make_spot(centre, axis, cosf(outer), intensity);
            continue;
        }
        switch (random_below(source, 5)) {
        case 0:
            lights[i] = make_point(centre[0], centre[1], centre[2], intensity);
            break;
        case 1:
            lights[i] = make_sphere(centre, random_float(source, 0.01f, 2), intensity);
            break;
        case 2:
            random_unit(source, axis);
            lights[i] = make_flat(centre, random_float(source, 0, 0.5f), axis, 1, intensity);
            break;
        case 3:
            random_unit(source, axis);
            lights[i] = make_flat(centre, random_float(source, 0, 0.5f), axis, random_float(source, 0.3f, 1),
                                  intensity);
            break;
        default:
            random_unit(source, axis);
            lights[i] = make_spot(centre, axis, random_float(source, 0.2f, 1), intensity);
            break;
        }
    }
    /* Suns (from a small cone of directions) and environments (from all). */
    for (uint32_t made = 0; made < infinite_count && made < count; made++) {
        float towards[3];
        random_unit(source, towards);
        float irradiance = random_float(source, 0, 3), cos_radius = random_float(source, 0.99f, 1);
        bool sun = random_below(source, 2) != 0;
        lights[random_below(source, count)] = sun ? make_sun(towards, cos_radius, irradiance) : make_infinite(irradiance);
    }
}

/* ---- tree invariants ---- */

static bool box_is_empty(const bvh_box *box)
{
    return box->min[0] > box->max[0];
}

/* Returns the angle between two vectors of any non-zero length. */
static double angle_between(const float a[3], const float b[3])
{
    double dot = 0, aa = 0, bb = 0;
    for (int k = 0; k < 3; k++) {
        dot += (double)a[k] * b[k];
        aa += (double)a[k] * a[k];
        bb += (double)b[k] * b[k];
    }
    return acos(fmax(-1, fmin(1, dot / sqrt(aa * bb))));
}

/* Returns ceil(log2(n)) for n >= 1. */
static uint32_t ceil_log2(uint32_t n)
{
    uint32_t levels = 0;
    while ((1ull << levels) < n)
        levels++;
    return levels;
}

/* Checks what a node on the path to a light promises about that light: its box holds the
 * light's, and its cone holds the light's cone or its negation (every way when the light
 * shines every way), to within tolerance radians. */
static void check_light_under(const light_tree_node *node, const light_bounds *light, double tolerance)
{
    if (light->infinite) {
        assert_true(node->irradiance >= light->irradiance);
        if (!box_is_empty(&node->box))
            return;   /* the root, with finite lights too: its cone is theirs (never weighed) */
        /* A node of infinite lights alone: its cone holds each one's directions. */
        if (light->cos_spread <= -1) {
            assert_true(node->cos_spread == -1);
            return;
        }
        if (node->cos_spread > -1)
            assert_true(angle_between(light->axis, node->axis) + acos(light->cos_spread)
                        <= acos(node->cos_spread) + tolerance);
        return;
    }
    assert_true(box_contains(&node->box, &light->box));
    assert_true(node->intensity >= light->intensity);
    if (light->cos_spread <= -1) {
        assert_true(node->cos_spread == -1);
        return;
    }
    if (node->cos_spread == -1)
        return;
    double angle = angle_between(light->axis, node->axis);
    if (node->one_sided) {
        /* Nothing below shines outside the cone: the light is one-sided, its cone inside. */
        assert_true(light->one_sided);
        assert_true(angle + acos(light->cos_spread) <= acos(node->cos_spread) + tolerance);
        return;
    }
    double two_sided = fmin(angle, M_PI - angle);
    assert_true(two_sided + acos(light->cos_spread) <= acos(node->cos_spread) + tolerance);
}

/* Checks every node on the path from the root to each light with check_light_under(). */
static void check_paths(const light_tree *tree, const light_bounds *lights, uint32_t count, double tolerance)
{
    for (uint32_t light = 0; light < count; light++) {
        uint32_t index = 0;
        check_light_under(&tree->nodes[0], &lights[light], tolerance);
        for (uint32_t level = 0; level < tree->depths[light]; level++) {
            index = tree->nodes[index].first + ((tree->trails[light] >> level) & 1u);
            check_light_under(&tree->nodes[index], &lights[light], tolerance);
        }
    }
}

/* Checks everything light_tree.h promises about tree, built from lights[0 .. count - 1]
 * (unit axes): see the top of this file. */
static void check_tree(const light_tree *tree, const light_bounds *lights, uint32_t count)
{
    assert_non_null(tree->nodes);
    assert_non_null(tree->trails);
    assert_non_null(tree->depths);
    assert_int_equal(tree->node_count, 2 * count - 1);

    bool *node_seen = calloc(tree->node_count, sizeof *node_seen);
    bool *light_seen = calloc(count, sizeof *light_seen);
    uint32_t *stack_node = malloc(tree->node_count * sizeof *stack_node);
    uint32_t *stack_depth = malloc(tree->node_count * sizeof *stack_depth);
    assert_true(node_seen && light_seen && stack_node && stack_depth);

    uint32_t stack_size = 0, deepest = 0;
    stack_node[stack_size] = 0;
    stack_depth[stack_size++] = 0;
    while (stack_size > 0) {
        stack_size--;
        uint32_t index = stack_node[stack_size], depth = stack_depth[stack_size];
        const light_tree_node *node = &tree->nodes[index];
        assert_false(node_seen[index]);
        node_seen[index] = true;
        deepest = depth > deepest ? depth : deepest;
        assert_true(node->cos_spread >= -1 && node->cos_spread <= 1);
        assert_close(sqrt((double)node->axis[0] * node->axis[0] + (double)node->axis[1] * node->axis[1] +
                          (double)node->axis[2] * node->axis[2]),
                     1, 1e-5);
        if (box_is_empty(&node->box)) {  /* no finite lights: no intensity, never one-sided */
            assert_true(node->intensity == 0);
            assert_false(node->one_sided);
        }

        if (node->leaf) {
            uint32_t light_index = node->first;
            assert_true(light_index < count);
            assert_false(light_seen[light_index]);
            light_seen[light_index] = true;
            assert_int_equal(tree->depths[light_index], depth);
            const light_bounds *light = &lights[light_index];
            if (light->infinite) {
                assert_true(box_is_empty(&node->box));
                assert_true(node->irradiance == light->irradiance);
                assert_true(node->cos_spread == light->cos_spread);
                if (light->cos_spread > -1)
                    assert_memory_equal(node->axis, light->axis, sizeof node->axis);
            } else {
                assert_true(same_box(&node->box, &light->box));
                assert_true(node->intensity == light->intensity);
                assert_true(node->irradiance == 0);
                assert_true(node->cos_spread == light->cos_spread);
                if (light->cos_spread > -1)
                    assert_memory_equal(node->axis, light->axis, sizeof node->axis);
                assert_true(node->one_sided == (light->one_sided && light->cos_spread > -1));
            }
            if (light->infinite)
                assert_false(node->one_sided);
            continue;
        }

        assert_true(node->first > index);                 /* children come after their parent */
        assert_true(node->first < tree->node_count - 1);  /* first + 1 is in range too */
        const light_tree_node *a = &tree->nodes[node->first], *b = &tree->nodes[node->first + 1];
        assert_true(box_contains(&node->box, &a->box));
        assert_true(box_contains(&node->box, &b->box));
        bvh_box tight = a->box;
        bvh_box_grow(&tight, &b->box);
        assert_true(same_box(&node->box, &tight));
        double intensity = (double)a->intensity + b->intensity, irradiance = (double)a->irradiance + b->irradiance;
        assert_close(node->intensity, intensity, 1e-5 * intensity);
        assert_close(node->irradiance, irradiance, 1e-5 * irradiance);
        /* A child that shines every way makes the node do so, unless it is the infinite
         * side of the root (whose cone is its finite lights'). */
        bool finite_a = !box_is_empty(&a->box), finite_b = !box_is_empty(&b->box);
        if ((a->cos_spread == -1 && (finite_a || !finite_b)) || (b->cos_spread == -1 && (finite_b || !finite_a)))
            assert_true(node->cos_spread == -1);
        /* One-sided exactly when every child with finite lights is (and the cone is not
         * every way). */
        bool all_one_sided = (!finite_a || a->one_sided) && (!finite_b || b->one_sided) && (finite_a || finite_b);
        assert_true(node->one_sided == (all_one_sided && node->cos_spread > -1));
        for (uint32_t child = 0; child < 2; child++) {
            stack_node[stack_size] = node->first + child;
            stack_depth[stack_size++] = depth + 1;
        }
    }
    for (uint32_t i = 0; i < tree->node_count; i++)
        assert_true(node_seen[i]);
    for (uint32_t i = 0; i < count; i++)
        assert_true(light_seen[i]);
    assert_int_equal(tree->depth, deepest);
    assert_true(tree->depth <= ceil_log2(count) + 1);
    assert_true(tree->depth <= LIGHT_TREE_MAX_DEPTH);

    /* Each light's trail leads to its leaf; then every node on the way bounds the light:
     * together these check every (node, light below it) pair. */
    uint8_t largest_depth = 0;
    for (uint32_t light = 0; light < count; light++) {
        uint32_t index = 0;
        for (uint32_t level = 0; level < tree->depths[light]; level++) {
            assert_false(tree->nodes[index].leaf);
            index = tree->nodes[index].first + ((tree->trails[light] >> level) & 1u);
        }
        assert_true(tree->nodes[index].leaf);
        assert_int_equal(tree->nodes[index].first, light);
        /* No stray bits below the leaf. */
        if (tree->depths[light] < 32)
            assert_int_equal(tree->trails[light] >> tree->depths[light], 0);
        largest_depth = tree->depths[light] > largest_depth ? tree->depths[light] : largest_depth;
    }
    assert_int_equal(largest_depth, tree->depth);
    check_paths(tree, lights, count, 1e-4);

    free(node_seen);
    free(light_seen);
    free(stack_node);
    free(stack_depth);
}

/* Builds the tree over lights, expects success and checks it; the caller frees *tree. */
static void build_and_check(const light_bounds *lights, uint32_t count, light_tree *tree)
{
    rt_error error = {{0}};
    rt_status status = light_tree_build(lights, count, tree, &error);
    if (status != RT_OK)
        fail_msg("light_tree_build failed: %s", error.message);
    check_tree(tree, lights, count);
}

/* Collects into in_subtree[] (count flags) the lights of the subtree at node index. */
static void mark_subtree(const light_tree *tree, uint32_t index, bool *in_subtree)
{
    const light_tree_node *node = &tree->nodes[index];
    if (node->leaf) {
        in_subtree[node->first] = true;
        return;
    }
    mark_subtree(tree, node->first, in_subtree);
    mark_subtree(tree, node->first + 1, in_subtree);
}

/* ---- tests ---- */

static void test_one_light(void **state)
{
    (void)state;
    const float axis[3] = {0, 1, 0}, centre[3] = {1, 2, 3};
    light_bounds light = make_flat(centre, 0.5f, axis, 1, 4);
    light_tree tree;
    build_and_check(&light, 1, &tree);
    assert_int_equal(tree.node_count, 1);
    assert_int_equal(tree.depth, 0);
    assert_int_equal(tree.trails[0], 0);
    assert_int_equal(tree.depths[0], 0);
    assert_true(tree.nodes[0].leaf);
    assert_int_equal(tree.nodes[0].first, 0);
    assert_true(tree.nodes[0].intensity == 4);
    assert_true(tree.nodes[0].cos_spread == 1);
    light_tree_free(&tree);

    /* One sun alone: a leaf with its irradiance and no box. */
    light = make_infinite(2.5f);
    build_and_check(&light, 1, &tree);
    assert_int_equal(tree.node_count, 1);
    assert_true(tree.nodes[0].irradiance == 2.5f);
    assert_true(tree.nodes[0].intensity == 0);
    assert_true(box_is_empty(&tree.nodes[0].box));
    light_tree_free(&tree);
}

static void test_random_sets(void **state)
{
    (void)state;
    const uint32_t sizes[] = {2, 3, 5, 9, 100, 1000};
    light_bounds *lights = malloc(1000 * sizeof *lights);
    assert_non_null(lights);
    uint32_t narrow_roots = 0;
    for (uint64_t seed = 1; seed <= 6; seed++) {
        random_source source = {seed};
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
            uint32_t count = sizes[s];
            light_mix mix = seed % 3 == 0 ? MIX_FLAT_NEAR_Z : seed == 5 ? MIX_SPOTS : MIX_ALL;
            /* Some sets with a few suns or an environment among them. */
            uint32_t infinite_count = seed % 2 == 0 ? 1 + random_below(&source, 3) : 0;
            random_lights(&source, lights, count, mix, 50, infinite_count);
            light_tree tree;
            build_and_check(lights, count, &tree);
            if (mix == MIX_FLAT_NEAR_Z && !box_is_empty(&tree.nodes[0].box)) {
                /* Normals within 20 degrees of the z axis (either way): the cones merge
                 * into one that is still far from "any direction" (the root's cone is
                 * its finite lights', a set made all suns and skies aside). */
                assert_true(tree.nodes[0].cos_spread > 0.5f);
                narrow_roots++;
            }
            light_tree_free(&tree);
        }
    }
    assert_true(narrow_roots >= 11);
    /* Spots alone: every node one-sided unless its cone went every way (check_tree checks
     * that each holds its spots' cones themselves). */
    random_source spot_source = {31};
    random_lights(&spot_source, lights, 200, MIX_SPOTS, 20, 0);
    light_tree spots;
    build_and_check(lights, 200, &spots);
    uint32_t one_sided_nodes = 0;
    for (uint32_t n = 0; n < spots.node_count; n++)
        one_sided_nodes += spots.nodes[n].one_sided;
    assert_true(one_sided_nodes >= 200);   /* the leaves at least */
    light_tree_free(&spots);

    /* Every light at one point (all centroids equal): median splits by index alone. */
    for (uint32_t i = 0; i < 100; i++)
        lights[i] = make_point(1, 2, 3, 1);
    light_tree tree;
    build_and_check(lights, 100, &tree);
    assert_int_equal(tree.depth, ceil_log2(100));
    light_tree_free(&tree);
    free(lights);
}

static void test_median_split(void **state)
{
    (void)state;
    /* Three lights along x, listed out of order: the first child gets count / 2 = 1 (the
     * lowest x), the odd light goes to the second child. */
    light_bounds lights[3] = {make_point(2, 0, 0, 1), make_point(0, 0, 0, 1), make_point(1, 0, 0, 1)};
    light_tree tree;
    build_and_check(lights, 3, &tree);
    const light_tree_node *first = &tree.nodes[tree.nodes[0].first];
    assert_true(first->leaf);
    assert_int_equal(first->first, 1);
    assert_int_equal(tree.trails[1], 0);
    assert_int_equal(tree.depths[1], 1);
    /* Then the second child splits x = 1 (light 2) from x = 2 (light 0). */
    assert_int_equal(tree.trails[2], 1);
    assert_int_equal(tree.trails[0], 3);
    light_tree_free(&tree);

    /* Along the longest axis of the centres: here z. */
    light_bounds spread[4] = {make_point(0, 0, 9, 1), make_point(1, 0, 0, 1), make_point(0, 1, 3, 1),
                              make_point(1, 1, 6, 1)};
    build_and_check(spread, 4, &tree);
    bool in_first[4] = {false};
    mark_subtree(&tree, tree.nodes[0].first, in_first);
    assert_true(in_first[1] && in_first[2] && !in_first[0] && !in_first[3]);
    light_tree_free(&tree);

    /* Equal centres: ties go by index. */
    light_bounds same[3] = {make_point(5, 5, 5, 1), make_point(5, 5, 5, 2), make_point(5, 5, 5, 3)};
    build_and_check(same, 3, &tree);
    assert_int_equal(tree.nodes[tree.nodes[0].first].first, 0);
    assert_true(tree.nodes[tree.nodes[0].first].leaf);
    light_tree_free(&tree);

    /* Infinite-only sets split by index: lights 0 and 1 first, 2 to 4 second. */
    light_bounds suns[5];
    for (uint32_t i = 0; i < 5; i++)
        suns[i] = make_infinite((float)i + 1);
    build_and_check(suns, 5, &tree);
    for (uint32_t i = 0; i < 5; i++)
        assert_int_equal(tree.trails[i] & 1u, i < 2 ? 0 : 1);
    assert_true(tree.nodes[tree.nodes[0].first].irradiance == 3);
    assert_true(tree.nodes[tree.nodes[0].first + 1].irradiance == 12);
    light_tree_free(&tree);
}

static void test_separate_clusters(void **state)
{
    (void)state;
    random_source source = {77};
    light_bounds lights[16];
    bool near_minus[16];
    /* Two clusters of 8 near x = -100 and x = +100, interleaved in the array. */
    for (uint32_t i = 0; i < 16; i++) {
        near_minus[i] = random_below(&source, 2) == 0;
        lights[i] = make_point(0, 0, 0, 1);
    }
    uint32_t minus_count = 0;
    for (uint32_t i = 0; i < 16; i++)
        minus_count += near_minus[i];
    /* Make it exactly 8 and 8: flip the last ones as needed. */
    for (uint32_t i = 15; minus_count != 8; i--) {
        if (minus_count > 8 && near_minus[i]) {
            near_minus[i] = false;
            minus_count--;
        } else if (minus_count < 8 && !near_minus[i]) {
            near_minus[i] = true;
            minus_count++;
        }
    }
    for (uint32_t i = 0; i < 16; i++)
        lights[i] = make_point((near_minus[i] ? -100.0f : 100.0f) + random_float(&source, -5, 5),
                               random_float(&source, -5, 5), random_float(&source, -5, 5),
                               random_float(&source, 0.5f, 2));
    light_tree tree;
    build_and_check(lights, 16, &tree);
    bool in_first[16] = {false};
    mark_subtree(&tree, tree.nodes[0].first, in_first);
    for (uint32_t i = 0; i < 16; i++)
        assert_int_equal(in_first[i], near_minus[i]);  /* the lower x go first */
    assert_true(tree.nodes[tree.nodes[0].first].box.max[0] < -90);
    assert_true(tree.nodes[tree.nodes[0].first + 1].box.min[0] > 90);
    light_tree_free(&tree);
}

static void test_finite_split_from_infinite(void **state)
{
    (void)state;
    random_source source = {5};
    enum { COUNT = 40 };
    light_bounds lights[COUNT];
    random_lights(&source, lights, COUNT, MIX_ALL, 20, 0);
    double total_intensity = 0, total_irradiance = 0;
    /* Three infinite lights at scattered indices. */
    const uint32_t infinite[3] = {0, 17, 39};
    for (uint32_t k = 0; k < 3; k++)
        lights[infinite[k]] = make_infinite(1.5f + (float)k);
    for (uint32_t i = 0; i < COUNT; i++) {
        total_intensity += lights[i].infinite ? 0 : lights[i].intensity;
        total_irradiance += lights[i].irradiance;
    }
    light_tree tree;
    build_and_check(lights, COUNT, &tree);
    const light_tree_node *root = &tree.nodes[0];
    const light_tree_node *finite = &tree.nodes[root->first], *sky = &tree.nodes[root->first + 1];
    assert_relative(sky->irradiance, total_irradiance, 1e-6);
    assert_true(sky->intensity == 0);
    assert_true(box_is_empty(&sky->box));
    assert_relative(finite->intensity, total_intensity, 1e-6);
    assert_true(finite->irradiance == 0);
    /* The infinite lights add nothing to the root's box and cone. */
    assert_true(same_box(&root->box, &finite->box));
    assert_true(root->cos_spread == finite->cos_spread);
    assert_relative(root->intensity, total_intensity, 1e-6);
    assert_relative(root->irradiance, total_irradiance, 1e-6);
    for (uint32_t k = 0; k < 3; k++)
        assert_int_equal(tree.trails[infinite[k]] & 1u, 1);
    assert_true(tree.depth <= ceil_log2(COUNT) + 1);
    light_tree_free(&tree);
}

static void test_cone_union(void **state)
{
    (void)state;
    const float zero[3] = {0, 0, 0}, far[3] = {3, 0, 0};
    const float up[3] = {0, 0, 1}, down[3] = {0, 0, -1}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
    light_tree tree;

    /* Facing opposite ways: two-sided, so one cone of no spread holds both. */
    light_bounds opposite[2] = {make_flat(zero, 1, up, 1, 1), make_flat(far, 1, down, 1, 1)};
    build_and_check(opposite, 2, &tree);
    assert_true(tree.nodes[0].cos_spread == 1);
    assert_close(fabs(tree.nodes[0].axis[2]), 1, 1e-6);
    light_tree_free(&tree);

    /* Facing x and y: the cone between them, 45 degrees each way (plus the widening). */
    light_bounds right_angle[2] = {make_flat(zero, 1, x, 1, 1), make_flat(far, 1, y, 1, 1)};
    build_and_check(right_angle, 2, &tree);
    assert_close(tree.nodes[0].cos_spread, cos(M_PI / 4), 1e-4);
    assert_true(tree.nodes[0].cos_spread < cos(M_PI / 4 + 0.5e-5));  /* widened by 1e-5 rad */
    assert_true(tree.nodes[0].cos_spread > cos(M_PI / 4 + 2e-5));
    assert_close(tree.nodes[0].axis[0], sqrt(0.5), 1e-5);
    assert_close(tree.nodes[0].axis[1], sqrt(0.5), 1e-5);
    assert_close(tree.nodes[0].axis[2], 0, 1e-6);
    light_tree_free(&tree);

    /* A cone holding the other: the wider one, unchanged. */
    const float tilted[3] = {(float)sin(0.2), 0, (float)cos(0.2)};
    light_bounds nested[2] = {make_flat(zero, 1, up, 0.5f, 1), make_flat(far, 1, tilted, 1, 1)};
    build_and_check(nested, 2, &tree);
    assert_true(tree.nodes[0].cos_spread == 0.5f);
    assert_memory_equal(tree.nodes[0].axis, up, sizeof up);
    light_tree_free(&tree);

    /* A light that shines every way, and a sun that adds no normals. */
    light_bounds with_sphere[3] = {make_flat(zero, 1, up, 1, 1), make_sphere(far, 1, 1), make_infinite(1)};
    build_and_check(with_sphere, 3, &tree);
    assert_true(tree.nodes[0].cos_spread == -1);
    light_tree_free(&tree);
    light_bounds with_sun[2] = {make_flat(zero, 1, y, 1, 1), make_infinite(1)};
    build_and_check(with_sun, 2, &tree);
    assert_true(tree.nodes[0].cos_spread == 1);
    assert_memory_equal(tree.nodes[0].axis, y, sizeof y);
    light_tree_free(&tree);

    /* Exactly opposite axes, one cone wider than pi / 2 (so not flipped): no plane holds
     * both axes, yet the cone through both is less than every way. */
    light_bounds apart[2] = {make_flat(zero, 1, up, -0.2f, 1), make_flat(far, 1, down, 0.9f, 1)};
    build_and_check(apart, 2, &tree);
    double through_both = 0.5 * (acos(-0.2f) + M_PI + acos(0.9f));
    assert_close(acos(tree.nodes[0].cos_spread), through_both, 1e-4);
    assert_close(tree.nodes[0].axis[2], cos(through_both - acos(-0.2f)), 1e-5);
    light_tree_free(&tree);

    /* Two spots aimed opposite ways: one-sided, so not flipped into one narrow cone (each
     * lights its own side only); the cone through both, pi / 2 + 0.2 rad each way. */
    float cos_narrow = (float)cos(0.2);
    light_bounds spots[2] = {make_spot(zero, up, cos_narrow, 1), make_spot(far, down, cos_narrow, 1)};
    build_and_check(spots, 2, &tree);
    assert_true(tree.nodes[0].one_sided);
    assert_close(acos(tree.nodes[0].cos_spread), M_PI / 2 + 0.2, 1e-4);
    light_tree_free(&tree);
    /* A spot and a flat light: two-sided (the flat light shines both ways); a spot and a
     * point light: every way; a spot and a sun: the spot's cone, one-sided. */
    light_bounds spot_and_flat[2] = {make_spot(zero, up, cos_narrow, 1), make_flat(far, 1, down, 1, 1)};
    build_and_check(spot_and_flat, 2, &tree);
    assert_false(tree.nodes[0].one_sided);
    assert_true(tree.nodes[0].cos_spread >= cos_narrow);
    light_tree_free(&tree);
    light_bounds spot_and_point[2] = {make_spot(zero, up, cos_narrow, 1), make_point(3, 0, 0, 1)};
    build_and_check(spot_and_point, 2, &tree);
    assert_false(tree.nodes[0].one_sided);
    assert_true(tree.nodes[0].cos_spread == -1);
    light_tree_free(&tree);
    light_bounds spot_and_sun[2] = {make_spot(zero, x, cos_narrow, 1), make_infinite(1)};
    build_and_check(spot_and_sun, 2, &tree);
    assert_true(tree.nodes[0].one_sided);
    assert_true(tree.nodes[0].cos_spread == cos_narrow);
    assert_memory_equal(tree.nodes[0].axis, x, sizeof x);
    light_tree_free(&tree);

    /* Suns: a node of suns alone holds the directions they come from (one-sided); with an
     * environment among them, every direction. */
    const float sun_a[3] = {0, (float)sin(0.3), (float)cos(0.3)}, sun_b[3] = {0, (float)-sin(0.3), (float)cos(0.3)};
    light_bounds suns[2] = {make_sun(sun_a, (float)cos(0.01), 1), make_sun(sun_b, (float)cos(0.01), 2)};
    build_and_check(suns, 2, &tree);
    assert_close(acos(tree.nodes[0].cos_spread), 0.31, 1e-4);
    assert_close(tree.nodes[0].axis[2], 1, 1e-6);
    light_tree_free(&tree);
    light_bounds sun_and_sky[2] = {make_sun(sun_a, 1, 1), make_infinite(1)};
    build_and_check(sun_and_sky, 2, &tree);
    assert_true(tree.nodes[0].cos_spread == -1);
    light_tree_free(&tree);

    /* Wide cones more than pi apart in all: any direction. */
    light_bounds wide[2] = {make_flat(zero, 1, up, -0.5f, 1), make_flat(far, 1, down, -0.5f, 1)};
    build_and_check(wide, 2, &tree);
    assert_true(tree.nodes[0].cos_spread == -1);
    light_tree_free(&tree);
}

static void test_cone_rounding(void **state)
{
    (void)state;
    /* Normals a few thousandths of a degree apart, where a float cosine has almost no
     * digits left (cos(3e-4) rounds to 1 in float) and a float axis moves by about 1e-7
     * rad: the widening and the outward rounding must still hold every light's normal.
     * The test's own rounding is below 1e-7 rad. */
    enum { COUNT = 300 };
    random_source source = {99};
    light_bounds lights[COUNT];
    for (uint32_t i = 0; i < COUNT; i++) {
        float centre[3];
        for (int k = 0; k < 3; k++)
            centre[k] = random_float(&source, -10, 10);
        double tilt = random_float(&source, 0, 1e-3f), phi = random_float(&source, 0, (float)(2 * M_PI));
        double sign = i % 3 == 0 ? -1 : 1;
        float axis[3] = {(float)(sin(tilt) * cos(phi)), (float)(sin(tilt) * sin(phi)), (float)(sign * cos(tilt))};
        lights[i] = make_flat(centre, 0.1f, axis, 1, 1);
    }
    light_tree tree;
    build_and_check(lights, COUNT, &tree);
    check_paths(&tree, lights, COUNT, 1e-7);
    assert_true(tree.nodes[0].cos_spread > (float)cos(2e-3));
    assert_true(tree.nodes[0].cos_spread < 1);
    light_tree_free(&tree);
}

static void test_odd_axes(void **state)
{
    (void)state;
    const float zero[3] = {0, 0, 0}, far[3] = {3, 0, 0}, none[3] = {0, 0, 0}, long_axis[3] = {0, 2, 0};
    /* A flat light of no area has no normal: it is taken to shine every way. A non-unit
     * axis is normalized. */
    light_bounds lights[2] = {make_flat(zero, 0, none, 1, 0), make_flat(far, 1, long_axis, 1, 1)};
    light_tree tree;
    rt_error error = {{0}};
    assert_int_equal(light_tree_build(lights, 2, &tree, &error), RT_OK);
    const light_tree_node *leaf_none = &tree.nodes[tree.nodes[0].first];
    const light_tree_node *leaf_long = &tree.nodes[tree.nodes[0].first + 1];
    assert_int_equal(leaf_none->first, 0);
    assert_true(leaf_none->cos_spread == -1);
    assert_true(leaf_long->axis[1] == 1);
    assert_true(leaf_long->cos_spread == 1);
    assert_true(tree.nodes[0].cos_spread == -1);
    light_tree_free(&tree);

    /* A point light's unused axis may hold anything. */
    light_bounds point = make_point(0, 0, 0, 1);
    point.axis[0] = NAN;
    assert_int_equal(light_tree_build(&point, 1, &tree, &error), RT_OK);
    assert_true(tree.nodes[0].axis[2] == 1);
    light_tree_free(&tree);
}

/* The fields of two nodes are identical (compared field by field, not the padding). */
static void assert_same_node(const light_tree_node *a, const light_tree_node *b)
{
    assert_memory_equal(&a->box, &b->box, sizeof a->box);
    assert_memory_equal(a->axis, b->axis, sizeof a->axis);
    assert_memory_equal(&a->cos_spread, &b->cos_spread, sizeof a->cos_spread);
    assert_memory_equal(&a->intensity, &b->intensity, sizeof a->intensity);
    assert_memory_equal(&a->irradiance, &b->irradiance, sizeof a->irradiance);
    assert_int_equal(a->first, b->first);
    assert_int_equal(a->leaf, b->leaf);
}

static void test_deterministic(void **state)
{
    (void)state;
    enum { COUNT = 1000 };
    random_source source = {41};
    light_bounds *lights = malloc(COUNT * sizeof *lights);
    assert_non_null(lights);
    random_lights(&source, lights, COUNT, MIX_ALL, 30, 4);
    /* Duplicates, to make ties that only the index breaks. */
    for (uint32_t i = 0; i < 50; i++)
        lights[COUNT - 1 - i] = lights[i];
    light_tree first, second;
    build_and_check(lights, COUNT, &first);
    build_and_check(lights, COUNT, &second);
    assert_int_equal(first.node_count, second.node_count);
    assert_int_equal(first.depth, second.depth);
    for (uint32_t i = 0; i < first.node_count; i++)
        assert_same_node(&first.nodes[i], &second.nodes[i]);
    assert_memory_equal(first.trails, second.trails, COUNT * sizeof *first.trails);
    assert_memory_equal(first.depths, second.depths, COUNT * sizeof *first.depths);
    light_tree_free(&first);
    light_tree_free(&second);
    free(lights);
}

/* Expects light_tree_build() to refuse with RT_ERROR_RUNTIME, a "LIGHT_TREE: " message
 * mentioning must_mention, and a zeroed output. */
static void expect_error(const light_bounds *lights, uint32_t count, const char *must_mention)
{
    light_tree tree = {.node_count = 99, .depth = 7};
    rt_error error = {{0}};
    assert_int_equal(light_tree_build(lights, count, &tree, &error), RT_ERROR_RUNTIME);
    assert_true(strncmp(error.message, "LIGHT_TREE: ", 12) == 0);
    assert_contains(error.message, must_mention);
    assert_null(tree.nodes);
    assert_null(tree.trails);
    assert_null(tree.depths);
    assert_int_equal(tree.node_count, 0);
    assert_int_equal(tree.depth, 0);
}

static void test_errors(void **state)
{
    (void)state;
    light_bounds lights[4] = {make_point(0, 0, 0, 1), make_point(1, 0, 0, 1), make_point(2, 0, 0, 1),
                              make_infinite(1)};
    expect_error(lights, 0, "no lights");
    expect_error(NULL, 3, "no bounds");
    expect_error(lights, LIGHT_TREE_MAX_LIGHTS + 1, "more than");

    lights[2].box.min[1] = NAN;
    expect_error(lights, 4, "light 2");
    expect_error(lights, 4, "NaN");
    lights[2].box.min[1] = 0;
    lights[1].box.max[0] = INFINITY;
    expect_error(lights, 4, "infinite");
    lights[1].box.max[0] = 1;
    lights[0].box.min[2] = 5;  /* inside out */
    expect_error(lights, 4, "light 0");
    lights[0].box.min[2] = 0;

    lights[1].intensity = -1;
    expect_error(lights, 4, "intensity");
    lights[1].intensity = 1;
    lights[3].irradiance = INFINITY;
    expect_error(lights, 4, "irradiance");
    lights[3].irradiance = -0.5f;
    expect_error(lights, 4, "light 3");
    lights[3].irradiance = 1;
    lights[0].cos_spread = NAN;
    expect_error(lights, 4, "cos_spread");
    lights[0].cos_spread = 1;
    lights[0].axis[1] = NAN;
    expect_error(lights, 4, "axis");
    lights[0].axis[1] = 0;
    lights[0].axis[2] = 1;
    lights[0].intensity = 3e38f;
    lights[1].intensity = 3e38f;
    expect_error(lights, 4, "too large");
    lights[0].intensity = 1;
    lights[1].intensity = 1;

    /* Fixed, the same lights build. */
    light_tree tree;
    build_and_check(lights, 4, &tree);
    light_tree_free(&tree);

    rt_error error = {{0}};
    assert_int_equal(light_tree_build(lights, 4, NULL, &error), RT_ERROR_RUNTIME);
    assert_true(strncmp(error.message, "LIGHT_TREE: ", 12) == 0);
}

static void test_free_is_safe(void **state)
{
    (void)state;
    light_tree tree = {0};
    light_tree_free(&tree);
    light_tree_free(NULL);
    assert_null(tree.nodes);

    light_bounds lights[2] = {make_point(0, 0, 0, 1), make_point(1, 0, 0, 1)};
    build_and_check(lights, 2, &tree);
    light_tree_free(&tree);
    assert_null(tree.nodes);
    assert_null(tree.trails);
    assert_null(tree.depths);
    assert_int_equal(tree.node_count, 0);
    light_tree_free(&tree);  /* twice: harmless */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_light),
        cmocka_unit_test(test_random_sets),
        cmocka_unit_test(test_median_split),
        cmocka_unit_test(test_separate_clusters),
        cmocka_unit_test(test_finite_split_from_infinite),
        cmocka_unit_test(test_cone_union),
        cmocka_unit_test(test_cone_rounding),
        cmocka_unit_test(test_odd_axes),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_free_is_safe),
    };
    return cmocka_run_group_tests_name("light_tree", tests, NULL, NULL);
}
