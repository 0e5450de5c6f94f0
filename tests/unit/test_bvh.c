/* test_bvh.c: unit tests of the BVH builder and its CPU traversal (core/bvh.c).
 *
 * Every tree built here goes through check_tree(), which checks the layout the shader
 * relies on (root 0, contiguous children, leaves covering every primitive slot once, tight
 * boxes, depth limit). Traversal is checked against a brute-force loop over all primitives:
 * same nearest distance, bit for bit, and the same primitive unless two tie.
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

#include "bvh.h"
#include "packed_layout.h"
#include "support.h"

/* ---- boxes ---- */

static bvh_box make_box(float min_x, float min_y, float min_z, float max_x, float max_y, float max_z)
{
    return (bvh_box){{min_x, min_y, min_z}, {max_x, max_y, max_z}};
}

static bvh_box union_of(const bvh_box *a, const bvh_box *b)
{
    bvh_box result;
    for (int axis = 0; axis < 3; axis++) {
        result.min[axis] = fminf(a->min[axis], b->min[axis]);
        result.max[axis] = fmaxf(a->max[axis], b->max[axis]);
    }
    return result;
}

static double surface_area(const bvh_box *box)
{
    double dx = (double)box->max[0] - box->min[0];
    double dy = (double)box->max[1] - box->min[1];
    double dz = (double)box->max[2] - box->min[2];
    return 2.0 * (dx * dy + dy * dz + dz * dx);
}

/* Fills boxes with count random boxes: centres uniform in [-extent, extent]^3, or in a few
 * clusters when clustered; sizes from points to a tenth of the extent, some flat. */
static void random_boxes(random_source *source, bvh_box *boxes, uint32_t count, float extent,
                         bool clustered)
{
    float cluster_centres[8][3];
    for (int cluster = 0; cluster < 8; cluster++)
        for (int axis = 0; axis < 3; axis++)
            cluster_centres[cluster][axis] = random_float(source, -extent, extent);
    for (uint32_t i = 0; i < count; i++) {
        const float *cluster_centre = cluster_centres[random_below(source, 8)];
        uint32_t shape = random_below(source, 8);
        for (int axis = 0; axis < 3; axis++) {
            float centre = clustered ? cluster_centre[axis] + random_float(source, -0.05f, 0.05f) * extent
                                     : random_float(source, -extent, extent);
            float half_size = random_float(source, 0, 0.05f) * extent;
            if (shape == 0 || (shape == 1 && axis == 2))  /* points and flat boxes */
                half_size = 0;
            boxes[i].min[axis] = centre - half_size;
            boxes[i].max[axis] = centre + half_size;
        }
    }
}

/* ---- tree invariants ---- */

/* Checks everything bvh.h promises about tree, built from boxes[0 .. count - 1] with the
 * given max_leaf_size and max_depth: root 0; children contiguous and in range; each node
 * reached exactly once; leaf slots covering 0 .. count - 1 exactly once; primitive_indices a
 * permutation; every box exactly the union of what is below it; depth right and within
 * max_depth; leaves above max_depth no bigger than max_leaf_size. Returns the largest leaf. */
static uint32_t check_tree(const bvh *tree, const bvh_box *boxes, uint32_t count,
                           uint32_t max_leaf_size, int max_depth)
{
    assert_int_equal(tree->primitive_count, count);
    assert_non_null(tree->nodes);
    if (count == 0) {
        assert_int_equal(tree->node_count, 1);
        assert_int_equal(tree->nodes[0].count, 0);
        assert_int_equal(tree->nodes[0].first, 0);
        assert_true(tree->nodes[0].box.min[0] > tree->nodes[0].box.max[0]);
        assert_int_equal(tree->depth, 0);
        return 0;
    }
    assert_non_null(tree->primitive_indices);
    assert_true(tree->node_count >= 1);
    assert_true(tree->node_count <= 2 * count - 1);
    assert_int_equal(tree->node_count % 2, 1);  /* every interior node has two children */

    bool *node_seen = calloc(tree->node_count, sizeof *node_seen);
    bool *slot_seen = calloc(count, sizeof *slot_seen);
    bool *primitive_seen = calloc(count, sizeof *primitive_seen);
    uint32_t *stack_node = malloc(tree->node_count * sizeof *stack_node);
    int *stack_depth = malloc(tree->node_count * sizeof *stack_depth);
    assert_true(node_seen && slot_seen && primitive_seen && stack_node && stack_depth);

    uint32_t stack_size = 0, largest_leaf = 0;
    int deepest = 0;
    stack_node[stack_size] = 0;
    stack_depth[stack_size++] = 0;
    while (stack_size > 0) {
        stack_size--;
        uint32_t index = stack_node[stack_size];
        int depth = stack_depth[stack_size];
        const bvh_node *node = &tree->nodes[index];
        assert_false(node_seen[index]);
        node_seen[index] = true;
        assert_true(depth <= max_depth);
        if (depth > deepest)
            deepest = depth;

        if (node->count > 0) {
            assert_true(node->first < count);
            assert_true(node->count <= count - node->first);
            if (depth < max_depth)
                assert_true(node->count <= max_leaf_size);
            if (node->count > largest_leaf)
                largest_leaf = node->count;
            bvh_box tight = boxes[tree->primitive_indices[node->first]];
            for (uint32_t slot = node->first; slot < node->first + node->count; slot++) {
                assert_false(slot_seen[slot]);
                slot_seen[slot] = true;
                uint32_t primitive = tree->primitive_indices[slot];
                assert_true(primitive < count);
                assert_false(primitive_seen[primitive]);
                primitive_seen[primitive] = true;
                assert_true(box_contains(&node->box, &boxes[primitive]));
                tight = union_of(&tight, &boxes[primitive]);
            }
            assert_true(same_box(&node->box, &tight));
        } else {
            assert_true(node->first >= 1);                 /* the root is nobody's child */
            assert_true(node->first < tree->node_count - 1);  /* first + 1 is in range too */
            const bvh_box *left = &tree->nodes[node->first].box;
            const bvh_box *right = &tree->nodes[node->first + 1].box;
            assert_true(box_contains(&node->box, left));
            assert_true(box_contains(&node->box, right));
            bvh_box tight = union_of(left, right);
            assert_true(same_box(&node->box, &tight));
            for (uint32_t child = 0; child < 2; child++) {
                stack_node[stack_size] = node->first + child;
                stack_depth[stack_size++] = depth + 1;
            }
        }
    }
    for (uint32_t i = 0; i < tree->node_count; i++)
        assert_true(node_seen[i]);
    for (uint32_t i = 0; i < count; i++) {
        assert_true(slot_seen[i]);
        assert_true(primitive_seen[i]);
    }
    assert_int_equal(tree->depth, deepest);
    assert_true(tree->depth <= max_depth);

    free(node_seen);
    free(slot_seen);
    free(primitive_seen);
    free(stack_node);
    free(stack_depth);
    return largest_leaf;
}

