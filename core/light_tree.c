/* light_tree.c: see light_tree.h.
 *
 * Build: top down, one light a leaf. A node's lights are items[begin .. end - 1] of a
 * private array of build items (box centre, split key, light index); splitting a node
 * reorders its range so that the first child's lights come first. The median split does
 * not sort: a quickselect puts the count / 2 smallest items (by key, then light index)
 * before the others in linear time on average, which is all a median split needs. Since
 * (key, index) is a total order, which lights go to which child does not depend on how the
 * range was ordered before, so the tree is the same on every run and every libc.
 *
 * The recursion reserves both children's slots, builds the first child's subtree and then
 * the second's, and fills the node from its two finished children on the way back up (the
 * box union, the cone union, the sums). It recurses at most 25 levels (LIGHT_TREE_MAX_LIGHTS).
 *
 * Cones of normals are merged in double as pbrt-v4's DirectionCone Union does, then stored
 * in float rounded outwards (see merge_cones()).
 */
#include "light_tree.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(24 + 1 <= LIGHT_TREE_MAX_DEPTH, "2^24 lights need 25 levels");

/* Angles a merged cone is widened by, so that rounding (of the axis to float, of the
 * angles' arithmetic) never leaves a child's cone sticking out of its parent's: float
 * rounding of a unit axis moves it by about 1e-7 rad, a hundred times less. */
#define CONE_WIDENING 1e-5

/* Quickselect rounds before falling back to sorting the rest of a range: average inputs
 * need a few dozen for 2^24 lights; only a pathological order gets here. */
#define SELECT_ROUNDS 128

/* A light while the tree is built. */
typedef struct build_item {
    float centroid[3];   /* the centre of a finite light's box */
    float key;           /* the coordinate the current split orders by (0 for infinite-only sets) */
    uint32_t light;      /* its index in the caller's array */
    bool infinite;
} build_item;

/* What the recursion shares. */
typedef struct build_state {
    const light_bounds *lights;
    build_item *items;
    light_tree *tree;
    uint32_t node_count;   /* nodes reserved so far */
} build_state;

/* A subtree's sums, kept in double all the way up so that the root's is as exact as one
 * sum over every light. */
typedef struct node_sums {
    double intensity;
    double irradiance;
} node_sums;

/* Returns whether a light's finite number is a finite number >= 0. */
static bool finite_non_negative(float value)
{
    return isfinite(value) && value >= 0;
}

/* Checks what light_tree.h says a light's bounds must be. Returns RT_OK, or
 * RT_ERROR_RUNTIME naming the light and the bad field. */
static rt_status check_light(const light_bounds *light, uint32_t index, rt_error *error)
{
    static const char axis_names[3] = {'x', 'y', 'z'};
    if (!finite_non_negative(light->intensity))
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "LIGHT_TREE: light %u has intensity %g; it must be a finite number >= 0", index,
                            (double)light->intensity);
    if (!finite_non_negative(light->irradiance))
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "LIGHT_TREE: light %u has irradiance %g; it must be a finite number >= 0", index,
                            (double)light->irradiance);
    /* An infinite light's box is not used: whatever is there is fine. */
    for (int axis = 0; axis < 3 && !light->infinite; axis++) {
        float low = light->box.min[axis], high = light->box.max[axis];
        if (!isfinite(low) || !isfinite(high))
            return rt_error_set(error, RT_ERROR_RUNTIME,
                                "LIGHT_TREE: the box of light %u has a %s %c coordinate", index,
                                isnan(low) || isnan(high) ? "NaN" : "infinite", axis_names[axis]);
        if (low > high)
            return rt_error_set(error, RT_ERROR_RUNTIME,
                                "LIGHT_TREE: the box of light %u has min %g > max %g on %c", index, (double)low,
                                (double)high, axis_names[axis]);
    }
    if (!(light->cos_spread >= -1 && light->cos_spread <= 1))
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "LIGHT_TREE: light %u has cos_spread %g; it must be in [-1, 1]", index,
                            (double)light->cos_spread);
    if (light->cos_spread > -1)
        for (int axis = 0; axis < 3; axis++)
            if (!isfinite(light->axis[axis]))
                return rt_error_set(error, RT_ERROR_RUNTIME, "LIGHT_TREE: light %u has a %s axis %c component",
                                    index, isnan(light->axis[axis]) ? "NaN" : "infinite", axis_names[axis]);
    return RT_OK;
}

