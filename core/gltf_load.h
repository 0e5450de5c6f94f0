/* gltf_load.h: reading a glTF 2.0 file (.gltf with external or data-URI buffers, or .glb)
 * into flat meshes, materials, encoded images and the placements of its default scene,
 * through tinygltf (a thin C shim over C++, like obj_load.cpp).
 *
 * tinygltf (Debian's 2.7.0, linked as its shared library) parses the JSON, the GLB
 * container, data URIs and external buffer files; gltf_load() validates everything it
 * returns before using it (indices, ranges, types, numbers) and never parses JSON itself.
 * So a property tinygltf does not read is not read here either; where tinygltf silently
 * ignores a value of the wrong JSON type, so does this.
 *
 * What comes back (gltf_model), in the renderer's conventions:
 *   - meshes: one per glTF mesh, its primitives' triangles together. Modes 4 (triangles),
 *     5 (strip) and 6 (fan) become triangle lists in glTF's corner order; points and lines
 *     (modes 0-3) are skipped with one warning for the file. Indexed and not. Per vertex:
 *     positions (POSITION), normals (NORMAL, made unit length; NULL when no primitive has
 *     them: flat shading, as glTF asks; a primitive without them among others that have
 *     them gets its triangles' flat normals, its vertices unshared), uvs (TEXCOORD_0, or
 *     NULL; (0, 0) where a primitive has none), colours (COLOR_0's RGB, linear as glTF
 *     defines them, or NULL; white where a primitive has none). Integer attributes are
 *     read as KHR_mesh_quantization and the accessor's `normalized` say. uvs are turned
 *     to the renderer's convention (v up: v' = 1 - v) after the material's
 *     KHR_texture_transform is applied to them (see gltf_material);
 *   - triangle_materials: per triangle, the index of its primitive's material, or -1;
 *   - materials: the metallic-roughness parameters with their textures (an image and the
 *     sampler's wrap modes), KHR_materials_emissive_strength folded into emissive,
 *     KHR_materials_transmission and KHR_materials_ior;
 *   - images: the encoded file (PNG or JPEG bytes: embedded in a buffer view, a data URI,
 *     or read from the external file), decoded later by the asset loader;
 *   - placements: each node of the default scene (`scene`, else scenes[0], else every node
 *     that is no node's child) that has a mesh with triangles, with its world transform
 *     (the parents' matrices or TRS composed, in double), in depth-first order; cameras and
 *     KHR_lights_punctual lights likewise, each with its node's transform and name.
 *
 * Extensions: KHR_lights_punctual, KHR_materials_emissive_strength, _transmission, _ior,
 * KHR_texture_transform and KHR_mesh_quantization are read. Any other extension in
 * extensionsRequired is an error naming it; others in extensionsUsed give one warning.
 * Ignored with a warning: skins and morph targets (the meshes are placed in their bind
 * pose), TEXCOORD_1 and up (textures that ask for them read TEXCOORD_0), a material whose
 * textures have different KHR_texture_transforms (the base colour texture's, else the
 * first one's applies to all), the transmission texture, KHR_lights_punctual's range.
 * Ignored silently: TANGENT (the renderer derives tangents from the uvs, per triangle),
 * occlusion textures, samplers' filters, animations, extras.
 *
 * Errors (RT_ERROR_INPUT): one sentence "PATH: WHERE: WHAT", WHERE the JSON path of what
 * is wrong or of what refers to it, e.g.
 *   "m.gltf: meshes[2].primitives[0].attributes.POSITION: accessor 7 reads past the end of
 *    buffer view 3 (of buffer 1): it needs bytes 0 to 180, the view has 96"
 *   "m.gltf: meshes[0].primitives[1].indices: index 40 (element 12 of accessor 3) is out
 *    of range: the primitive has 30 vertices"
 *   "m.gltf: nodes[1].children: node 0 is an ancestor of nodes[1] (the node hierarchy has
 *    a cycle)"
 *   "m.gltf: extensionsRequired: the extension 'KHR_draco_mesh_compression' is required
 *    but not supported"
 *   "m.gltf: tinygltf: [json.exception.parse_error.101] parse error at line 3, ..." (what
 *    tinygltf refuses, in its words: malformed JSON, a missing required property, a
 *    missing buffer file, a GLB whose chunks do not add up)
 *   "m.glb: not a binary glTF file (it does not start with 'glTF')", and errno's reason
 *   for a file that cannot be read.
 * Out of memory: RT_ERROR_RUNTIME. No C++ exception crosses into C. On failure *out is
 * left zeroed.
 */
#ifndef RT_GLTF_LOAD_H
#define RT_GLTF_LOAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GLTF_NAME_MAX 64         /* names kept, with the NUL (longer ones are cut) */
#define GLTF_MAX_WARNINGS 8      /* warnings kept; more are only counted */
#define GLTF_WARNING_MAX 256     /* bytes of one warning, with the NUL */