/* Builds with config (NULL for defaults), expects success, checks the invariants. */
static void build_and_check(const bvh_box *boxes, uint32_t count, const bvh_build_config *config,
                            bvh *tree)
{
    rt_error error = {{0}};
    if (bvh_build(boxes, count, config, tree, &error) != RT_OK)
        fail_msg("bvh_build failed: %s", error.message);
    uint32_t max_leaf_size = config && config->max_leaf_size ? (uint32_t)config->max_leaf_size : 4;
    int max_depth = config && config->max_depth ? config->max_depth : BVH_MAX_DEPTH;
    check_tree(tree, boxes, count, max_leaf_size, max_depth);
}

/* ---- primitives for traversal tests ---- */

typedef struct sphere {
    float centre[3];
    float radius;
} sphere;

/* Sphere hit in double precision, so that the float distance is within rounding of the true
 * one and padded boxes surely contain every hit the test can report. */
static bool hit_sphere(void *context, uint32_t primitive, const float origin[3],
                       const float direction[3], float t_min, float *t_max)
{
    const sphere *s = &((const sphere *)context)[primitive];
    double offset[3], a = 0, half_b = 0, c = 0;
    for (int axis = 0; axis < 3; axis++) {
        offset[axis] = (double)origin[axis] - s->centre[axis];
        a += (double)direction[axis] * direction[axis];
        half_b += offset[axis] * direction[axis];
        c += offset[axis] * offset[axis];
    }
    c -= (double)s->radius * s->radius;
    double discriminant = half_b * half_b - a * c;
    if (discriminant < 0 || a == 0)
        return false;
    double root = sqrt(discriminant);
    float t = (float)((-half_b - root) / a);
    if (!(t > t_min && t < *t_max)) {
        t = (float)((-half_b + root) / a);
        if (!(t > t_min && t < *t_max))
            return false;
    }
    *t_max = t;
    return true;
}

/* A solid box as a primitive: the surface distance (entry, or exit when the ray starts
 * inside). Written independently of bvh.c but with the same slab rules, so that tight boxes
 * (no padding) must give exactly the brute-force answer. */
static bool hit_box(void *context, uint32_t primitive, const float origin[3],
                    const float direction[3], float t_min, float *t_max)
{
    const bvh_box *box = &((const bvh_box *)context)[primitive];
    float entry = -INFINITY, exit = INFINITY;
    for (int axis = 0; axis < 3; axis++) {
        float inverse = 1.0f / direction[axis];
        bool backwards = signbit(inverse) != 0;
        float t_near = ((backwards ? box->max[axis] : box->min[axis]) - origin[axis]) * inverse;
        float t_far = ((backwards ? box->min[axis] : box->max[axis]) - origin[axis]) * inverse;
        if (t_near > entry)  /* NaN (origin on the plane, direction parallel) is ignored */
            entry = t_near;
        if (t_far < exit)
            exit = t_far;
    }
    if (!(entry <= exit))
        return false;
    float t = entry > t_min ? entry : exit;
    if (!(t > t_min && t < *t_max))
        return false;
    *t_max = t;
    return true;
}