/* ---- ordering ---- */

/* Returns whether item a goes before item b: by key, then by light index, a total order
 * (keys hold no NaN), so that a median split has one answer. */
static bool item_before(const build_item *a, const build_item *b)
{
    return a->key < b->key || (a->key == b->key && a->light < b->light);
}

/* qsort comparator of the same order. */
static int compare_items(const void *a, const void *b)
{
    const build_item *x = a, *y = b;
    return item_before(x, y) ? -1 : item_before(y, x) ? 1 : 0;
}

static void swap_items(build_item *items, uint32_t i, uint32_t j)
{
    build_item swapped = items[i];
    items[i] = items[j];
    items[j] = swapped;
}

/* Reorders items[begin .. end - 1] so that items[middle] is where sorting would put it:
 * every item before it goes before it and every item after goes after (a quickselect with
 * a median-of-three pivot; the items are distinct under item_before, so a plain Lomuto
 * partition has no duplicates to degrade on). */
static void select_middle(build_item *items, uint32_t begin, uint32_t end, uint32_t middle)
{
    for (int round = 0; end - begin > 1; round++) {
        if (round == SELECT_ROUNDS) {
            qsort(items + begin, end - begin, sizeof *items, compare_items);
            return;
        }
        uint32_t last = end - 1, centre = begin + (end - begin) / 2;
        /* Smallest of the three to begin, the median of the three to last: the pivot. */
        if (item_before(&items[centre], &items[begin]))
            swap_items(items, centre, begin);
        if (item_before(&items[last], &items[begin]))
            swap_items(items, last, begin);
        if (item_before(&items[centre], &items[last]))
            swap_items(items, centre, last);
        uint32_t store = begin;
        for (uint32_t i = begin; i < last; i++)
            if (item_before(&items[i], &items[last]))
                swap_items(items, i, store++);
        swap_items(items, store, last);
        if (store == middle)
            return;
        if (middle < store)
            end = store;
        else
            begin = store + 1;
    }
}

/* Splits the lights items[begin .. end - 1] (at least two) as light_tree.h says: finite
 * from infinite first, else at the median of the centres along the longest axis of their
 * box (infinite-only: of the light indices). Returns the index of the first item of the
 * second child. */
static uint32_t split_items(build_item *items, uint32_t begin, uint32_t end)
{
    uint32_t finite_count = 0;
    for (uint32_t i = begin; i < end; i++)
        finite_count += !items[i].infinite;
    if (finite_count > 0 && finite_count < end - begin) {
        /* Finite first; the order inside each group does not matter (see the top). */
        uint32_t store = begin;
        for (uint32_t i = begin; i < end; i++)
            if (!items[i].infinite)
                swap_items(items, i, store++);
        return store;
    }

    int axis = 0;
    if (finite_count > 0) {
        bvh_box centres = bvh_box_empty();
        for (uint32_t i = begin; i < end; i++)
            bvh_box_add_point(&centres, items[i].centroid);
        /* In double: max - min of floats near FLT_MAX overflows float. Ties keep the lower
         * axis. */
        double longest = -1;
        for (int a = 0; a < 3; a++) {
            double extent = (double)centres.max[a] - (double)centres.min[a];
            if (extent > longest) {
                longest = extent;
                axis = a;
            }
        }
    }
    for (uint32_t i = begin; i < end; i++)
        items[i].key = finite_count > 0 ? items[i].centroid[axis] : 0;
    /* The first child gets count / 2 rounded down; the odd light goes to the second. */
    uint32_t middle = begin + (end - begin) / 2;
    select_middle(items, begin, end, middle);
    return middle;
}

