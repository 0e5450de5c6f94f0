/* bvh.c: see bvh.h.
 *
 * Build: a top-down binned surface area heuristic (SAH) builder. Each node bins the
 * centroids of its primitives into bin_count equal slices of the centroid bounds on each of
 * the three axes, evaluates every plane between two bins with one sweep from each side, and
 * splits on the cheapest plane of all three axes. The work list is an explicit stack (the
 * right child waits, the left child is built at once), so nothing recurses and the stack
 * never holds more than one waiting node per level.
 *
 * The primitives are moved around in a private array of build items (box, centroid, input
 * index) so that every pass over a node reads memory in order; primitive_indices is copied
 * out of it at the end.
 *
 * Traversal: a slab test that picks the entry plane of each axis by the sign of 1/direction
 * (so a zero component gives +-inf, never a division trap), and a stack of waiting far
 * children, each with its entry distance so that it can be dropped when a nearer hit has
 * been found since it was pushed.
 */
#include "bvh.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "packed_layout.h"

enum {
    DEFAULT_MAX_LEAF_SIZE = 4,
    DEFAULT_BIN_COUNT = 16,
    LARGEST_MAX_LEAF_SIZE = 255,
    LARGEST_BIN_COUNT = 256,
};

#define DEFAULT_TRAVERSAL_COST 1.0
#define DEFAULT_INTERSECTION_COST 1.0

/* More primitives than this would overflow the uint32_t node count (2 * count - 1). */
#define LARGEST_PRIMITIVE_COUNT 0x80000000u

/* A primitive while the tree is built: its box, its box centre and where it came from. */
typedef struct build_item {
    bvh_box box;
    float centroid[3];
    uint32_t primitive;
} build_item;

/* A node whose primitives are items[begin .. end - 1], waiting to be made a leaf or split. */
typedef struct build_task {
    uint32_t node;
    uint32_t begin;
    uint32_t end;
    int depth;
} build_task;

typedef struct sah_bin {
    bvh_box box;
    uint32_t count;
} sah_bin;

/* The config with defaults filled in; costs in double because the SAH sums are. */
typedef struct build_settings {
    uint32_t max_leaf_size;
    int bin_count;
    int max_depth;
    double traversal_cost;
    double intersection_cost;
} build_settings;

/* Scratch memory for choosing a split, allocated once per build. */
typedef struct split_scratch {
    sah_bin *bins;                 /* bin_count bins for one axis */
    double *right_weighted_area;   /* [i]: metric(bins i..last) * count(bins i..last) */
    uint32_t *right_count;         /* [i]: count(bins i..last) */
} split_scratch;

/* The plane chosen for a node: primitives whose centroid falls in bins 0..last_left_bin of
 * axis go left. origin and scale map a centroid to its bin (see bin_of()). */
typedef struct split_plane {
    int axis;
    int last_left_bin;
    double origin;
    double scale;
    double cost;                   /* not divided by the node's metric (see choose_split()) */
} split_plane;

/* Returns how expensive it is to have a ray enter *box, measured as its surface area, or as
 * the sum of its edge lengths when by_edge_length is set (for nodes of zero area, where a
 * line of boxes would make every area zero and the SAH blind). Computed in double because
 * float extents up to 2 * FLT_MAX and their products overflow float. */
static double box_metric(const bvh_box *box, bool by_edge_length)
{
    double extent[3];
    for (int axis = 0; axis < 3; axis++)
        extent[axis] = (double)box->max[axis] - (double)box->min[axis];
    if (by_edge_length)
        return extent[0] + extent[1] + extent[2];
    return 2.0 * (extent[0] * extent[1] + extent[1] * extent[2] + extent[2] * extent[0]);
}

/* Returns the bin of a centroid coordinate. Computed in double so that the distance from
 * the origin cannot overflow; the last bin takes the centroid that sits on the upper bound. */
static int bin_of(float centroid, double origin, double scale, int bin_count)
{
    int bin = (int)(((double)centroid - origin) * scale);
    return bin < bin_count ? bin : bin_count - 1;
}

/* Fills *settings from config (NULL or zero fields mean the defaults). Returns RT_OK, or
 * RT_ERROR_INPUT with a message naming the first bad field. */