static uint32_t brute_force_nearest(uint32_t count, bvh_primitive_test test, void *context,
                                    const float origin[3], const float direction[3], float t_min,
                                    float t_max, float *t_hit)
{
    uint32_t nearest = UINT32_MAX;
    for (uint32_t primitive = 0; primitive < count; primitive++)
        if (test(context, primitive, origin, direction, t_min, &t_max))
            nearest = primitive;
    if (nearest != UINT32_MAX)
        *t_hit = t_max;
    return nearest;
}

/* Asserts that the tree finds what brute force finds. Returns whether anything was hit. */
static bool expect_brute_force_answer(const bvh *tree, uint32_t count, bvh_primitive_test test,
                                      void *context, const float origin[3],
                                      const float direction[3], float t_min, float t_max)
{
    float expected_t = NAN, found_t = NAN;
    uint32_t expected = brute_force_nearest(count, test, context, origin, direction, t_min, t_max,
                                            &expected_t);
    uint32_t found = bvh_intersect_nearest(tree, origin, direction, t_min, t_max, test, context,
                                           &found_t);
    if (expected == UINT32_MAX) {
        assert_int_equal(found, UINT32_MAX);
        return false;
    }
    assert_int_not_equal(found, UINT32_MAX);
    assert_true(found_t == expected_t);
    if (found != expected) {
        /* A tie: the other primitive must be hit at exactly the same distance. */
        float own_t = t_max;
        assert_true(test(context, found, origin, direction, t_min, &own_t));
        assert_true(own_t == expected_t);
    }
    return true;
}

static void normalize(float vector[3])
{
    float length = sqrtf(vector[0] * vector[0] + vector[1] * vector[1] + vector[2] * vector[2]);
    if (length > 0)
        for (int axis = 0; axis < 3; axis++)
            vector[axis] /= length;
}

/* Makes a random ray for a scene of boxes around [-extent, extent]^3: from outside or
 * inside boxes, aimed at a box, along an axis (other components +0 or -0), or starting
 * exactly on a box's plane and running parallel to it. Never a zero direction. */
static void random_ray(random_source *source, const bvh_box *boxes, uint32_t count, float extent,
                       float origin[3], float direction[3])
{
    const bvh_box *target = &boxes[random_below(source, count)];
    for (int axis = 0; axis < 3; axis++) {
        origin[axis] = random_float(source, -1.5f * extent, 1.5f * extent);
        direction[axis] = random_float(source, -1, 1);
    }
    switch (random_below(source, 6)) {
    case 0:  /* from anywhere, anywhere */
        break;
    case 1:  /* from inside a box */
        for (int axis = 0; axis < 3; axis++)
            origin[axis] = random_float(source, target->min[axis], target->max[axis]);
        break;
    case 2: {  /* along an axis */
        int along = (int)random_below(source, 3);
        for (int axis = 0; axis < 3; axis++)
            direction[axis] = random_below(source, 2) ? 0.0f : -0.0f;
        direction[along] = random_below(source, 2) ? 1.0f : -1.0f;
        break;
    }
    case 3:  /* one zero component */
        direction[random_below(source, 3)] = random_below(source, 2) ? 0.0f : -0.0f;
        break;
    case 4: {  /* on a plane of a box, parallel to it */
        int axis = (int)random_below(source, 3);
        origin[axis] = random_below(source, 2) ? target->min[axis] : target->max[axis];
        direction[axis] = random_below(source, 2) ? 0.0f : -0.0f;
        break;
    }
    default:  /* at a box's centre */
        for (int axis = 0; axis < 3; axis++)
            direction[axis] = (0.5f * target->min[axis] + 0.5f * target->max[axis]) - origin[axis];
        break;
    }
    if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0)
        direction[0] = 1;
    normalize(direction);
}

/* Draws a ray interval: mostly (0, inf), sometimes starting later, ending sooner, or
 * starting behind the origin (a line rather than a ray). */
static void random_interval(random_source *source, float extent, float *t_min, float *t_max)
{
    *t_min = 0;
    *t_max = INFINITY;
    uint32_t kind = random_below(source, 5);
    if (kind == 1)
        *t_min = random_float(source, 0, extent);
    else if (kind == 2)
        *t_max = random_float(source, 0, 2 * extent);
    else if (kind == 3)
        *t_min = -random_float(source, 0, 2 * extent);
}

/* Runs ray_count random rays through a scene of box primitives and compares with brute
 * force. Returns how many rays hit something, so that callers can check the rays mattered. */
static uint32_t compare_box_scene(random_source *source, const bvh_box *boxes, uint32_t count,
                                  float extent, uint32_t ray_count)
{
    bvh tree;
    build_and_check(boxes, count, NULL, &tree);
    uint32_t hits = 0;
    for (uint32_t ray = 0; ray < ray_count; ray++) {
        float origin[3], direction[3], t_min, t_max;
        random_ray(source, boxes, count, extent, origin, direction);
        random_interval(source, extent, &t_min, &t_max);
        hits += expect_brute_force_answer(&tree, count, hit_box, (void *)boxes, origin, direction,
                                          t_min, t_max);
    }
    bvh_free(&tree);
    return hits;
}

/* ---- tests ---- */