/* ---- cones ---- */

/* Returns whether a node has finite lights below it (an empty box has min > max; a finite
 * light's box never does). */
static bool has_finite_lights(const light_tree_node *node)
{
    return node->box.min[0] <= node->box.max[0];
}

/* Sets a node's cone to "any direction". */
static void set_whole_sphere(light_tree_node *node)
{
    node->axis[0] = 0;
    node->axis[1] = 0;
    node->axis[2] = 1;
    node->cos_spread = -1;
}

/* Returns the length of a double 3-vector. */
static double length3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* Returns the largest float <= value (value in [-1, 1]): a cosine rounded so that its
 * angle only grows. */
static float float_at_most(double value)
{
    float rounded = (float)value;
    return (double)rounded > value ? nextafterf(rounded, -2.0f) : rounded;
}

/* Sets out's cone to the union of its children a's and b's cones, both holding finite
 * lights (pbrt-v4's DirectionCone Union), two-sided unless one_sided:
 *   - either child shining every way: every way;
 *   - two-sided, both spreads below pi/2 and their axes more than pi/2 apart: b's axis is
 *     flipped first (emitters are two-sided, so -axis bounds b's lights as well);
 *   - one cone holding the other (theta_d + theta_b <= theta_a): that cone, as it is;
 *   - else the cone through both: half-angle theta = (theta_a + theta_d + theta_b) / 2,
 *     axis a's rotated towards b's by theta - theta_a (so that it reaches from a's far side
 *     to b's far side), widened by CONE_WIDENING; every way when that reaches pi.
 * theta_d is the angle between the axes. */
static void merge_cones(const light_tree_node *a, const light_tree_node *b, bool one_sided, light_tree_node *out)
{
    if (a->cos_spread <= -1 || b->cos_spread <= -1) {
        set_whole_sphere(out);
        return;
    }
    double wa[3], wb[3];
    for (int k = 0; k < 3; k++) {
        wa[k] = a->axis[k];
        wb[k] = b->axis[k];
    }
    double length_a = length3(wa), length_b = length3(wb);
    for (int k = 0; k < 3; k++) {
        wa[k] /= length_a;
        wb[k] /= length_b;
    }
    double dot = wa[0] * wb[0] + wa[1] * wb[1] + wa[2] * wb[2];
    if (!one_sided && a->cos_spread > 0 && b->cos_spread > 0 && dot < 0) {
        for (int k = 0; k < 3; k++)
            wb[k] = -wb[k];
        dot = -dot;
    }
    double theta_a = acos(a->cos_spread), theta_b = acos(b->cos_spread);
    /* The part of b's axis across a's: its length is sin(theta_d), its direction the way
     * from a's axis towards b's. atan2 keeps theta_d exact near 0 and pi, where acos(dot)
     * is not. */
    double across[3];
    for (int k = 0; k < 3; k++)
        across[k] = wb[k] - dot * wa[k];
    double sine = length3(across);
    double theta_d = atan2(sine, dot);
    if (fmin(theta_d + theta_b, M_PI) <= theta_a) {
        memcpy(out->axis, a->axis, sizeof out->axis);
        out->cos_spread = a->cos_spread;
        return;
    }
    if (fmin(theta_d + theta_a, M_PI) <= theta_b) {
        memcpy(out->axis, b->axis, sizeof out->axis);
        out->cos_spread = b->cos_spread;
        return;
    }
    double theta = 0.5 * (theta_a + theta_d + theta_b);
    if (theta + CONE_WIDENING >= M_PI) {
        set_whole_sphere(out);
        return;
    }
    double turn = theta - theta_a;
    if (sine < 1e-6) {
        /* The axes are (nearly) the same or opposite, and the direction of the turn is lost
         * in rounding: take any direction across a's. Nearly the same: the turn is below
         * theta_d < 1e-6; nearly opposite: every way from a's axis passes b's within the
         * angle left to pi. Either way a wrong direction costs at most 2e-6 rad, less than
         * the widening. */
        int smallest = 0;
        for (int k = 1; k < 3; k++)
            if (fabs(wa[k]) < fabs(wa[smallest]))
                smallest = k;
        double helper[3] = {0, 0, 0};
        helper[smallest] = 1;
        double along = wa[smallest];
        for (int k = 0; k < 3; k++)
            across[k] = helper[k] - along * wa[k];
        sine = length3(across);
    }
    double axis[3];
    for (int k = 0; k < 3; k++)
        axis[k] = wa[k] * cos(turn) + across[k] / sine * sin(turn);
    double length = length3(axis);
    for (int k = 0; k < 3; k++)
        out->axis[k] = (float)(axis[k] / length);
    out->cos_spread = float_at_most(cos(theta + CONE_WIDENING));
}

