/* pack.h: turns a scene into the packed texel array the tracer reads (plain C, tested
 * without a GPU). The record layout is packed_layout.h, the one definition shared with the
 * shader.
 *
 * What it builds: a top-level BVH (root: node 0) over the world's own primitives and the
 * instances, and one bottom-level BVH per object that an instance places (each object
 * once, however often it is placed). The world's primitives are its spheres, the shapes
 * and mesh triangles of objects placed with the identity and no volume (copied into the
 * top level), and those of placements baked into it (moved by their transform: emitters,
 * so that they become lights, and placements whose shapes a transform keeps exactly,
 * within a memory budget; core/pack_collect.c has the rule). Volumes and the other
 * placements are instances. Shapes without a material get the instance's, and failing
 * that a default grey Lambertian material (appended last).
 *
 * Output: texel_count texels of four uint32 each (texels[4*i .. 4*i+3] is texel i);
 * floats are stored as their bit patterns. Reading them back on the CPU (records, the
 * shader's traversal) is packed_traverse.h's. The packer's steps and files:
 * pack_internal.h.
 *
 * Defaults of pack_options (all zero): BVHs built with bvh_build_config defaults, a bake
 * budget of PACK_DEFAULT_BAKE_BUDGET (262,144) primitives, placements baked by the rule,
 * no BVH cache.
 *
 * The BVH cache (pack_bvh_cache): a BVH is a pure function of its primitives' boxes and
 * the build config (bvh.h), so a packer given a cache takes each tree whose boxes and
 * config equal, bit for bit, those of a tree the previous pack_scene() with that cache
 * built, instead of building it again; the texels are the same either way. The cache then
 * holds the trees of this pack (those of the one before are dropped), so it costs one
 * scene's BVHs and boxes. A sweep or an animation whose rows change lights, materials or
 * the camera but no shape keeps every tree (core/render_job.c makes one per job).
 */
#ifndef RT_PACK_H
#define RT_PACK_H

#include <stdbool.h>
#include <stdint.h>

#include "bvh.h"
#include "scene.h"
#include "status.h"

/* The default of pack_options.bake_budget. */
#define PACK_DEFAULT_BAKE_BUDGET 262144

typedef struct pack_bvh_cache pack_bvh_cache;

typedef struct pack_options {
    const bvh_build_config *bvh_config;  /* NULL: defaults */
    pack_bvh_cache *bvh_cache;           /* NULL: every BVH built; else see "The BVH cache" */
    uint32_t bake_budget;    /* an object's placements with a transform are baked into the
                              * top level while the copies beyond the first hold at most
                              * this many primitives (core/pack_collect.c says when else);
                              * 0: PACK_DEFAULT_BAKE_BUDGET */
    bool keep_instances;     /* true: only identity placements and emitters join the top
                              * level, every other placement stays an instance (the rule
                              * before baking; for tests and measurements) */
    bool no_threaded_walk;   /* true: no threaded walk section (packed_layout.h), so the
                              * tracer walks the nodes with its stack (for tests and
                              * measurements) */
} pack_options;

/* What a packed scene holds, noted by each section's writer as it writes: render.c
 * chooses the tracer variant from it (gpu.h, GPU_OMIT_*) without reading texels again.
 * The type sets have bit 1 << tag set for each tag of packed_layout.h present. */
typedef struct pack_summary {
    uint32_t primitive_types;    /* PRIMITIVE_* records in any BVH level; PRIMITIVE_INSTANCE:
                                  * a second level */
    uint32_t light_types;        /* LIGHT_* records in the light section (LIGHT_SPHERE,
                                  * _QUAD, _TRIANGLE: emissive world primitives;
                                  * LIGHT_ENVIRONMENT: the sky's environment map) */
    bool volumes;                /* an instance is a volume (INSTANCE_VOLUME) */
    bool emitters;               /* an emissive material, whether a primitive uses it or not */
    bool textures;               /* a texture record, or a material naming a texture */
    bool normal_maps;            /* a material with a normal map */
    uint32_t material_types;     /* MATERIAL_* tags of the material section (the default
                                  * material included) */
    bool pbr;                    /* a MATERIAL_PBR material */
    bool alpha_mask;             /* a material with MATERIAL_FLAG_ALPHA_MASK */
    bool vertex_colors;          /* the vertex colour section (packed_layout.h "colours") */
} pack_summary;

typedef struct packed_scene {
    uint32_t *texels;
    uint32_t texel_count;
    uint32_t material_offset, material_count;   /* material_count includes the default */
    uint32_t primitive_offset, primitive_count;
    uint32_t info_offset;                       /* primitive info, four to a texel */
    uint32_t shape_offset, shape_texels;        /* moving sphere and quad records */
    uint32_t vertex_offset, vertex_count;
    uint32_t uv_offset;                         /* two vertices' uvs to a texel */
    uint32_t color_offset;                      /* vertex colours, or PACKED_NONE */
    uint32_t node_offset, node_count;
    uint32_t instance_offset, instance_count;
    uint32_t texture_offset, texture_count;
    uint32_t image_offset, image_count;
    uint32_t light_offset, light_count;
    uint32_t area_light_count;                  /* the first lights: emissive primitives */
    uint32_t light_tree_offset;                 /* PACKED_NONE: no light tree (at most
                                                 * LIGHT_LOCAL_CHOICE_MAX lights) */
    uint32_t light_tree_depth;                  /* its deepest leaf (0: none) */
    uint32_t threaded_offset, threaded_items;   /* the threaded walk's lists (0 items:
                                                 * none; packed_layout.h) */
    uint32_t default_material;
    uint32_t triangle_count;     /* triangles stored (mesh triangles once per object) */
    int bvh_depth;               /* deepest level of any BVH */
    double bvh_build_seconds;    /* all BVH builds together */
    uint32_t bvh_built;          /* BVHs built by this pack (the top level and one per
                                  * instanced object) */
    uint32_t bvh_reused;         /* BVHs taken from pack_options.bvh_cache instead */
    pack_summary summary;        /* what the sections hold */
    uint64_t texel_hash;         /* hash_bytes (hash.h) of the texels from HASH_START: the
                                  * one hash of the packed scene (the device's copy, the
                                  * scene hash of render.h) */
} packed_scene;

/* Returns options with every field at its default (all zero). */
pack_options pack_options_defaults(void);

/* Builds the BVHs and writes all records. options may be NULL. Meshes must be loaded
 * (scene_load_assets) and images too. A scene whose indices would not fit 32 bits is
 * RT_ERROR_INPUT; an instance whose transform cannot be inverted too. The caller frees
 * *out with packed_scene_free(). */
rt_status pack_scene(const scene *s, const pack_options *options, packed_scene *out, rt_error *error);

/* Creates an empty BVH cache into *out (RT_ERROR_RUNTIME when memory runs out). Free it
 * with pack_bvh_cache_free() (NULL is allowed there). */
rt_status pack_bvh_cache_create(pack_bvh_cache **out, rt_error *error);
void pack_bvh_cache_free(pack_bvh_cache *cache);

/* Frees out->texels and zeroes *out. */
void packed_scene_free(packed_scene *packed);

/* The octahedral encoding of a unit normal in 32 bits, as the vertex section stores it
 * (two signed 16-bit fractions, x low); packed_traverse.h decodes it. */
uint32_t packed_encode_normal(const float normal[3]);

#endif