static rt_status resolve_config(const bvh_build_config *config, build_settings *settings,
                                rt_error *error)
{
    bvh_build_config given = config != NULL ? *config : bvh_build_config_defaults();

    if (given.max_leaf_size < 0 || given.max_leaf_size > LARGEST_MAX_LEAF_SIZE)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "BVH: max_leaf_size %d is out of range (0 for the default %d, or 1 to %d)",
                            given.max_leaf_size, DEFAULT_MAX_LEAF_SIZE, LARGEST_MAX_LEAF_SIZE);
    /* One bin has no plane between bins, so it could never split. */
    if (given.bin_count < 0 || given.bin_count == 1 || given.bin_count > LARGEST_BIN_COUNT)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "BVH: bin_count %d is out of range (0 for the default %d, or 2 to %d)",
                            given.bin_count, DEFAULT_BIN_COUNT, LARGEST_BIN_COUNT);
    if (given.max_depth < 0 || given.max_depth > BVH_MAX_DEPTH)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "BVH: max_depth %d is out of range (0 for the default %d, or 1 to %d)",
                            given.max_depth, BVH_MAX_DEPTH, BVH_MAX_DEPTH);
    if (!isfinite(given.traversal_cost) || given.traversal_cost < 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "BVH: traversal_cost %g must be a finite number >= 0 (0 for the default)",
                            (double)given.traversal_cost);
    if (!isfinite(given.intersection_cost) || given.intersection_cost < 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "BVH: intersection_cost %g must be a finite number >= 0 (0 for the default)",
                            (double)given.intersection_cost);

    settings->max_leaf_size = given.max_leaf_size ? (uint32_t)given.max_leaf_size : DEFAULT_MAX_LEAF_SIZE;
    settings->bin_count = given.bin_count ? given.bin_count : DEFAULT_BIN_COUNT;
    settings->max_depth = given.max_depth ? given.max_depth : BVH_MAX_DEPTH;
    settings->traversal_cost = given.traversal_cost != 0 ? given.traversal_cost : DEFAULT_TRAVERSAL_COST;
    settings->intersection_cost =
        given.intersection_cost != 0 ? given.intersection_cost : DEFAULT_INTERSECTION_COST;
    return RT_OK;
}

/* Checks that every box is finite and not inside out. Returns RT_OK, or RT_ERROR_INPUT
 * naming the first bad primitive. */
static rt_status check_boxes(const bvh_box *boxes, uint32_t count, rt_error *error)
{
    static const char axis_names[3] = {'x', 'y', 'z'};
    for (uint32_t primitive = 0; primitive < count; primitive++) {
        const bvh_box *box = &boxes[primitive];
        for (int axis = 0; axis < 3; axis++) {
            float low = box->min[axis], high = box->max[axis];
            if (isnan(low) || isnan(high))
                return rt_error_set(error, RT_ERROR_INPUT,
                                    "BVH: the box of primitive %u has a NaN %c coordinate",
                                    primitive, axis_names[axis]);
            if (isinf(low) || isinf(high))
                return rt_error_set(error, RT_ERROR_INPUT,
                                    "BVH: the box of primitive %u has an infinite %c coordinate",
                                    primitive, axis_names[axis]);
            if (low > high)
                return rt_error_set(error, RT_ERROR_INPUT,
                                    "BVH: the box of primitive %u has min %g > max %g on %c",
                                    primitive, (double)low, (double)high, axis_names[axis]);
        }
    }
    return RT_OK;
}

/* Computes the box around items[begin .. end - 1] and the box around their centroids. */
static void bound_items(const build_item *items, uint32_t begin, uint32_t end,
                        bvh_box *box, bvh_box *centroid_box)
{
    *box = bvh_box_empty();
    *centroid_box = bvh_box_empty();
    for (uint32_t i = begin; i < end; i++) {
        bvh_box_grow(box, &items[i].box);
        for (int axis = 0; axis < 3; axis++) {
            float centroid = items[i].centroid[axis];
            centroid_box->min[axis] = centroid < centroid_box->min[axis] ? centroid : centroid_box->min[axis];
            centroid_box->max[axis] = centroid > centroid_box->max[axis] ? centroid : centroid_box->max[axis];
        }
    }
}