static void test_defaults_are_zero(void **state)
{
    (void)state;
    bvh_build_config config = bvh_build_config_defaults();
    assert_int_equal(config.max_leaf_size, 0);
    assert_int_equal(config.bin_count, 0);
    assert_int_equal(config.max_depth, 0);
    assert_true(config.traversal_cost == 0 && config.intersection_cost == 0);
}

static void test_empty_input(void **state)
{
    (void)state;
    bvh tree;
    rt_error error = {{0}};
    assert_int_equal(bvh_build(NULL, 0, NULL, &tree, &error), RT_OK);
    check_tree(&tree, NULL, 0, 4, BVH_MAX_DEPTH);
    assert_true(isinf(tree.nodes[0].box.min[0]) && tree.nodes[0].box.min[0] > 0);

    float origin[3] = {0, 0, 0}, direction[3] = {1, 0, 0}, t_hit = 42;
    assert_int_equal(bvh_intersect_nearest(&tree, origin, direction, 0, INFINITY, hit_box, NULL, &t_hit),
                     UINT32_MAX);
    assert_true(t_hit == 42);  /* untouched on a miss */
    bvh_free(&tree);
    assert_null(tree.nodes);
    assert_int_equal(tree.node_count, 0);
}

static void test_one_primitive(void **state)
{
    (void)state;
    bvh_box box = make_box(5, -1, -1, 6, 1, 1);
    bvh tree;
    build_and_check(&box, 1, NULL, &tree);
    assert_int_equal(tree.node_count, 1);
    assert_int_equal(tree.nodes[0].count, 1);
    assert_int_equal(tree.primitive_indices[0], 0);
    assert_int_equal(tree.depth, 0);

    float origin[3] = {0, 0, 0}, direction[3] = {1, 0, 0}, t_hit = 0;
    assert_int_equal(bvh_intersect_nearest(&tree, origin, direction, 0, INFINITY, hit_box, &box, &t_hit), 0);
    assert_true(t_hit == 5);
    /* The interval is honoured: before the box nothing; from inside it the exit. */
    assert_int_equal(bvh_intersect_nearest(&tree, origin, direction, 0, 4, hit_box, &box, &t_hit), UINT32_MAX);
    assert_int_equal(bvh_intersect_nearest(&tree, origin, direction, 5.5f, INFINITY, hit_box, &box, &t_hit), 0);
    assert_true(t_hit == 6);
    float backwards[3] = {-1, 0, 0};
    assert_int_equal(bvh_intersect_nearest(&tree, origin, backwards, 0, INFINITY, hit_box, &box, &t_hit),
                     UINT32_MAX);
    bvh_free(&tree);
}

static void test_two_primitives(void **state)
{
    (void)state;
    /* Far apart: splitting costs much less than testing both. */
    bvh_box apart[2] = {make_box(10, 0, 0, 11, 1, 1), make_box(0, 0, 0, 1, 1, 1)};
    bvh tree;
    build_and_check(apart, 2, NULL, &tree);
    assert_int_equal(tree.node_count, 3);
    assert_int_equal(tree.depth, 1);
    assert_int_equal(tree.nodes[0].count, 0);
    assert_int_equal(tree.nodes[0].first, 1);

    float origin[3] = {-5, 0.5f, 0.5f}, direction[3] = {1, 0, 0}, t_hit = 0;
    assert_int_equal(bvh_intersect_nearest(&tree, origin, direction, 0, INFINITY, hit_box, apart, &t_hit), 1);
    assert_true(t_hit == 5);
    float from_far_side[3] = {20, 0.5f, 0.5f}, backwards[3] = {-1, 0, 0};
    assert_int_equal(bvh_intersect_nearest(&tree, from_far_side, backwards, 0, INFINITY, hit_box, apart, &t_hit), 0);
    assert_true(t_hit == 9);
    bvh_free(&tree);

    /* The same box twice: nothing separates them and two fit one leaf. */
    bvh_box same[2] = {make_box(0, 0, 0, 1, 1, 1), make_box(0, 0, 0, 1, 1, 1)};
    build_and_check(same, 2, NULL, &tree);
    assert_int_equal(tree.node_count, 1);
    assert_int_equal(tree.nodes[0].count, 2);
    bvh_free(&tree);
}

static void test_identical_boxes(void **state)
{
    (void)state;
    enum { COUNT = 1000 };
    bvh_box *boxes = malloc(COUNT * sizeof *boxes);
    assert_non_null(boxes);
    for (uint32_t i = 0; i < COUNT; i++)
        boxes[i] = make_box(1, 1, 1, 2, 2, 2);
    bvh tree;
    build_and_check(boxes, COUNT, NULL, &tree);
    /* Median halving: 1000 -> 500 -> ... -> 3 or 4 after 8 levels. */
    assert_int_equal(tree.depth, 8);
    float origin[3] = {0, 1.5f, 1.5f}, direction[3] = {1, 0, 0}, t_hit = 0;
    uint32_t hit = bvh_intersect_nearest(&tree, origin, direction, 0, INFINITY, hit_box, boxes, &t_hit);
    assert_true(hit < COUNT);
    assert_true(t_hit == 1);
    bvh_free(&tree);
    free(boxes);
}

