/* pack_internal.h: what the packer's files share; not part of the library's interface
 * (pack.h is). The packer works in three steps, each in its own file:
 *
 *   collect   core/pack_collect.c    scene -> primitive lists (world, placements copied in
 *                                    or baked, instances) and their BVHs
 *   plan      core/pack.c            where every section of packed_layout.h starts
 *   write     one writer per section:
 *             core/pack_geometry.c   primitives, shapes, BVH nodes, vertices, instances
 *             core/pack_lights.c     lights and their powers, the environment's CDF
 *             core/pack_materials.c  materials, textures, images
 *
 * Each writer fills its section of p->texels at the offsets of p->layout, and notes in
 * p->out->summary what its section holds (pack.h, pack_summary).
 */
#ifndef RT_PACK_INTERNAL_H
#define RT_PACK_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "bvh.h"
#include "pack.h"
#include "packed_layout.h"
#include "scene.h"
#include "status.h"

/* Lists stop well short of 32-bit indices, which the packed records use. */
#define PACK_LIST_LIMIT (UINT32_MAX / 4)

/* One primitive on its way into a BVH: what to write and its bounding box. */
typedef struct pending_primitive {
    uint32_t type;
    uint32_t material;           /* PACKED_NONE: the instance's */
    uint32_t instance;           /* PRIMITIVE_INSTANCE */
    uint32_t vertices[3];        /* triangles: indices into the packer's vertex list */
    bool has_uvs;                /* triangles: the vertices carry uvs */
    float data[3][4];
    bvh_box box;
} pending_primitive;

typedef struct primitive_list {
    pending_primitive *items;
    uint32_t count;
    size_t capacity;
} primitive_list;

/* A triangle vertex on its way into the vertex section. */
typedef struct pending_vertex {
    float position[3];
    float normal[3];
    bool has_normal;
    float uv[2];
    float color[3];              /* linear RGB; white when its mesh has no colours */
} pending_vertex;

typedef struct vertex_list {
    pending_vertex *items;
    uint32_t count;
    size_t capacity;
} vertex_list;

/* A built BVH over a primitive list, kept until everything is placed. */
typedef struct built_tree {
    primitive_list primitives;
    bvh tree;
    uint32_t node_base, primitive_base;   /* where it lands in the packed arrays */
} built_tree;

/* Where each section starts (texel indices) and how many records it holds: the plan made
 * before any texel is written, in 64 bits so that a scene too large for 32-bit indices is
 * found before anything is cut short. */
typedef struct pack_layout {
    uint64_t material_offset, material_count;     /* material_count includes the default */
    uint64_t primitive_offset, primitive_count;
    uint64_t info_offset;
    uint64_t shape_offset, shape_texels;
    uint64_t vertex_offset, vertex_count;
    uint64_t uv_offset;
    uint64_t color_offset;                        /* PACKED_NONE: no vertex colour section */
    uint64_t node_offset, node_count;
    uint64_t instance_offset;
    uint64_t texture_offset;
    uint64_t image_offset;
    uint64_t light_offset, light_count, area_light_count;
    uint64_t environment_offset, environment_texels;
    uint64_t light_tree_offset, light_tree_nodes;   /* PACKED_NONE and 0: no light tree */
    uint64_t pixel_offset;                        /* image pixels, after all the records */
    uint64_t threaded_offset, threaded_items;     /* 0 and 0: no threaded walk */
    uint64_t threaded_stride;                     /* texels an item */
    uint64_t texel_count;
} pack_layout;

typedef struct packer {
    const scene *scene;
    const pack_options *options;
    built_tree top;
    built_tree *objects;         /* per scene object: its BVH when an instance needs one */
    bool *object_needed;
    uint32_t *instance_of_scene; /* scene instance -> packed instance index or PACKED_NONE */
    uint32_t packed_instances;
    vertex_list vertices;        /* every triangle's vertices, in the order they are stored */
    uint32_t *mesh_first_vertex; /* per mesh: where its untransformed vertices start, or
                                  * UINT32_MAX before a triangle needs them */
    uint32_t *vertex_order;      /* vertex list index -> stored index (UINT32_MAX: unused) */
    const scene_image *environment;   /* the sky's environment map when it is a light */
    pack_layout layout;
    uint32_t *texels;            /* layout.texel_count texels, zeroed before the writers */
    packed_scene *out;
} packer;