/* Finds the cheapest binned SAH plane over the three axes for items[begin .. end - 1].
 * Costs are left multiplied by the node's metric (traversal_cost * metric(node) +
 * intersection_cost * sum over children of metric(child) * count(child)) so that a node of
 * zero metric divides nothing. Returns false when no axis has two distinct centroids (every
 * plane would leave one side empty); ties keep the first plane found (axis x first, then
 * lower bins), which keeps the build deterministic. */
static bool choose_split(const build_item *items, uint32_t begin, uint32_t end,
                         const bvh_box *centroid_box, double node_metric, bool by_edge_length,
                         const build_settings *settings, split_scratch *scratch,
                         split_plane *best)
{
    int bin_count = settings->bin_count;
    bool found = false;

    for (int axis = 0; axis < 3; axis++) {
        double origin = centroid_box->min[axis];
        double extent = (double)centroid_box->max[axis] - origin;
        if (!(extent > 0))
            continue;
        double scale = bin_count / extent;

        for (int bin = 0; bin < bin_count; bin++) {
            scratch->bins[bin].box = bvh_box_empty();
            scratch->bins[bin].count = 0;
        }
        for (uint32_t i = begin; i < end; i++) {
            sah_bin *bin = &scratch->bins[bin_of(items[i].centroid[axis], origin, scale, bin_count)];
            bvh_box_grow(&bin->box, &items[i].box);
            bin->count++;
        }

        /* Right to left: what the right side costs for each plane, before bin i. An empty
         * bin changes nothing, so it reuses the value of the bin after it (this matters
         * for small nodes with many bins, most of them empty). */
        bvh_box right_box = bvh_box_empty();
        uint32_t right_count = 0;
        double right_weighted_area = 0;
        for (int bin = bin_count - 1; bin > 0; bin--) {
            if (scratch->bins[bin].count > 0) {
                bvh_box_grow(&right_box, &scratch->bins[bin].box);
                right_count += scratch->bins[bin].count;
                right_weighted_area = box_metric(&right_box, by_edge_length) * right_count;
            }
            scratch->right_count[bin] = right_count;
            scratch->right_weighted_area[bin] = right_weighted_area;
        }

        /* Left to right: add the left side and keep the cheapest plane with both sides full.
         * The plane after an empty bin splits like the plane before it, so it is skipped. */
        bvh_box left_box = bvh_box_empty();
        uint32_t left_count = 0;
        for (int bin = 0; bin < bin_count - 1; bin++) {
            if (scratch->bins[bin].count == 0)
                continue;
            bvh_box_grow(&left_box, &scratch->bins[bin].box);
            left_count += scratch->bins[bin].count;
            if (scratch->right_count[bin + 1] == 0)
                break;
            double cost = settings->traversal_cost * node_metric +
                          settings->intersection_cost *
                              (box_metric(&left_box, by_edge_length) * left_count +
                               scratch->right_weighted_area[bin + 1]);
            if (!found || cost < best->cost) {
                found = true;
                *best = (split_plane){.axis = axis, .last_left_bin = bin, .origin = origin,
                                      .scale = scale, .cost = cost};
            }
        }
    }
    return found;
}

/* Moves the items of items[begin .. end - 1] that go left of plane before the others.
 * Returns the index of the first item that goes right. */
static uint32_t partition_items(build_item *items, uint32_t begin, uint32_t end,
                                const split_plane *plane, int bin_count)
{
    uint32_t left_end = begin;
    uint32_t right_begin = end;
    while (left_end < right_begin) {
        int bin = bin_of(items[left_end].centroid[plane->axis], plane->origin, plane->scale, bin_count);
        if (bin <= plane->last_left_bin) {
            left_end++;
        } else {
            right_begin--;
            build_item swapped = items[left_end];
            items[left_end] = items[right_begin];
            items[right_begin] = swapped;
        }
    }
    return left_end;
}

/* Returns the all-zero config, which means every default (see bvh.h). */
bvh_build_config bvh_build_config_defaults(void)
{
    return (bvh_build_config){0};
}