/* A texture a material uses: an image and how lookups outside [0, 1] fold. */
typedef struct gltf_texture_ref {
    int image;                   /* index into gltf_model.images, or -1: no texture */
    int wrap_u, wrap_v;          /* IMAGE_WRAP_* of packed_layout.h (the sampler's wrapS,
                                  * wrapT; REPEAT without a sampler) */
} gltf_texture_ref;

typedef enum gltf_alpha_mode { GLTF_ALPHA_OPAQUE = 0, GLTF_ALPHA_MASK = 1, GLTF_ALPHA_BLEND = 2 } gltf_alpha_mode;

/* A metallic-roughness material, its factors checked to glTF's ranges. */
typedef struct gltf_material {
    char name[GLTF_NAME_MAX];    /* "" when unnamed */
    float base_color[4];         /* baseColorFactor, linear RGBA */
    gltf_texture_ref base_color_texture;     /* sRGB */
    float metallic, roughness;   /* metallicFactor, roughnessFactor */
    gltf_texture_ref metallic_roughness_texture;   /* linear: G roughness, B metallic */
    gltf_texture_ref normal_texture;         /* linear, tangent space */
    float emissive[3];           /* emissiveFactor x emissiveStrength */
    gltf_texture_ref emissive_texture;       /* sRGB */
    gltf_alpha_mode alpha_mode;
    float alpha_cutoff;          /* MASK: default 0.5 */
    bool double_sided;
    float transmission;          /* KHR_materials_transmission transmissionFactor, 0 without */
    float ior;                   /* KHR_materials_ior, 1.5 without */
} gltf_material;

/* An image file's bytes, as stored (the asset loader decodes them). */
typedef struct gltf_image {
    unsigned char *bytes;        /* malloc'd; never NULL after a successful load */
    size_t size;                 /* > 0 */
    char name[GLTF_NAME_MAX];    /* its name, else its URI's file name, else "" */
} gltf_image;

/* A triangle mesh. Arrays are malloc'd, so a caller may take them over by copying the
 * pointer and setting the field to NULL. */
typedef struct gltf_mesh {
    char name[GLTF_NAME_MAX];
    float *positions;            /* 3 per vertex */
    float *normals;              /* 3 per vertex, or NULL */
    float *uvs;                  /* 2 per vertex (v up), or NULL */
    float *colors;               /* 3 per vertex (linear RGB), or NULL */
    uint32_t *indices;           /* 3 per triangle */
    int *triangle_materials;     /* per triangle: index into materials, or -1 */
    int vertex_count, triangle_count;   /* 0 for a mesh of points or lines only */
} gltf_mesh;

/* A 3x4 affine map, object to world: world = M[:, 0..2] * p + M[:, 3], rows x, y, z. */
typedef double gltf_matrix[3][4];

typedef struct gltf_placement {
    int mesh;                    /* index into meshes; its triangle_count > 0 */
    gltf_matrix object_to_world;
    char node_name[GLTF_NAME_MAX];
} gltf_placement;

/* A camera placed by a node: it looks down the node's -Z, +Y up. */
typedef struct gltf_camera {
    char name[GLTF_NAME_MAX];    /* the camera's */
    char node_name[GLTF_NAME_MAX];
    int index;                   /* into the file's cameras */
    bool orthographic;           /* rtspheres renders perspective cameras only */
    double yfov;                 /* perspective: vertical field of view, radians, (0, pi) */
    double aspect_ratio;         /* width / height, or 0 when the file gives none */
    gltf_matrix camera_to_world;
} gltf_camera;

typedef enum gltf_light_type { GLTF_LIGHT_POINT = 0, GLTF_LIGHT_SPOT = 1, GLTF_LIGHT_DIRECTIONAL = 2 } gltf_light_type;

/* A KHR_lights_punctual light placed by a node: at its origin, pointing down its -Z. */
typedef struct gltf_light {
    char name[GLTF_NAME_MAX];
    gltf_light_type type;
    float color[3];              /* linear RGB, in [0, 1] */
    float intensity;             /* candela (point, spot) or lux (directional), >= 0 */
    float inner_cone, outer_cone;  /* spot: half-angles in radians, 0 <= inner < outer <= pi/2 */
    gltf_matrix light_to_world;
} gltf_light;

typedef struct gltf_model {
    gltf_mesh *meshes;
    int mesh_count;
    gltf_material *materials;
    int material_count;
    gltf_image *images;
    int image_count;
    gltf_placement *placements;
    int placement_count;
    gltf_camera *cameras;        /* in the order the scene's nodes place them */
    int camera_count;
    gltf_light *lights;
    int light_count;
    int warning_count;           /* may exceed GLTF_MAX_WARNINGS */
    char warnings[GLTF_MAX_WARNINGS][GLTF_WARNING_MAX];  /* "WHERE: WHAT", no path prefix */
} gltf_model;

/* Reads the glTF file at path (.glb by its first bytes "glTF"; a file named .glb without
 * them is refused) into *out (zeroed first; on failure left zeroed). */
rt_status gltf_load(const char *path, gltf_model *out, rt_error *error);

/* Frees everything *model holds (not model itself) and zeroes it. NULL is allowed. */
void gltf_model_free(gltf_model *model);

#ifdef __cplusplus
}
#endif

#endif
