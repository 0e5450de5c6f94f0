/* pack.h: turns a scene into the packed texel array the tracer reads (plain C, tested
 * without a GPU). The record layout is packed_layout.h, the one definition shared with the
 * shader.
 *
 * What it builds: one bottom-level BVH per object that an instance places with a transform,
 * a volume flag or a mesh (each object once, however often it is placed), and a top-level
 * BVH (root: node 0) over the world's own primitives (spheres, and the shapes and mesh
 * triangles of objects placed with the identity and no volume: those are copied into the
 * top level, so simple scenes pay nothing for instancing and emissive meshes become
 * lights) and the instances. Shapes without a material get the
 * instance's, and failing that a default grey Lambertian material (appended last).
 *
 * Output: texel_count texels of four uint32 each (texels[4*i .. 4*i+3] is texel i);
 * floats are stored as their bit patterns.
 *
 * Defaults of pack_options (all zero): BVHs built with bvh_build_config defaults.
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
    uint32_t material_offset, material_count;   /* material_count includes the default */
    uint32_t primitive_offset, primitive_count;
    uint32_t info_offset;                       /* primitive info, four to a texel */
    uint32_t shape_offset, shape_texels;        /* moving sphere and quad records */
    uint32_t vertex_offset, vertex_count;
    uint32_t uv_offset;                         /* two vertices' uvs to a texel */
    uint32_t node_offset, node_count;
    uint32_t instance_offset, instance_count;
    uint32_t texture_offset, texture_count;
    uint32_t image_offset, image_count;
    uint32_t light_offset, light_count;
    uint32_t area_light_count;                  /* the first lights: emissive primitives */
    uint32_t default_material;
    uint32_t triangle_count;     /* triangles stored (mesh triangles once per object) */
    int bvh_depth;               /* deepest level of any BVH */
    double bvh_build_seconds;    /* all BVH builds together */
} packed_scene;

/* A decoded primitive, for tests and CPU tools: its record, info and the geometry they
 * point to, as the layout of before (one record with the geometry inline). */
typedef struct packed_primitive {
    uint32_t type;
    uint32_t material;           /* PACKED_NONE: the instance's */
    bool has_uvs;                /* triangles: the vertices carry uvs */
    uint32_t instance;           /* PRIMITIVE_INSTANCE only */
    uint32_t vertices[3];        /* triangles: vertex indices */
    float data[3][4];            /* sphere: (centre, radius); moving sphere: (centre at 0,
                                  * radius), (centre at 1, 0); triangle: (v0, 0), (v1 - v0,
                                  * 0), (v2 - v0, 0); quad: (Q, 0), (u, 0), (v, 0) */
} packed_primitive;

/* A nearest hit found by packed_intersect_nearest(). */
typedef struct packed_hit {
    float t;
    uint32_t primitive;          /* slot in the primitive section */
    uint32_t instance;           /* PACKED_NONE: a world primitive */
} packed_hit;

/* Returns options with every field at its default (all zero). */
pack_options pack_options_defaults(void);

/* Builds the BVHs and writes all records. options may be NULL. Meshes must be loaded
 * (scene_load_assets) and images too. A scene whose indices would not fit 32 bits is
 * RT_ERROR_INPUT; an instance whose transform cannot be inverted too. The caller frees
 * *out with packed_scene_free(). */
rt_status pack_scene(const scene *s, const pack_options *options, packed_scene *out, rt_error *error);

/* Frees out->texels and zeroes *out. */
void packed_scene_free(packed_scene *packed);

/* Reads texel index's component (0..3) as an integer / as a float. */
uint32_t packed_uint(const packed_scene *packed, uint32_t texel, int component);
float packed_float(const packed_scene *packed, uint32_t texel, int component);

/* Decodes the primitive in slot (0 .. primitive_count-1). */
packed_primitive packed_primitive_at(const packed_scene *packed, uint32_t slot);

/* The type tag (PRIMITIVE_*) of the primitive in slot. */
uint32_t packed_primitive_type(const packed_scene *packed, uint32_t slot);

/* Vertex index's position, and its normal (false when it has none). */
void packed_vertex_position(const packed_scene *packed, uint32_t vertex, float position[3]);
bool packed_vertex_normal(const packed_scene *packed, uint32_t vertex, float normal[3]);

/* The octahedral encoding of a unit normal in 32 bits, as the vertex section stores it
 * (two signed 16-bit fractions, x low), and its decoding (a unit vector). */
uint32_t packed_encode_normal(const float normal[3]);
void packed_decode_normal(uint32_t bits, float normal[3]);

/* Nearest hit of a world-space ray (any direction length) at the given time (for moving
 * spheres), walking the packed BVHs exactly as the shader does (nearer child first, into
 * instances). Returns true and fills *hit when something is hit with t in (0, t_max).
 * Boundaries of volume instances count as hits, as in the shader (which enters or leaves
 * the medium there). */
bool packed_intersect_nearest(const packed_scene *packed, const float origin[3], const float direction[3],
                              float time, float t_max, packed_hit *hit);

/* The volumes containing point, packed as the shader keeps a path's media: the volume
 * instance number + 1 of the innermost in the low 16 bits, of the next one out in the high
 * 16 bits; 0 when the point is in no volume. Found by walking a ray from the point and
 * noting which volume boundaries it leaves (closed boundaries assumed). */
uint32_t packed_media_at(const packed_scene *packed, const float point[3]);

#endif