/* Builds an empty tree: one node holding nothing. Its box is the empty box (min +inf,
 * max -inf) rather than zeros, because a slab test that picks the entry plane by the sign of
 * the direction finds entry +inf > exit -inf and rejects it, while a zero box would be hit by
 * rays through the origin. Returns RT_OK or RT_ERROR_RUNTIME when memory runs out. */
static rt_status build_empty(bvh *out, rt_error *error)
{
    out->nodes = malloc(sizeof *out->nodes);
    if (out->nodes == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "BVH: out of memory for the empty tree");
    out->nodes[0] = (bvh_node){.box = bvh_box_empty(), .first = 0, .count = 0};
    out->node_count = 1;
    return RT_OK;
}

/* Frees the working arrays of bvh_build (any may be NULL). */
static void free_build_arrays(build_item *items, split_scratch *scratch)
{
    free(items);
    free(scratch->bins);
    free(scratch->right_weighted_area);
    free(scratch->right_count);
}

/* Decides how the task's items (bounded by box, their centroids by centroid_box) are split:
 * returns false when they become a leaf (splitting costs more than the leaf, and the leaf
 * is small enough), else true with the items partitioned at *middle. */
static bool split_task(build_item *items, const build_task *task, const bvh_box *box, const bvh_box *centroid_box,
                       const build_settings *settings, split_scratch *scratch, uint32_t *middle)
{
    uint32_t task_size = task->end - task->begin;
    bool by_edge_length = box_metric(box, false) == 0;
    double node_metric = box_metric(box, by_edge_length);
    split_plane plane;
    if (choose_split(items, task->begin, task->end, centroid_box, node_metric, by_edge_length, settings, scratch,
                     &plane)) {
        double leaf_cost = settings->intersection_cost * task_size * node_metric;
        if (plane.cost >= leaf_cost && task_size <= settings->max_leaf_size)
            return false;
        *middle = partition_items(items, task->begin, task->end, &plane, settings->bin_count);
        return true;
    }
    if (task_size <= settings->max_leaf_size)
        return false;
    /* Every centroid is the same point: no plane separates them, and the order among them
     * does not matter, so halve by index. */
    *middle = task->begin + task_size / 2;
    return true;
}

/* Builds the tree into *out (zeroed first, and left zeroed on failure). Returns RT_OK,
 * RT_ERROR_INPUT for a bad config or box, RT_ERROR_RUNTIME when memory runs out. The
 * caller frees *out with bvh_free(). */
