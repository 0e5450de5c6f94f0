/* scene.h: the scene graph as plain C arrays, the parser's output and the packer's input.
 *
 * A scene is built by scene_parse.c (from text) or by hand (tests); the packer
 * (pack.c) turns it into GPU records. It owns its arrays: scene_free() frees them.
 * Nothing here calls GL.
 *
 * Defaults (scene_defaults()):
 *   camera:  look_from (0,0,1), look_at (0,0,0), up (0,1,0), vertical fov 40 degrees,
 *            aperture 0 (pinhole), focus_distance 0 (= distance from look_from to look_at)
 *   render:  640x360, 64 samples per pixel, max depth 16, seed 1
 *   sky:     gradient from (1,1,1) at the horizon/below to (0.5,0.7,1.0) straight up
 *   no materials, no spheres
 */
#ifndef RT_SCENE_H
#define RT_SCENE_H

#include <stdint.h>

#include "packed_layout.h"

#define SCENE_NAME_MAX 64

typedef struct scene_camera {
    float look_from[3];
    float look_at[3];
    float up[3];
    float vertical_fov_degrees;  /* full vertical field of view, 0 < fov < 180 */
    float aperture;              /* lens diameter; 0 is a pinhole */
    float focus_distance;        /* 0 means |look_at - look_from| */
} scene_camera;

typedef struct scene_render_settings {
    int width, height;           /* pixels, >= 1 */
    int samples_per_pixel;       /* >= 1 */
    int max_depth;               /* path segments per sample, >= 1 */
    uint32_t seed;
} scene_render_settings;

typedef enum scene_sky_type {
    SKY_GRADIENT = 0,            /* lerp(bottom, top, 0.5 * (direction.y + 1)) */
    SKY_CONSTANT = 1,            /* bottom colour everywhere */
} scene_sky_type;

typedef struct scene_sky {
    scene_sky_type type;
    float bottom[3];             /* gradient: colour at direction.y = -1; constant: the colour */
    float top[3];                /* gradient: colour at direction.y = +1 */
} scene_sky;

/* One named material. type is a MATERIAL_* tag of packed_layout.h; fields that the
 * type does not use are ignored (and left at zero by the parser). */
typedef struct scene_material {
    char name[SCENE_NAME_MAX];
    int type;
    float albedo[3];             /* lambertian, metal */
    float fuzz;                  /* metal, 0..1 */
    float index_of_refraction;   /* dielectric, > 0 */
    float emission[3];           /* emissive: colour x strength (radiance) */
} scene_material;

typedef struct scene_sphere {
    float center[3];
    float radius;                /* > 0 */
    int material;                /* index into scene.materials */
} scene_sphere;

typedef struct scene {
    scene_camera camera;
    scene_render_settings render;
    scene_sky sky;
    scene_material *materials;
    int material_count, material_capacity;
    scene_sphere *spheres;
    int sphere_count, sphere_capacity;
} scene;

/* Fills *s with the defaults above and empty arrays. Never fails; frees nothing. */
void scene_defaults(scene *s);

/* Frees the arrays of *s (not *s itself) and leaves it as scene_defaults() would. */
void scene_free(scene *s);

/* Appends a material and returns its index, or -1 when memory runs out. */
int scene_add_material(scene *s, const scene_material *material);

/* Appends a sphere and returns its index, or -1 when memory runs out. */
int scene_add_sphere(scene *s, const scene_sphere *sphere);

/* Returns the index of the material called name, or -1. */
int scene_find_material(const scene *s, const char *name);

#endif