static void test_point_boxes(void **state)
{
    (void)state;
    enum { COUNT = 2000 };
    random_source source = {7};
    bvh_box *boxes = malloc(COUNT * sizeof *boxes);
    assert_non_null(boxes);
    /* Integer grid points in [0, 12]^3: zero-size boxes, many of them duplicates. */
    for (uint32_t i = 0; i < COUNT; i++) {
        float point[3];
        for (int axis = 0; axis < 3; axis++)
            point[axis] = (float)random_below(&source, 13);
        boxes[i] = make_box(point[0], point[1], point[2], point[0], point[1], point[2]);
    }
    bvh tree;
    build_and_check(boxes, COUNT, NULL, &tree);

    /* A ray along x exactly through a point: the y and z slabs give 0 * inf = NaN and must
     * not hide it. */
    for (uint32_t i = 0; i < 200; i++) {
        const bvh_box *target = &boxes[random_below(&source, COUNT)];
        float origin[3] = {target->min[0] - 5.5f, target->min[1], target->min[2]};
        float direction[3] = {1, random_below(&source, 2) ? 0.0f : -0.0f, 0};
        assert_true(expect_brute_force_answer(&tree, COUNT, hit_box, boxes, origin, direction, 0, INFINITY));
        float t_hit = 0;
        assert_true(bvh_intersect_nearest(&tree, origin, direction, 0, INFINITY, hit_box, boxes, &t_hit) < COUNT);
        assert_true(t_hit <= 5.5f);
    }
    bvh_free(&tree);
    assert_true(compare_box_scene(&source, boxes, COUNT, 6, 1000) > 0);
    free(boxes);
}

static void test_flat_boxes(void **state)
{
    (void)state;
    enum { COUNT = 1500 };
    random_source source = {11};
    bvh_box *boxes = malloc(COUNT * sizeof *boxes);
    assert_non_null(boxes);
    /* All in the plane z = 0.25. */
    for (uint32_t i = 0; i < COUNT; i++) {
        float x = random_float(&source, -10, 10), y = random_float(&source, -10, 10);
        float w = random_float(&source, 0, 0.5f), h = random_float(&source, 0, 0.5f);
        boxes[i] = make_box(x, y, 0.25f, x + w, y + h, 0.25f);
    }
    bvh tree;
    build_and_check(boxes, COUNT, NULL, &tree);
    assert_true(tree.nodes[0].box.min[2] == 0.25f && tree.nodes[0].box.max[2] == 0.25f);
    bvh_free(&tree);
    assert_true(compare_box_scene(&source, boxes, COUNT, 10, 3000) > 100);

    /* Boxes along a line (zero area everywhere): the SAH must still split them. */
    for (uint32_t i = 0; i < COUNT; i++) {
        float x = random_float(&source, -10, 10);
        boxes[i] = make_box(x, 1, 2, x + random_float(&source, 0, 0.1f), 1, 2);
    }
    build_and_check(boxes, COUNT, NULL, &tree);
    assert_true(tree.depth < 20);
    bvh_free(&tree);
    free(boxes);
}

static void test_huge_coordinates(void **state)
{
    (void)state;
    enum { COUNT = 1200 };
    random_source source = {13};
    bvh_box *boxes = malloc(COUNT * sizeof *boxes);
    assert_non_null(boxes);
    /* Mixed scales, from 1e-30 to near FLT_MAX, with extents and centre sums that
     * overflow float. */
    const float scales[4] = {3.0e38f, 1.0e20f, 1.0f, 1.0e-30f};
    for (uint32_t i = 0; i < COUNT; i++) {
        float scale = scales[i % 4];
        for (int axis = 0; axis < 3; axis++) {
            float a = random_float(&source, -scale, scale), b = random_float(&source, -scale, scale);
            boxes[i].min[axis] = fminf(a, b);
            boxes[i].max[axis] = i % 8 == 0 ? fminf(a, b) : fmaxf(a, b);
        }
    }
    boxes[0] = make_box(3.4e38f, 3.4e38f, 3.4e38f, 3.4e38f, 3.4e38f, 3.4e38f);
    boxes[1] = make_box(-3.4e38f, -3.4e38f, -3.4e38f, -3.4e38f, -3.4e38f, -3.4e38f);
    bvh tree;
    build_and_check(boxes, COUNT, NULL, &tree);
    bvh_free(&tree);
    assert_true(compare_box_scene(&source, boxes, COUNT, 3.0e38f, 2000) > 100);

    /* The small ones near the origin must still be separated from each other. */
    bvh_box tiny[64];
    for (uint32_t i = 0; i < 64; i++) {
        float x = (float)i * 1e-30f;
        tiny[i] = make_box(x, 0, 0, x + 1e-31f, 1e-31f, 1e-31f);
    }
    build_and_check(tiny, 64, NULL, &tree);
    assert_true(tree.node_count > 1);
    bvh_free(&tree);
    free(boxes);
}

