/* scene.h: the scene graph as plain C arrays, the parser's output and the packer's input.
 *
 * A scene is built by the parser (from text: core/scene_parse.c runs it, core/scene_builder.c
 * fills the scene) or by hand (tests); the packer (core/pack*.c) turns it into GPU records.
 * It owns its arrays: scene_free() frees them.
 * Nothing here calls GL.
 *
 * Defaults (scene_defaults()):
 *   camera:  look_from (0,0,1), look_at (0,0,0), up (0,1,0), vertical fov 40 degrees,
 *            aperture 0 (pinhole), focus_distance 0 (= distance from look_from to look_at)
 *   render:  640x360, 64 samples per pixel, max depth 16, seed 1
 *   camera shutter open 0, close 1
 *   sky:     gradient from (1,1,1) at the horizon/below to (0.5,0.7,1.0) straight up,
 *            intensity 1, rotation 0, faces and environment -1
 *   materials added by hand should set the texture fields to -1 (scene_material_defaults)
 *   no materials, spheres, shapes, objects, instances, meshes or warnings
 */
#ifndef RT_SCENE_H
#define RT_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "packed_layout.h"
#include "tracer_interface.h"

#define SCENE_NAME_MAX 64
#define SCENE_MAX_IMAGE_SIDE 65536      /* widest and tallest image (the `render` line, --size):
                                         * larger than any device's textures, rendered in
                                         * tiles (render_job.h) */

/* Light groups (`group NAME` on lights, emissive materials and the sky): each group's
 * contribution is written as its own layer with --light-groups (render.h). Group 0 is
 * "default", where everything without a group clause falls. The layers cost the tracer
 * 16 bytes per pixel each (docs/scene-format.md, "Light groups"). */
#define SCENE_LIGHT_GROUP_MAX 32
#define SCENE_LIGHT_GROUP_NAME_MAX 24   /* bytes of a group's name, so NAME.R fits a channel name */
#define SCENE_DEFAULT_LIGHT_GROUP "default"

typedef struct scene_camera {
    float look_from[3];
    float look_at[3];
    float up[3];
    float vertical_fov_degrees;  /* full vertical field of view, 0 < fov < 180 */
    float aperture;              /* lens diameter; 0 is a pinhole */
    float focus_distance;        /* 0 means |look_at - look_from| */
    float shutter_open;          /* each ray gets a time uniform in [open, close]; moving */
    float shutter_close;         /* spheres are at their time-0 and time-1 centres; 0 and 1 */
} scene_camera;

typedef struct scene_render_settings {
    int width, height;           /* pixels, >= 1 */
    int samples_per_pixel;       /* >= 1 */
    int max_depth;               /* path segments per sample, >= 1 */
    uint32_t seed;
} scene_render_settings;

/* Cube-map face order, as the seed report's sky box and OpenGL use it. */
enum { SKY_FACE_POSITIVE_X, SKY_FACE_NEGATIVE_X, SKY_FACE_POSITIVE_Y, SKY_FACE_NEGATIVE_Y, SKY_FACE_POSITIVE_Z,
       SKY_FACE_NEGATIVE_Z, SKY_FACE_COUNT };

typedef struct scene_sky {
    int type;                    /* SKY_* of tracer_interface.h: gradient, constant, box, environment */
    float bottom[3];             /* gradient: colour at direction.y = -1; constant: the colour */
    float top[3];                /* gradient: colour at direction.y = +1 */
    int faces[SKY_FACE_COUNT];   /* box: indices into scene.images, +X -X +Y -Y +Z -Z */
    int environment;             /* environment: index into scene.images */
    float intensity;             /* multiplies every kind of sky; default 1 */
    float rotation_degrees;      /* box and environment: turn about +Y; default 0 */
    int light_group;             /* index into scene.light_groups (the Whitted ambient term
                                  * counts as the sky's too); default 0 */
} scene_sky;

/* An image file used by a texture, a normal map or the sky: recorded by the parser
 * (deduplicated by resolved path), pixels filled by the asset loader. An image of a glTF
 * model comes with its file's bytes (encoded) and a path that only names it. */