/* ---- the build ---- */

/* Fills nodes[index] as the leaf of light items[at]: its bounds as light_tree.h says, its
 * trail and depth. Returns its sums. */
static node_sums make_leaf(build_state *state, uint32_t index, uint32_t at, uint32_t trail, uint32_t depth)
{
    uint32_t light = state->items[at].light;
    const light_bounds *bounds = &state->lights[light];
    light_tree_node *node = &state->tree->nodes[index];
    node->first = light;
    node->leaf = true;
    node->one_sided = false;
    node->axis[0] = 0;
    node->axis[1] = 0;
    node->axis[2] = 1;
    node_sums sums = {0, 0};
    if (bounds->infinite) {
        node->box = bvh_box_empty();
        node->intensity = 0;
        node->irradiance = bounds->irradiance;
        sums.irradiance = bounds->irradiance;
    } else {
        node->box = bounds->box;
        node->intensity = bounds->intensity;
        node->irradiance = 0;
        sums.intensity = bounds->intensity;
    }
    /* The cone: of a finite light's normals, of the directions an infinite one comes from. */
    node->cos_spread = bounds->cos_spread;
    if (bounds->cos_spread > -1) {
        double v[3] = {bounds->axis[0], bounds->axis[1], bounds->axis[2]};
        double length = length3(v);
        if (!(length > 0)) {
            /* No normal (a flat light of no area): bound it by every direction. */
            node->cos_spread = -1;
        } else if (fabs(length - 1) <= 1e-6) {
            memcpy(node->axis, bounds->axis, sizeof node->axis);
        } else {
            for (int k = 0; k < 3; k++)
                node->axis[k] = (float)(v[k] / length);
        }
    }
    node->one_sided = !bounds->infinite && bounds->one_sided && node->cos_spread > -1;
    state->tree->trails[light] = trail;
    state->tree->depths[light] = (uint8_t)depth;
    if (depth > state->tree->depth)
        state->tree->depth = depth;
    return sums;
}

/* Builds the subtree of the lights items[begin .. end - 1] (at least one) into nodes[index],
 * whose walk from the root is trail, depth levels down. Returns its sums. */