static void test_random_invariants(void **state)
{
    (void)state;
    const uint32_t sizes[] = {1, 2, 3, 4, 5, 7, 16, 33, 100, 257, 1000, 5000};
    const bvh_build_config configs[] = {
        {0},
        {.max_leaf_size = 1},
        {.max_leaf_size = 8, .bin_count = 2},
        {.bin_count = 256},
        {.max_depth = 6},
        {.max_leaf_size = 255, .intersection_cost = 10, .traversal_cost = 0.5f},
        {.traversal_cost = 100},
    };
    bvh_box *boxes = malloc(5000 * sizeof *boxes);
    assert_non_null(boxes);
    for (uint64_t seed = 1; seed <= 4; seed++) {
        random_source source = {seed};
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
            random_boxes(&source, boxes, sizes[s], 100, seed % 2 == 0);
            for (size_t c = 0; c < sizeof configs / sizeof configs[0]; c++) {
                bvh tree;
                build_and_check(boxes, sizes[s], &configs[c], &tree);
                if (configs[c].max_leaf_size == 1 && configs[c].max_depth == 0 && sizes[s] <= 1000) {
                    /* One primitive per leaf: every node that can exist does. */
                    assert_int_equal(tree.node_count, 2 * sizes[s] - 1);
                }
                bvh_free(&tree);
            }
        }
    }
    free(boxes);
}

static void test_max_depth_adversarial(void **state)
{
    (void)state;
    enum { COUNT = 200 };
    bvh_box boxes[COUNT];
    /* Exponentially spaced: each SAH split peels off only the biggest, farthest box, so an
     * unlimited tree would be about COUNT levels deep. */
    float position = 1;
    for (uint32_t i = 0; i < COUNT; i++) {
        boxes[i] = make_box(position, 0, 0, position * 1.25f, 1, 1);
        position *= 1.5f;
    }
    bvh tree;
    bvh_build_config shallow = {.max_depth = 4};
    build_and_check(boxes, COUNT, &shallow, &tree);
    assert_int_equal(tree.depth, 4);
    uint32_t largest_leaf = check_tree(&tree, boxes, COUNT, 4, 4);
    assert_true(largest_leaf > 4);  /* the depth limit forced a big leaf */
    bvh_free(&tree);

    build_and_check(boxes, COUNT, NULL, &tree);
    assert_true(tree.depth > 4);
    assert_true(tree.depth <= BVH_MAX_DEPTH);

    random_source source = {17};
    for (uint32_t ray = 0; ray < 500; ray++) {
        float origin[3] = {random_float(&source, -10, 1e30f), 0.5f, 0.5f};
        float direction[3] = {random_below(&source, 2) ? 1.0f : -1.0f, 0, 0};
        expect_brute_force_answer(&tree, COUNT, hit_box, boxes, origin, direction, 0, INFINITY);
    }
    bvh_free(&tree);

    bvh_build_config one_level = {.max_depth = 1};
    build_and_check(boxes, COUNT, &one_level, &tree);
    assert_int_equal(tree.node_count, 3);
    bvh_free(&tree);
}

static void test_spheres_against_brute_force(void **state)
{
    (void)state;
    const uint32_t scene_sizes[] = {1, 3, 60, 2000};
    for (uint32_t scene = 0; scene < 4; scene++) {
        random_source source = {100 + scene};
        uint32_t count = scene_sizes[scene];
        sphere *spheres = malloc(count * sizeof *spheres);
        bvh_box *boxes = malloc(count * sizeof *boxes);
        assert_true(spheres && boxes);
        float extent = 10;
        for (uint32_t i = 0; i < count; i++) {
            for (int axis = 0; axis < 3; axis++)
                spheres[i].centre[axis] = random_float(&source, -extent, extent);
            spheres[i].radius = random_float(&source, 0.01f, 1.0f);
            /* Padded a little beyond the rounding of the hit distance, as a renderer would. */
            float pad = spheres[i].radius * 1e-3f + 1e-4f;
            for (int axis = 0; axis < 3; axis++) {
                boxes[i].min[axis] = spheres[i].centre[axis] - spheres[i].radius - pad;
                boxes[i].max[axis] = spheres[i].centre[axis] + spheres[i].radius + pad;
            }
        }
        /* Some exact duplicates, to make ties. */
        if (count > 10)
            for (uint32_t i = 0; i < 5; i++) {
                spheres[count - 1 - i] = spheres[i];
                boxes[count - 1 - i] = boxes[i];
            }
        bvh tree;
        build_and_check(boxes, count, NULL, &tree);
        uint32_t hits = 0;
        for (uint32_t ray = 0; ray < 3000; ray++) {
            float origin[3], direction[3], t_min, t_max;
            random_ray(&source, boxes, count, extent, origin, direction);
            random_interval(&source, extent, &t_min, &t_max);
            hits += expect_brute_force_answer(&tree, count, hit_sphere, spheres, origin, direction,
                                              t_min, t_max);
        }
        assert_true(hits > 300);
        bvh_free(&tree);
        free(spheres);
        free(boxes);
    }
}