typedef struct scene_image {
    char path[1024];
    char position[256];          /* "file:line:column" of the first statement naming it */
    bool data;                   /* values, not colours (normal maps): never sRGB-decoded */
    unsigned char *encoded;      /* NULL, or the image file's bytes, which the loader decodes
                                  * instead of reading path (owned; scene_free frees it) */
    size_t encoded_size;
    int wrap[2];                 /* IMAGE_WRAP_* of packed_layout.h for u and v: how lookups
                                  * outside [0, 1] fold; 0 (repeat) unless a glTF sampler says */
    int width, height;           /* filled by the loader */
    float *pixels;               /* filled by the loader: RGBA, linear, rows top to bottom */
} scene_image;

/* A named texture: a colour that varies over a surface. type is a TEXTURE_* tag of
 * packed_layout.h. */
typedef struct scene_texture {
    char name[SCENE_NAME_MAX];
    int type;
    float color[3];              /* constant */
    float scale;                 /* checker: cell size in world units; noise kinds: frequency */
    int even, odd;               /* checker: the two textures (indices into scene.textures) */
    int image;                   /* image: index into scene.images */
} scene_texture;

/* A light that is not a surface: point, spot or sun (area lights are emissive shapes). */
typedef enum scene_light_type {
    SCENE_LIGHT_POINT = 0,
    SCENE_LIGHT_SPOT = 1,
    SCENE_LIGHT_SUN = 2,
} scene_light_type;

typedef enum scene_falloff {
    FALLOFF_INVERSE_SQUARE = 0,  /* physical: intensity / d^2 */
    FALLOFF_POLYNOMIAL = 1,      /* the seed report's: intensity / (c + l d + q d^2) */
} scene_falloff;

typedef struct scene_light {
    scene_light_type type;
    float position[3];           /* point, spot */
    float direction[3];          /* spot: where it points; sun: the direction light travels */
    float color[3];              /* colour x intensity: point/spot W/sr-like, sun irradiance */
    float spot_outer_degrees;    /* spot: half-angle where it ends (default 30) */
    float spot_inner_degrees;    /* spot: half-angle of full intensity (default 25) */
    float sun_angle_degrees;     /* sun: angular diameter, soft shadows (default 0.53) */
    scene_falloff falloff;
    float attenuation[3];        /* polynomial falloff: constant, linear, quadratic */
    int light_group;             /* index into scene.light_groups; default 0 */
} scene_light;

/* One named material. type is a MATERIAL_* tag of packed_layout.h; fields that the
 * type does not use are ignored (and left at zero by the parser). */
typedef struct scene_material {
    char name[SCENE_NAME_MAX];
    int type;
    float albedo[3];             /* lambertian, metal */
    float fuzz;                  /* metal, 0..1 */
    float index_of_refraction;   /* dielectric, > 0 */
    float emission[3];           /* emissive: colour x strength (radiance) */
    int albedo_texture;          /* -1: albedo is the colour above; else index into scene.textures */
    int emission_texture;        /* -1, or a texture whose colour x strength is the emission */
    int normal_map;              /* -1, or index into scene.images: a tangent-space normal map */
    float phong_exponent;        /* Whitted/Phong specular exponent; 0: the default (32) */
    float specular[3];           /* Whitted/Phong specular colour; default (0.04, 0.04, 0.04)
                                  * for lambertian, the albedo for metal */
    bool specular_set;           /* false: use the default above */
    /* pbr: the glTF 2.0 metallic-roughness model (docs/scene-format.md); albedo is its base
     * colour, albedo_texture its base colour texture, index_of_refraction its ior (whoever
     * makes a pbr material sets it: glTF's default is 1.5), emission / emission_texture /
     * normal_map as above. */
    float metallic;              /* pbr: 0..1 */
    float roughness;             /* pbr: perceptual roughness 0..1 (GGX alpha = roughness^2) */
    float transmission;          /* pbr: 0..1, the share of the dielectric part transmitted
                                  * (KHR_materials_transmission) */
    int metallic_roughness_texture;  /* pbr: -1, or index into scene.images: roughness in
                                  * its G channel, metallic in B (as glTF packs them) */
    int alpha_mode;              /* pbr: SCENE_ALPHA_OPAQUE or SCENE_ALPHA_MASK */
    float alpha;                 /* pbr: base alpha (glTF baseColorFactor's a), 1 by default */
    float alpha_cutoff;          /* pbr, mask: where alpha is below it there is no surface */
    bool vertex_colors;          /* pbr: the base colour is multiplied by the mesh's vertex
                                  * colours (PLY, glTF COLOR_0) */
    bool one_sided;              /* emissive and pbr emission: only the front face emits (the
                                  * side the geometric normal points to); default both sides */
    int light_group;             /* what it emits: index into scene.light_groups; default 0 */
} scene_material;

