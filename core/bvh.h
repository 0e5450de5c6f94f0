/* bvh.h: bounding volume hierarchy builder (plain C, no GL).
 *
 * Building is a pure step: an array of primitive bounding boxes in, a flat node array
 * and a primitive order out. The tree layout is the one the shader walks
 * (packed_layout.h): root is node 0; an interior node's two children are contiguous
 * (nodes[first] and nodes[first + 1]); a leaf covers primitive_indices[first ..
 * first + count - 1]. primitive_indices[k] is the index, in the caller's input array, of
 * the k-th primitive in leaf order: the packer writes primitives in that order.
 *
 * The builder uses the surface area heuristic over binned centroids (splitting at the
 * median when all centroids coincide); it never makes a tree deeper than
 * config.max_depth: a node at that depth becomes a leaf whatever its size.
 *
 * Defaults of bvh_build_config (zero means default):
 *   max_leaf_size 4, bin_count 16, max_depth BVH_MAX_DEPTH (24),
 *   traversal_cost 1.0, intersection_cost 1.0
 */
#ifndef RT_BVH_H
#define RT_BVH_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "status.h"

typedef struct bvh_box {
    float min[3];
    float max[3];
} bvh_box;

/* The box API (the one box type of the code base; the packer uses it too). */

/* Returns the box that contains nothing: min +inf, max -inf, so that growing it by any box
 * or point gives that box or point. */
static inline bvh_box bvh_box_empty(void)
{
    return (bvh_box){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
}

/* Grows *box to also contain *other. Plain comparisons rather than fminf()/fmaxf(): boxes
 * hold no NaN (checked on input), and those are library calls unless inlined. */
static inline void bvh_box_grow(bvh_box *box, const bvh_box *other)
{
    for (int axis = 0; axis < 3; axis++) {
        box->min[axis] = other->min[axis] < box->min[axis] ? other->min[axis] : box->min[axis];
        box->max[axis] = other->max[axis] > box->max[axis] ? other->max[axis] : box->max[axis];
    }
}

/* Grows *box to also contain point p. */
static inline void bvh_box_add_point(bvh_box *box, const float p[3])
{
    for (int axis = 0; axis < 3; axis++) {
        box->min[axis] = p[axis] < box->min[axis] ? p[axis] : box->min[axis];
        box->max[axis] = p[axis] > box->max[axis] ? p[axis] : box->max[axis];
    }
}

typedef struct bvh_build_config {
    int max_leaf_size;
    int bin_count;
    int max_depth;
    float traversal_cost;
    float intersection_cost;
} bvh_build_config;

typedef struct bvh_node {
    bvh_box box;
    uint32_t first;              /* interior: left child index; leaf: first primitive slot */
    uint32_t count;              /* 0: interior; > 0: number of primitives in the leaf */
} bvh_node;

typedef struct bvh {
    bvh_node *nodes;
    uint32_t node_count;
    uint32_t *primitive_indices;
    uint32_t primitive_count;
    int depth;                   /* levels below the root; 0 for a single leaf */
} bvh;

/* Returns a config with every field at its default (all zero). */
bvh_build_config bvh_build_config_defaults(void);

/* Builds a BVH over count primitive boxes. config may be NULL for defaults.
 * count 0 gives one empty leaf (node_count 1, count 0 is then "interior with no
 * children"; callers check primitive_count). Boxes with NaN or infinite coordinates,
 * or min > max, and invalid configs are RT_ERROR_INPUT.
 * The caller frees *out with bvh_free(). */
rt_status bvh_build(const bvh_box *boxes, uint32_t count, const bvh_build_config *config,
                    bvh *out, rt_error *error);

/* Frees the arrays of *tree and zeroes it. */
void bvh_free(bvh *tree);

/* Intersection callback for bvh_intersect_nearest(): tests primitive (an index into the
 * caller's original array) against the ray; when it is hit at a distance in
 * (t_min, *t_max), it stores the distance in *t_max and returns true. */
typedef bool (*bvh_primitive_test)(void *context, uint32_t primitive,
                                   const float origin[3], const float direction[3],
                                   float t_min, float *t_max);

/* Finds the nearest hit along a ray by walking the tree nearer child first, the way the
 * shader does. Returns the index (in the caller's array) of the nearest primitive hit
 * with t in (t_min, t_max), and its distance in *t_hit, or UINT32_MAX when nothing is hit.
 * Used by tests (against brute force) and by CPU-side tools. */
uint32_t bvh_intersect_nearest(const bvh *tree, const float origin[3], const float direction[3],
                               float t_min, float t_max, bvh_primitive_test test,
                               void *context, float *t_hit);

#endif