static inline uint32_t float_bits(float value)
{
    uint32_t bits;
    memcpy(&bits, &value, sizeof bits);
    return bits;
}

static inline float bits_float(uint32_t bits)
{
    float value;
    memcpy(&value, &bits, sizeof value);
    return value;
}

static inline void put_texel(uint32_t *texels, uint64_t index, uint32_t x, uint32_t y, uint32_t z, uint32_t w)
{
    texels[4 * index + 0] = x;
    texels[4 * index + 1] = y;
    texels[4 * index + 2] = z;
    texels[4 * index + 3] = w;
}

/* ---- core/pack_collect.c ------------------------------------------------------------ */

/* Collects the top level (world spheres, placements copied in or baked into the world)
 * and decides which placements stay instances (p->instance_of_scene, p->object_needed). */
rt_status pack_collect(packer *p, rt_error *error);

/* Builds one bottom-level BVH per object an instance needs, then the top-level BVH over
 * the collected primitives and one item per instance; sets out->bvh_depth and adds the
 * build time to out->bvh_build_seconds. */
rt_status pack_build_trees(packer *p, rt_error *error);

/* Whether the material index resolves to a material of the scene whose surfaces are
 * lights: emissive, or pbr with an emission and no alpha mask. */
bool pack_is_emissive(const scene *s, uint32_t material);

/* Ends a pack for its BVH cache (NULL: nothing): on success the trees of this pack become
 * the ones the next pack may take, the rest are dropped; on failure this pack's are. */
void pack_bvh_cache_finish(pack_bvh_cache *cache, bool succeeded);

/* Inverts the affine 3x4 matrix m into inverse. Returns false when it is singular. */
bool pack_invert_affine(const float m[3][4], float inverse[3][4]);

/* ---- core/pack_geometry.c ----------------------------------------------------------- */

/* Chooses where each used vertex is stored (p->vertex_order) and returns how many are. */
rt_status pack_order_vertices(packer *p, uint32_t *vertex_count, rt_error *error);

/* Writes every BVH's primitive records, their info and shape records, and its nodes. */
void pack_write_primitives(packer *p);

/* The number of items of the threaded walk (packed_layout.h "threaded walk") the packer
 * writes for this scene: its top-level interior nodes and primitives, or 0 when the scene
 * is not still spheres and quads in one level, the lists would be too long, or the
 * options ask for none (pack_geometry.c). */
uint64_t pack_threaded_items(const packer *p);

/* Texels an item of the threaded walk takes in this scene: 3 with quads, else 2. */
uint32_t pack_threaded_stride(const packer *p);

/* Writes the threaded walk's lists after the primitives and nodes (pack_geometry.c). */
void pack_write_threaded(packer *p);

/* Whether the scene needs the vertex colour section: a material with vertex_colors used
 * by a mesh with colours (packed_layout.h "colours"). */
bool pack_needs_vertex_colors(const scene *s);

/* Writes the vertex section (positions and encoded normals), the uv section and, when
 * the plan has one, the vertex colour section. */
void pack_write_vertices(packer *p);

/* Writes the instance records. */
rt_status pack_write_instances(packer *p, rt_error *error);

/* ---- core/pack_lights.c ------------------------------------------------------------- */

/* The emissive world primitives, which become the first (area) lights. */
uint32_t pack_count_area_lights(const packer *p);

/* Writes the light section and the environment's sampling distribution. */
rt_status pack_write_lights(packer *p, rt_error *error);

/* ---- core/pack_materials.c ---------------------------------------------------------- */

/* Writes the materials and the default grey one after them. */
void pack_write_materials(packer *p);

/* Writes the texture records, the image records and the images' pixels. */
void pack_write_textures(packer *p);

#endif