/* pbr alpha modes (glTF's OPAQUE and MASK; BLEND is imported as MASK). */
enum { SCENE_ALPHA_OPAQUE = 0, SCENE_ALPHA_MASK = 1 };

typedef struct scene_sphere {
    float center[3];
    float radius;                /* > 0 */
    int material;                /* index into scene.materials */
} scene_sphere;

/* ---- the general scene model (groups, transforms, instancing, meshes, volumes) --------
 *
 * Geometry lives in objects: an object is a set of shapes (or one mesh) in its own
 * coordinates. Instances place objects in the world with a transform, so an object placed
 * many times costs its geometry once (the renderer builds one bottom-level BVH per object
 * and a top-level BVH over instances, as hardware ray tracing APIs do). The parser turns
 * nested groups into objects and instances, composing transforms.
 *
 * The plain `spheres` array above is the world's own spheres, with no transform: the
 * common case of simple scenes, kept as it is.
 */

typedef enum scene_shape_type {
    SHAPE_SPHERE = 0,            /* points[0] centre, radius */
    SHAPE_MOVING_SPHERE = 1,     /* points[0] centre at time 0, points[1] at time 1, radius */
    SHAPE_TRIANGLE = 2,          /* points[0..2] corners (counter-clockwise seen from the front);
                                  * optional normals and uvs per corner (has_normals, has_uvs) */
    SHAPE_QUAD = 3,              /* points[0] corner Q, points[1] edge u, points[2] edge v:
                                  * the parallelogram Q + a u + b v, a, b in [0,1]; uv = (a, b) */
} scene_shape_type;

typedef struct scene_shape {
    scene_shape_type type;
    int material;                /* index into scene.materials, or -1: the instance's */
    float points[3][3];
    float radius;
    /* SHAPE_TRIANGLE only (false and zero for every other type and for a triangle written
     * without them): per-corner shading data, corner k going with points[k], in the
     * object's coordinates like points (an instance transform applies to them as to a
     * mesh's vertex normals). The same data a mesh triangle has through its vertices. */
    bool has_normals;            /* true: normals[k] is the unit shading normal at corner k;
                                  * false: flat shading (the geometric normal) */
    bool has_uvs;                /* true: uvs[k] is the texture coordinate (u, v) at corner k,
                                  * v pointing up as in scene_mesh.uvs; false: none */
    float normals[3][3];         /* unit length when has_normals, else zero */
    float uvs[3][2];             /* any finite values when has_uvs, else zero */
} scene_shape;

/* A triangle mesh, loaded from an OBJ or PLY file once however often it is placed. The
 * parser records path and position; the asset loader (scene_assets.h) fills the arrays.
 * A mesh of a glTF model comes filled (scene_gltf.h) and its path only names it. */
typedef struct scene_mesh {
    char path[1024];             /* resolved relative to the scene file that names it */
    char position[256];          /* "file:line:column" of the first statement naming it */
    int default_material;        /* for faces without a usable usemtl: -1 = the instance's */
    /* Filled by the loader: */
    float *positions;            /* 3 per vertex */
    float *normals;              /* 3 per vertex, or NULL: flat shading */
    float *uvs;                  /* 2 per vertex, or NULL; v points up (v = 1: image top row) */
    float *colors;               /* 3 per vertex (linear RGB, 0..1), or NULL: none; a pbr
                                  * material with vertex_colors multiplies its base colour
                                  * by them (PLY, glTF COLOR_0) */
    uint32_t *indices;           /* 3 per triangle, into the vertex arrays */
    int *triangle_materials;     /* per triangle: index into scene.materials or -1 */
    int vertex_count, triangle_count;
} scene_mesh;

/* An object: shapes[first_shape .. first_shape + shape_count - 1], or mesh >= 0. */
typedef struct scene_object {
    int first_shape, shape_count;
    int mesh;                    /* index into scene.meshes, or -1 */
} scene_object;

