/* pack.h: turns a scene and its BVH into the packed texel array the tracer reads
 * (plain C, tested without a GPU). The record layout is packed_layout.h, the one
 * definition shared with the shader.
 *
 * Output: texel_count texels of four uint32 each (texels[4*i .. 4*i+3] is texel i);
 * floats are stored as their bit patterns. Primitives are written in BVH leaf order.
 *
 * Defaults of pack_options (all zero): BVH built with bvh_build_config defaults.
 */
#ifndef RT_PACK_H
#define RT_PACK_H

#include <stdint.h>

#include "bvh.h"
#include "scene.h"
#include "status.h"

typedef struct pack_options {
    const bvh_build_config *bvh_config;  /* NULL: defaults */
} pack_options;

typedef struct packed_scene {
    uint32_t *texels;
    uint32_t texel_count;
    uint32_t material_offset, material_count;
    uint32_t primitive_offset, primitive_count;
    uint32_t node_offset, node_count;
    int bvh_depth;
    double bvh_build_seconds;
} packed_scene;

/* A decoded primitive record, for tests and CPU tools. */
typedef struct packed_primitive {
    uint32_t type;
    uint32_t material;
    float sphere[4];             /* centre xyz, radius */
} packed_primitive;

/* Returns options with every field at its default (all zero). */
pack_options pack_options_defaults(void);

/* Builds the BVH over the scene's primitives and writes all records. options may be NULL.
 * A scene whose indices would not fit 32 bits is RT_ERROR_INPUT. The caller frees *out
 * with packed_scene_free(). */
rt_status pack_scene(const scene *s, const pack_options *options, packed_scene *out, rt_error *error);

/* Frees out->texels and zeroes *out. */
void packed_scene_free(packed_scene *packed);

/* Reads texel index's component (0..3) as an integer / as a float. */
uint32_t packed_uint(const packed_scene *packed, uint32_t texel, int component);
float packed_float(const packed_scene *packed, uint32_t texel, int component);

/* Decodes the primitive in slot (0 .. primitive_count-1). */
packed_primitive packed_primitive_at(const packed_scene *packed, uint32_t slot);

/* Nearest hit of a ray against the packed scene, walking the packed BVH exactly as the
 * shader does (nearer child first). Returns the primitive slot hit, or UINT32_MAX; the
 * distance goes to *t_hit. direction must be unit length. For tests and CPU tools. */
uint32_t packed_intersect_nearest(const packed_scene *packed, const float origin[3], const float direction[3],
                                  float t_max, float *t_hit);

#endif