rt_status bvh_build(const bvh_box *boxes, uint32_t count, const bvh_build_config *config,
                    bvh *out, rt_error *error)
{
    if (out == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "BVH: no output tree was given");
    memset(out, 0, sizeof *out);

    build_settings settings = {0};
    rt_status status = resolve_config(config, &settings, error);
    if (status != RT_OK)
        return status;
    if (count > 0 && boxes == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "BVH: %u primitives but no boxes", count);
    if (count > LARGEST_PRIMITIVE_COUNT)
        return rt_error_set(error, RT_ERROR_INPUT, "BVH: %u primitives is more than the %u supported",
                            count, LARGEST_PRIMITIVE_COUNT);
    status = check_boxes(boxes, count, error);
    if (status != RT_OK)
        return status;
    if (count == 0)
        return build_empty(out, error);

    /* A binary tree with at most count leaves, each holding at least one primitive. */
    uint64_t node_capacity = 2 * (uint64_t)count - 1;
    build_item *items = NULL;
    split_scratch scratch = {0};
    /* Only a 32-bit size_t can fail this. */
    if (node_capacity <= SIZE_MAX / sizeof(build_item)) {
        out->nodes = malloc((size_t)node_capacity * sizeof *out->nodes);
        out->primitive_indices = malloc((size_t)count * sizeof *out->primitive_indices);
        items = malloc((size_t)count * sizeof *items);
        scratch.bins = malloc((size_t)settings.bin_count * sizeof *scratch.bins);
        scratch.right_weighted_area = malloc((size_t)settings.bin_count * sizeof *scratch.right_weighted_area);
        scratch.right_count = malloc((size_t)settings.bin_count * sizeof *scratch.right_count);
    }
    if (out->nodes == NULL || out->primitive_indices == NULL || items == NULL ||
        scratch.bins == NULL || scratch.right_weighted_area == NULL || scratch.right_count == NULL) {
        free_build_arrays(items, &scratch);
        bvh_free(out);
        return rt_error_set(error, RT_ERROR_RUNTIME, "BVH: out of memory for %u primitives", count);
    }

    for (uint32_t i = 0; i < count; i++) {
        items[i].box = boxes[i];
        items[i].primitive = i;
        /* Halves first: min + max can overflow for boxes near FLT_MAX. */
        for (int axis = 0; axis < 3; axis++)
            items[i].centroid[axis] = 0.5f * boxes[i].min[axis] + 0.5f * boxes[i].max[axis];
    }

    /* The left child is built at once and the right one waits, so at most one task per
     * level of the current path waits: no more than max_depth. */
    build_task waiting[BVH_MAX_DEPTH + 1];
    int waiting_count = 0;
    build_task task = {.node = 0, .begin = 0, .end = count, .depth = 0};
    uint32_t node_count = 1;
    int tree_depth = 0;

    for (;;) {
        bvh_node *node = &out->nodes[task.node];
        uint32_t task_size = task.end - task.begin;
        bvh_box centroid_box;
        bound_items(items, task.begin, task.end, &node->box, &centroid_box);
        if (task.depth > tree_depth)
            tree_depth = task.depth;

        uint32_t middle = 0;
        bool make_leaf = task_size == 1 || task.depth >= settings.max_depth
                         || !split_task(items, &task, &node->box, &centroid_box, &settings, &scratch, &middle);
        if (make_leaf) {
            node->first = task.begin;
            node->count = task_size;
            if (waiting_count == 0)
                break;
            task = waiting[--waiting_count];
            continue;
        }

        uint32_t left = node_count;
        node_count += 2;
        node->first = left;
        node->count = 0;
        waiting[waiting_count++] = (build_task){.node = left + 1, .begin = middle, .end = task.end,
                                                .depth = task.depth + 1};
        task = (build_task){.node = left, .begin = task.begin, .end = middle, .depth = task.depth + 1};
    }

    for (uint32_t i = 0; i < count; i++)
        out->primitive_indices[i] = items[i].primitive;
    free_build_arrays(items, &scratch);

    /* Give back the nodes that bigger leaves left unused; keeping the larger block is fine
     * if the system will not shrink it. */
    bvh_node *shrunk = realloc(out->nodes, (size_t)node_count * sizeof *out->nodes);
    if (shrunk != NULL)
        out->nodes = shrunk;
    out->node_count = node_count;
    out->primitive_count = count;
    out->depth = tree_depth;
    return RT_OK;
}

/* Frees the two arrays of *tree and zeroes it, so that freeing twice is harmless. */
void bvh_free(bvh *tree)
{
    if (tree == NULL)
        return;
    free(tree->nodes);
    free(tree->primitive_indices);
    memset(tree, 0, sizeof *tree);
}

/* A ray prepared for slab tests: 1/direction per axis (+-inf for a zero component, with the
 * sign of the zero) and whether that axis is entered through the box's max plane. */
typedef struct slab_ray {
    float origin[3];
    float inverse_direction[3];
    bool enters_through_max[3];
} slab_ray;

/* Clips [t_min, t_max] to where the ray is inside *box. Returns true when some of it is
 * left, with the clipped start (the entry distance) in *entry.
 *
 * A zero direction component with the origin exactly on one of the box's planes gives
 * 0 * inf = NaN; NaN fails both comparisons below, so that axis then does not narrow the
 * interval: the ray runs inside the closed slab. The comparisons are monotonic in the
 * plane positions, so a box inside another is never hit by a ray that misses the outer one. */
