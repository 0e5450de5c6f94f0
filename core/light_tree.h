/* light_tree.h: light tree builder (plain C, no GL).
 *
 * A light tree is a bounding volume hierarchy over lights (as pbrt-v4's BVHLightSampler or
 * Cycles' light tree) for choosing one light of many for a shading point with probability
 * roughly proportional to what each light gives that point. The shader walks it from the
 * root: at each interior node it estimates the importance of the two children at the point
 * from their bounds (box, cone of normals, intensity, irradiance) and picks one at random
 * in proportion, until it reaches a leaf; the product of the choices' probabilities is the
 * light's probability. To evaluate that probability for a light hit by chance (for MIS),
 * the shader replays the same walk along the light's trail.
 *
 * Building is a pure step: an array of light bounds in, a flat node array out. The layout
 * is the one the packer writes (packed_layout.h, light tree): root is node 0; an interior
 * node's two children are contiguous (nodes[first] and nodes[first + 1]), allocated in the
 * order the build makes them; a leaf holds exactly one light, first being its index in the
 * caller's array. A tree of count lights has exactly 2 * count - 1 nodes.
 *
 * Splitting a set of lights:
 *   - a set with both finite and infinite lights: the finite ones go to the first child,
 *     the infinite ones (suns, environments) to the second; only the root can be such a set;
 *   - otherwise the lights are ordered by the centre of their box along the longest axis of
 *     the box around those centres (infinite-only sets: by index), ties broken by index, and
 *     the first count / 2 (rounded down) go to the first child, the rest to the second: the
 *     odd light goes second.
 * Median splits keep the tree balanced: its depth is at most ceil(log2(count)) + 1, and
 * the same input always gives the same tree.
 *
 * Emitters are two-sided: a flat light with normal n lights the side -n faces as well, so
 * a node's cone of normals only has to hold n or -n of each of its lights. A spot light is
 * one-sided: it shines within its cone about its direction and nowhere else, so a node
 * whose finite lights are all one-sided has a one-sided cone, which holds each light's cone
 * itself (never its negation), and nothing shines outside it (pbrt-v4's LightBounds with
 * no emission beyond the cone).
 */
#ifndef RT_LIGHT_TREE_H
#define RT_LIGHT_TREE_H

#include <stdbool.h>
#include <stdint.h>

#include "bvh.h" /* bvh_box, bvh_box_empty, bvh_box_grow, bvh_box_add_point */
#include "packed_layout.h"   /* LIGHT_TREE_MAX_DEPTH: a trail's bits, which the shader follows */
#include "status.h"

/* LIGHT_TREE_MAX_DEPTH (packed_layout.h) is the deepest a leaf may be: a trail has one bit
 * per level. Builds stay well within it: LIGHT_TREE_MAX_LIGHTS lights make a tree at most
 * 25 levels deep. */

/* The most lights a tree is built over (2^24): their indices are then exact in a float,
 * and ceil(log2(2^24)) + 1 = 25 levels stay within LIGHT_TREE_MAX_DEPTH. */
#define LIGHT_TREE_MAX_LIGHTS (1u << 24)

/* What the builder knows of one light: the bounds of what it can give a point. */
typedef struct light_bounds {
    bvh_box box;        /* a finite light's extent (a point light: min == max); unused for infinite lights */
    float axis[3];      /* unit normal of a flat (two-sided) emitter; an infinite light's direction
                           towards it (a sun's); unused when cos_spread is -1 */
    float cos_spread;   /* cosine of the half-angle of the cone of normals about axis: 1 for one flat
                           light; -1 for lights that shine every way (spheres, point and spot lights);
                           an infinite light's: of the cone of directions it comes from (a sun's
                           angular radius; -1 for an environment, from everywhere) */
    float intensity;    /* finite lights: what the importance divides by the squared distance (>= 0) */
    float irradiance;   /* infinite lights (sun, environment): their importance anywhere (>= 0) */
    bool infinite;      /* a sun or environment: no position; only irradiance counts */
    bool one_sided;     /* a finite light that shines only within cos_spread of +axis and nowhere
                           else (a spot: axis its direction, cos_spread its outer cone's); ignored
                           when cos_spread is -1 */
} light_bounds;

/* One node: the bounds of every light below it. */
typedef struct light_tree_node {
    bvh_box box;          /* the union of its finite lights' boxes; bvh_box_empty() when it has none */
    float axis[3];        /* a unit axis of a cone holding every finite light's normal cone below it
                             (or its negation); with no finite lights, every infinite light's cone
                             of directions (one-sided); (0, 0, 1) when cos_spread is -1 */
    float cos_spread;     /* that cone's half-angle's cosine (-1: any direction) */
    float intensity;      /* sum of its finite lights' intensities */
    float irradiance;     /* sum of its infinite lights' irradiances */
    uint32_t first;       /* interior: its first child (the second is first + 1); leaf: the light's index */
    bool leaf;            /* a leaf holds exactly one light */
    bool one_sided;       /* it has finite lights, all one-sided, and its cone holds each one's cone
                             itself: nothing below it shines outside the cone */
} light_tree_node;

/* A built tree; every array is the tree's own (light_tree_free() frees them). */
typedef struct light_tree {
    light_tree_node *nodes;   /* node_count nodes, root at 0 */
    uint32_t node_count;      /* 2 * count - 1 */
    uint32_t *trails;         /* per light: bit k set when the walk from the root to the light's leaf
                                 takes the second child (first + 1) at depth k (the root's choice is bit 0) */
    uint8_t *depths;          /* per light: the depth of its leaf (the root is depth 0) */
    uint32_t depth;           /* the deepest leaf's depth */
} light_tree;

/* Builds the light tree over lights[0 .. count - 1] into *out (no config: the build has no
 * knobs). A leaf copies its light's bounds: a finite light's box, axis, cos_spread,
 * one_sided and intensity (irradiance 0); an infinite light's irradiance, axis and
 * cos_spread (empty box, intensity 0, not one_sided). An axis that is not of unit length is
 * normalized in the leaf; a zero axis (a degenerate flat light) makes its leaf's cos_spread
 * -1 (any direction); a leaf with cos_spread -1 is never one-sided. An interior node holds
 * the union of its children's boxes and cones and the sums (added up in double) of their
 * intensities and irradiances; with finite lights it is one-sided when every child with
 * finite lights is, and its cone is then the one-sided union (no axis flipped), else the
 * two-sided one; a child without finite lights adds nothing to it (only the root has both
 * kinds, and the walk never weighs the root). A node of infinite lights alone holds the
 * one-sided union of their cones of directions.
 *
 * Returns RT_OK, or RT_ERROR_RUNTIME with a message starting "LIGHT_TREE: " (the packer
 * makes these bounds, so a bad one is a bug rather than the user's input) for: count 0 or
 * above LIGHT_TREE_MAX_LIGHTS; a NaN or infinite coordinate or min > max in a finite light's
 * box; a NaN or infinite axis of a light whose cos_spread is not -1; a cos_spread
 * outside [-1, 1]; an intensity or irradiance (of any light) that is NaN, infinite or
 * negative; sums too large for a float; out of memory. On error *out is left zeroed and
 * nothing is allocated. The caller frees *out with light_tree_free(). */
rt_status light_tree_build(const light_bounds *lights, uint32_t count, light_tree *out, rt_error *error);

/* Frees the arrays light_tree_build() allocated and zeroes *tree, so that freeing a zeroed
 * (or already freed) tree, or NULL, is harmless. */
void light_tree_free(light_tree *tree);

#endif