/* One placement of an object. object_to_world maps object coordinates to the world:
 * world = M[:, 0..2] * p + M[:, 3], rows x, y, z. */
typedef struct scene_instance {
    int object;
    float object_to_world[3][4];
    int material;                /* overrides shapes whose material is -1; -1: none */
    bool volume;                 /* the object is the closed boundary of a constant medium */
    float density;               /* volume: scattering events per unit length */
    float volume_albedo[3];      /* volume: colour of the isotropic scattering */
} scene_instance;

/* A warning recorded while the scene was read or its files loaded (scene_assets.h says
 * which). The core prints nothing: the caller shows each message, e.g. as
 * "rtspheres render: warning: MESSAGE". MESSAGE starts with the "file:line:column" of the
 * statement concerned, like an error. */
#define SCENE_WARNING_MAX 1024
typedef struct scene_warning {
    char message[SCENE_WARNING_MAX];
} scene_warning;

typedef struct scene {
    scene_camera camera;
    scene_render_settings render;
    scene_sky sky;
    scene_material *materials;
    int material_count;
    size_t material_capacity;
    scene_sphere *spheres;
    int sphere_count;
    size_t sphere_capacity;
    scene_shape *shapes;
    int shape_count;
    size_t shape_capacity;
    scene_object *objects;
    int object_count;
    size_t object_capacity;
    scene_instance *instances;
    int instance_count;
    size_t instance_capacity;
    scene_mesh *meshes;
    int mesh_count;
    size_t mesh_capacity;
    scene_texture *textures;
    int texture_count;
    size_t texture_capacity;
    scene_image *images;
    int image_count;
    size_t image_capacity;
    scene_light *lights;
    int light_count;
    size_t light_capacity;
    float ambient[3];            /* Whitted integrator's ambient term; default 0.03 0.03 0.03 */
    char light_groups[SCENE_LIGHT_GROUP_MAX][SCENE_NAME_MAX];   /* [0] is "default", then in
                                  * the order the scene first names them */
    int light_group_count;       /* >= 1 */
    scene_warning *warnings;     /* things worth telling the user that do not stop the render */
    int warning_count;
    size_t warning_capacity;     /* (e.g. a mesh's missing MTL file), in the order found */
} scene;

/* Fills *s with the defaults above and empty arrays. Never fails; frees nothing. */
void scene_defaults(scene *s);

/* Frees the arrays of *s (not *s itself) and leaves it as scene_defaults() would. */
void scene_free(scene *s);

/* Returns a material with no textures (texture fields -1), everything else zero. */
scene_material scene_material_defaults(void);

/* Appends a material and returns its index, or -1 when memory runs out. */
int scene_add_material(scene *s, const scene_material *material);

/* Appends a sphere and returns its index, or -1 when memory runs out. */
int scene_add_sphere(scene *s, const scene_sphere *sphere);

/* Append one element and return its index, or -1 when memory runs out. */
int scene_add_shape(scene *s, const scene_shape *shape);
int scene_add_object(scene *s, const scene_object *object);
int scene_add_instance(scene *s, const scene_instance *instance);
int scene_add_mesh(scene *s, const scene_mesh *mesh);
int scene_add_texture(scene *s, const scene_texture *texture);
int scene_add_image(scene *s, const scene_image *image);
int scene_add_light(scene *s, const scene_light *light);

/* Returns the index of the light group called name, adding it when it is new; -1 when
 * SCENE_LIGHT_GROUP_MAX groups are already there. */
int scene_light_group(scene *s, const char *name);

/* Appends a warning whose message is the printf-style format (cut to SCENE_WARNING_MAX - 1
 * bytes); returns its index, or -1 when memory runs out. */
int scene_add_warning(scene *s, const char *format, ...) __attribute__((format(printf, 2, 3)));

/* Returns a light of the given type with every default set (white, intensity 1,
 * inverse-square falloff, spot cone 25/30 degrees, sun 0.53 degrees, pointing down). */
scene_light scene_light_defaults(scene_light_type type);

/* Sets m to the identity placement (object_to_world = [I | 0]). */
void scene_identity_transform(float m[3][4]);

/* Returns the index of the material called name, or -1. */
int scene_find_material(const scene *s, const char *name);

#endif