static bool clip_to_box(const bvh_box *box, const slab_ray *ray, float t_min, float t_max,
                        float *entry)
{
    float near = t_min;
    float far = t_max;
    for (int axis = 0; axis < 3; axis++) {
        float entry_plane = ray->enters_through_max[axis] ? box->max[axis] : box->min[axis];
        float exit_plane = ray->enters_through_max[axis] ? box->min[axis] : box->max[axis];
        float t_entry = (entry_plane - ray->origin[axis]) * ray->inverse_direction[axis];
        float t_exit = (exit_plane - ray->origin[axis]) * ray->inverse_direction[axis];
        if (t_entry > near)
            near = t_entry;
        if (t_exit < far)
            far = t_exit;
    }
    *entry = near;
    return near <= far;
}

/* A far child waiting its turn, with the distance at which the ray enters it. */
typedef struct traversal_entry {
    uint32_t node;
    float entry;
} traversal_entry;

/* Walks tree nearer child first and returns the nearest primitive test() accepts, or
 * UINT32_MAX; *t_hit (may be NULL) is written on a hit only. The result is exactly that
 * of testing every primitive as long as the slab interval of each primitive's box holds
 * every distance its test can report (callers pad boxes by their test's rounding error):
 * a node is then never skipped while it may hold a nearer hit. Allocates nothing. */
uint32_t bvh_intersect_nearest(const bvh *tree, const float origin[3], const float direction[3],
                               float t_min, float t_max, bvh_primitive_test test,
                               void *context, float *t_hit)
{
    /* An empty tree's root is "interior with no children"; a tree deeper than the stack
     * was not made by bvh_build(). */
    if (tree == NULL || tree->nodes == NULL || tree->primitive_count == 0 || test == NULL ||
        tree->depth > BVH_MAX_DEPTH)
        return UINT32_MAX;

    slab_ray ray;
    for (int axis = 0; axis < 3; axis++) {
        ray.origin[axis] = origin[axis];
        ray.inverse_direction[axis] = 1.0f / direction[axis];
        ray.enters_through_max[axis] = signbit(ray.inverse_direction[axis]) != 0;
    }

    float nearest_t = t_max;
    uint32_t nearest = UINT32_MAX;
    float entry;
    if (!clip_to_box(&tree->nodes[0].box, &ray, t_min, nearest_t, &entry) || !(entry < nearest_t))
        return UINT32_MAX;

    /* One far child waits per level on the path from the root, so depth slots suffice. */
    traversal_entry waiting[BVH_MAX_DEPTH];
    int waiting_count = 0;
    uint32_t node_index = 0;

    for (;;) {
        const bvh_node *node = &tree->nodes[node_index];
        bool descend = false;
        if (node->count > 0) {
            for (uint32_t slot = node->first; slot < node->first + node->count; slot++) {
                uint32_t primitive = tree->primitive_indices[slot];
                if (test(context, primitive, origin, direction, t_min, &nearest_t))
                    nearest = primitive;
            }
        } else {
            uint32_t left = node->first, right = node->first + 1;
            float left_entry, right_entry;
            /* An entry at or beyond the nearest hit cannot hold a nearer one: the primitive
             * test only accepts distances below nearest_t. */
            bool hits_left = clip_to_box(&tree->nodes[left].box, &ray, t_min, nearest_t, &left_entry) &&
                             left_entry < nearest_t;
            bool hits_right = clip_to_box(&tree->nodes[right].box, &ray, t_min, nearest_t, &right_entry) &&
                              right_entry < nearest_t;
            if (hits_left && hits_right) {
                bool left_first = left_entry <= right_entry;
                waiting[waiting_count++] = left_first ? (traversal_entry){right, right_entry}
                                                      : (traversal_entry){left, left_entry};
                node_index = left_first ? left : right;
                descend = true;
            } else if (hits_left || hits_right) {
                node_index = hits_left ? left : right;
                descend = true;
            }
        }
        if (descend)
            continue;

        /* Resume with the nearest waiting child that a hit found meanwhile has not ruled out. */
        while (waiting_count > 0 && !(waiting[waiting_count - 1].entry < nearest_t))
            waiting_count--;
        if (waiting_count == 0)
            break;
        node_index = waiting[--waiting_count].node;
    }

    if (nearest != UINT32_MAX && t_hit != NULL)
        *t_hit = nearest_t;
    return nearest;
}