static void test_boxes_against_brute_force(void **state)
{
    (void)state;
    const uint32_t scene_sizes[] = {2, 17, 500, 3000};
    for (uint32_t scene = 0; scene < 4; scene++) {
        random_source source = {200 + scene};
        uint32_t count = scene_sizes[scene];
        bvh_box *boxes = malloc(count * sizeof *boxes);
        assert_non_null(boxes);
        random_boxes(&source, boxes, count, 50, scene % 2 == 1);
        assert_true(compare_box_scene(&source, boxes, count, 50, 3000) > 300);
        free(boxes);
    }
}

/* The SAH cost of a subtree: traversal cost 1 per interior node and 1 per primitive,
 * each weighted by the node's surface area. */
static double tree_cost(const bvh *tree, uint32_t index)
{
    const bvh_node *node = &tree->nodes[index];
    double area = surface_area(&node->box);
    if (node->count > 0)
        return area * node->count;
    return area + tree_cost(tree, node->first) + tree_cost(tree, node->first + 1);
}

static const bvh_box *median_sort_boxes;
static int median_sort_axis;

static int compare_centroids(const void *a, const void *b)
{
    const bvh_box *box_a = &median_sort_boxes[*(const uint32_t *)a];
    const bvh_box *box_b = &median_sort_boxes[*(const uint32_t *)b];
    float centre_a = box_a->min[median_sort_axis] + box_a->max[median_sort_axis];
    float centre_b = box_b->min[median_sort_axis] + box_b->max[median_sort_axis];
    return (centre_a > centre_b) - (centre_a < centre_b);
}

/* The same cost for a tree that splits at the median of the widest axis, leaves of <= 4. */
static double median_tree_cost(const bvh_box *boxes, uint32_t *indices, uint32_t count)
{
    bvh_box box = boxes[indices[0]];
    for (uint32_t i = 1; i < count; i++)
        box = union_of(&box, &boxes[indices[i]]);
    double area = surface_area(&box);
    if (count <= 4)
        return area * count;
    int widest = 0;
    for (int axis = 1; axis < 3; axis++)
        if (box.max[axis] - box.min[axis] > box.max[widest] - box.min[widest])
            widest = axis;
    median_sort_boxes = boxes;
    median_sort_axis = widest;
    qsort(indices, count, sizeof *indices, compare_centroids);
    return area + median_tree_cost(boxes, indices, count / 2) +
           median_tree_cost(boxes, indices + count / 2, count - count / 2);
}

static void test_sah_quality(void **state)
{
    (void)state;
    enum { HALF = 500 };
    random_source source = {31};
    bvh_box boxes[2 * HALF];
    /* Two clusters far apart along x. */
    for (uint32_t i = 0; i < 2 * HALF; i++) {
        float offset = i < HALF ? 0 : 1000;
        float x = offset + random_float(&source, 0, 10), y = random_float(&source, 0, 10),
              z = random_float(&source, 0, 10);
        boxes[i] = make_box(x, y, z, x + 0.1f, y + 0.1f, z + 0.1f);
    }
    bvh tree;
    build_and_check(boxes, 2 * HALF, NULL, &tree);
    const bvh_node *left = &tree.nodes[tree.nodes[0].first];
    const bvh_node *right = &tree.nodes[tree.nodes[0].first + 1];
    assert_int_equal(tree.nodes[0].count, 0);
    bool left_is_near = left->box.max[0] < 500;
    const bvh_node *near = left_is_near ? left : right, *far = left_is_near ? right : left;
    assert_true(near->box.max[0] < 11);
    assert_true(far->box.min[0] >= 1000);
    bvh_free(&tree);

    /* Clustered boxes of mixed sizes: cheaper than splitting at the median. */
    enum { COUNT = 4000 };
    bvh_box *clustered = malloc(COUNT * sizeof *clustered);
    uint32_t *indices = malloc(COUNT * sizeof *indices);
    assert_true(clustered && indices);
    random_boxes(&source, clustered, COUNT, 100, true);
    for (uint32_t i = 0; i < COUNT / 10; i++) {  /* a sparse background of big boxes */
        float x = random_float(&source, -100, 100), y = random_float(&source, -100, 100);
        clustered[i] = make_box(x, y, -100, x + 5, y + 5, -95);
    }
    for (uint32_t i = 0; i < COUNT; i++)
        indices[i] = i;
    build_and_check(clustered, COUNT, NULL, &tree);
    double sah = tree_cost(&tree, 0), median = median_tree_cost(clustered, indices, COUNT);
    assert_true(sah < median);
    bvh_free(&tree);
    free(clustered);
    free(indices);
}

static void test_deterministic(void **state)
{
    (void)state;
    enum { COUNT = 3000 };
    random_source source = {41};
    bvh_box *boxes = malloc(COUNT * sizeof *boxes);
    assert_non_null(boxes);
    random_boxes(&source, boxes, COUNT, 10, true);
    bvh first, second;
    build_and_check(boxes, COUNT, NULL, &first);
    build_and_check(boxes, COUNT, NULL, &second);
    assert_int_equal(first.node_count, second.node_count);
    assert_int_equal(first.depth, second.depth);
    assert_memory_equal(first.nodes, second.nodes, first.node_count * sizeof *first.nodes);
    assert_memory_equal(first.primitive_indices, second.primitive_indices, COUNT * sizeof(uint32_t));
    bvh_free(&first);
    bvh_free(&second);
    free(boxes);
}