static node_sums build_node(build_state *state, uint32_t index, uint32_t begin, uint32_t end, uint32_t trail,
                            uint32_t depth)
{
    if (end - begin == 1)
        return make_leaf(state, index, begin, trail, depth);

    uint32_t middle = split_items(state->items, begin, end);
    uint32_t first = state->node_count;
    state->node_count += 2;
    node_sums sums_a = build_node(state, first, begin, middle, trail, depth + 1);
    node_sums sums_b = build_node(state, first + 1, middle, end, trail | (1u << depth), depth + 1);

    /* The node array never moves during the build, so these stay valid. */
    light_tree_node *node = &state->tree->nodes[index];
    const light_tree_node *a = &state->tree->nodes[first], *b = &state->tree->nodes[first + 1];
    node->first = first;
    node->leaf = false;
    node->box = a->box;
    bvh_box_grow(&node->box, &b->box);
    bool finite_a = has_finite_lights(a), finite_b = has_finite_lights(b);
    if (finite_a && finite_b) {
        node->one_sided = a->one_sided && b->one_sided;
        merge_cones(a, b, node->one_sided, node);
        if (node->cos_spread <= -1)
            node->one_sided = false;
    } else if (finite_a || finite_b) {
        /* A child without finite lights bounds no normals: it adds nothing to the cone. */
        const light_tree_node *only = finite_a ? a : b;
        memcpy(node->axis, only->axis, sizeof node->axis);
        node->cos_spread = only->cos_spread;
        node->one_sided = only->one_sided;
    } else {
        /* Infinite lights alone: the directions they come from. */
        node->one_sided = false;
        merge_cones(a, b, true, node);
    }
    node_sums sums = {sums_a.intensity + sums_b.intensity, sums_a.irradiance + sums_b.irradiance};
    node->intensity = (float)sums.intensity;
    node->irradiance = (float)sums.irradiance;
    return sums;
}

rt_status light_tree_build(const light_bounds *lights, uint32_t count, light_tree *out, rt_error *error)
{
    if (out == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "LIGHT_TREE: no output tree was given");
    memset(out, 0, sizeof *out);
    if (count == 0)
        return rt_error_set(error, RT_ERROR_RUNTIME, "LIGHT_TREE: no lights (a tree needs at least one)");
    if (count > LIGHT_TREE_MAX_LIGHTS)
        return rt_error_set(error, RT_ERROR_RUNTIME, "LIGHT_TREE: %u lights is more than the %u supported", count,
                            LIGHT_TREE_MAX_LIGHTS);
    if (lights == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "LIGHT_TREE: %u lights but no bounds", count);
    for (uint32_t i = 0; i < count; i++) {
        rt_status status = check_light(&lights[i], i, error);
        if (status != RT_OK)
            return status;
    }

    /* calloc: the padding of the nodes is zero too, so that identical trees are identical
     * bytes. */
    light_tree tree = {0};
    tree.nodes = calloc(2 * (size_t)count - 1, sizeof *tree.nodes);
    tree.trails = malloc((size_t)count * sizeof *tree.trails);
    tree.depths = malloc((size_t)count * sizeof *tree.depths);
    build_item *items = malloc((size_t)count * sizeof *items);
    if (tree.nodes == NULL || tree.trails == NULL || tree.depths == NULL || items == NULL) {
        free(items);
        light_tree_free(&tree);
        return rt_error_set(error, RT_ERROR_RUNTIME, "LIGHT_TREE: out of memory for %u lights", count);
    }
    for (uint32_t i = 0; i < count; i++) {
        items[i] = (build_item){.light = i, .infinite = lights[i].infinite};
        if (!lights[i].infinite)
            /* Halves first: min + max can overflow for boxes near FLT_MAX. */
            for (int axis = 0; axis < 3; axis++)
                items[i].centroid[axis] = 0.5f * lights[i].box.min[axis] + 0.5f * lights[i].box.max[axis];
    }

    build_state state = {.lights = lights, .items = items, .tree = &tree, .node_count = 1};
    node_sums sums = build_node(&state, 0, 0, count, 0, 0);
    free(items);
    if (sums.intensity > FLT_MAX || sums.irradiance > FLT_MAX) {
        light_tree_free(&tree);
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "LIGHT_TREE: the lights' total intensity %g or irradiance %g is too large for a float",
                            sums.intensity, sums.irradiance);
    }
    tree.node_count = state.node_count;
    *out = tree;
    return RT_OK;
}

void light_tree_free(light_tree *tree)
{
    if (tree == NULL)
        return;
    free(tree->nodes);
    free(tree->trails);
    free(tree->depths);
    memset(tree, 0, sizeof *tree);
}