/* Expects bvh_build() to refuse with RT_ERROR_INPUT, a "BVH: " message mentioning
 * must_mention, and a zeroed output. */
static void expect_input_error(const bvh_box *boxes, uint32_t count, const bvh_build_config *config,
                               const char *must_mention)
{
    bvh tree = {.node_count = 99};
    rt_error error = {{0}};
    assert_int_equal(bvh_build(boxes, count, config, &tree, &error), RT_ERROR_INPUT);
    assert_true(strncmp(error.message, "BVH: ", 5) == 0);
    assert_non_null(strstr(error.message, must_mention));
    assert_null(tree.nodes);
    assert_null(tree.primitive_indices);
    assert_int_equal(tree.node_count, 0);
}

static void test_config_validation(void **state)
{
    (void)state;
    bvh_box boxes[3] = {make_box(0, 0, 0, 1, 1, 1), make_box(2, 0, 0, 3, 1, 1), make_box(4, 0, 0, 5, 1, 1)};
    expect_input_error(boxes, 3, &(bvh_build_config){.max_leaf_size = -1}, "max_leaf_size");
    expect_input_error(boxes, 3, &(bvh_build_config){.max_leaf_size = 256}, "max_leaf_size");
    expect_input_error(boxes, 3, &(bvh_build_config){.bin_count = -3}, "bin_count");
    expect_input_error(boxes, 3, &(bvh_build_config){.bin_count = 1}, "bin_count");
    expect_input_error(boxes, 3, &(bvh_build_config){.bin_count = 257}, "bin_count");
    expect_input_error(boxes, 3, &(bvh_build_config){.max_depth = -1}, "max_depth");
    expect_input_error(boxes, 3, &(bvh_build_config){.max_depth = BVH_MAX_DEPTH + 1}, "max_depth");
    expect_input_error(boxes, 3, &(bvh_build_config){.traversal_cost = -1}, "traversal_cost");
    expect_input_error(boxes, 3, &(bvh_build_config){.traversal_cost = NAN}, "traversal_cost");
    expect_input_error(boxes, 3, &(bvh_build_config){.intersection_cost = -0.5f}, "intersection_cost");
    expect_input_error(boxes, 3, &(bvh_build_config){.intersection_cost = INFINITY}, "intersection_cost");
    /* Bad config is reported even with no primitives. */
    expect_input_error(NULL, 0, &(bvh_build_config){.bin_count = 1000}, "bin_count");
    expect_input_error(NULL, 3, NULL, "no boxes");

    /* The limits themselves are fine. */
    const bvh_build_config limits[] = {
        {.max_leaf_size = 255, .bin_count = 256, .max_depth = BVH_MAX_DEPTH},
        {.max_leaf_size = 1, .bin_count = 2, .max_depth = 1},
    };
    for (int i = 0; i < 2; i++) {
        bvh tree;
        build_and_check(boxes, 3, &limits[i], &tree);
        bvh_free(&tree);
    }

    rt_error error = {{0}};
    assert_int_equal(bvh_build(boxes, 3, NULL, NULL, &error), RT_ERROR_INPUT);
    assert_true(strncmp(error.message, "BVH: ", 5) == 0);
}

static void test_invalid_boxes(void **state)
{
    (void)state;
    bvh_box boxes[10];
    for (uint32_t i = 0; i < 10; i++)
        boxes[i] = make_box((float)i, 0, 0, (float)i + 1, 1, 1);
    boxes[7].min[1] = NAN;
    expect_input_error(boxes, 10, NULL, "primitive 7");
    expect_input_error(boxes, 10, NULL, "NaN");
    boxes[7].min[1] = 0;
    boxes[3].max[2] = INFINITY;
    expect_input_error(boxes, 10, NULL, "primitive 3");
    boxes[3].max[2] = 1;
    boxes[0].min[0] = -INFINITY;
    expect_input_error(boxes, 10, NULL, "primitive 0");
    boxes[0].min[0] = 0;
    boxes[9].min[0] = 20;  /* inside out */
    expect_input_error(boxes, 10, NULL, "primitive 9");
    boxes[9].min[0] = 9;
    bvh tree;
    build_and_check(boxes, 10, NULL, &tree);
    bvh_free(&tree);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_are_zero),
        cmocka_unit_test(test_empty_input),
        cmocka_unit_test(test_one_primitive),
        cmocka_unit_test(test_two_primitives),
        cmocka_unit_test(test_identical_boxes),
        cmocka_unit_test(test_point_boxes),
        cmocka_unit_test(test_flat_boxes),
        cmocka_unit_test(test_huge_coordinates),
        cmocka_unit_test(test_random_invariants),
        cmocka_unit_test(test_max_depth_adversarial),
        cmocka_unit_test(test_spheres_against_brute_force),
        cmocka_unit_test(test_boxes_against_brute_force),
        cmocka_unit_test(test_sah_quality),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_config_validation),
        cmocka_unit_test(test_invalid_boxes),
    };
    return cmocka_run_group_tests_name("bvh", tests, NULL, NULL);
}
