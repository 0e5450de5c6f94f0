/* scene_gltf.h: a glTF model (gltf_load.h) in the scene: its materials, textures, images
 * and meshes added to a scene, and a glTF file rendered by itself as a whole scene.
 *
 * scene_gltf_add() moves a loaded model's contents into a scene and says where each of
 * its placements goes; the caller places them (the parser's `gltf` statement through the
 * builder, with the blocks around it; scene_gltf_load_file() at the top level):
 *   - each glTF material becomes a pbr material (scene.h) named "FILE:NAME" (FILE the
 *     file's name, NAME the material's, or "materials[I]" when it has none; cut to
 *     SCENE_NAME_MAX - 1 bytes): base colour and alpha from baseColorFactor, its texture
 *     as an image texture (the pbr material multiplies the two, as glTF does), metallic,
 *     roughness and their texture, the normal map, emission (emissiveFactor x
 *     KHR_materials_emissive_strength) and its texture, transmission, ior, alpha mode
 *     (BLEND is imported as MASK with its cutoff, 0.5 by default: the renderer has no
 *     blending) and vertex_colors when a mesh with COLOR_0 uses it. glTF emission is
 *     one-sided (one_sided). doubleSided is not used: both faces of every triangle are
 *     surfaces, as a path tracer needs for closed meshes;
 *   - a primitive without a material gets glTF's default material (white, metallic 1,
 *     roughness 1), "FILE:default", added when needed;
 *   - images: one scene image per (glTF image, colour or data, sampler wrap modes) used,
 *     with the file's bytes (decoded by scene_load_assets(): sRGB for base colour and
 *     emission, linear for metallic-roughness and normal maps); path "images[I]" (plus
 *     " (NAME)" when it has a name) only names it in messages, which start with
 *     "POSITION: glTF 'PATH'" (or PATH for a file by itself);
 *   - each mesh with triangles becomes a filled scene mesh (path "FILE: meshes[I]") and
 *     one object, however many nodes place it.
 *
 * scene_gltf_load_file() makes a whole scene of a glTF file: scene_defaults(), then
 *   - camera: the one called camera_name (a camera's or its node's name), else the first
 *     the scene's nodes place; its yfov, and its aspectRatio as the image size (height
 *     360, width rounded); without a camera, one looking down -Z at the centre of the
 *     placed meshes' box from far enough that its bounding sphere fills the 40-degree
 *     field of view, image 640x360. An orthographic camera is refused;
 *   - lights: KHR_lights_punctual as the scene's lights: point and spot at the node's
 *     origin, spot and directional along its -Z; colour x intensity, with glTF's candela
 *     (point, spot) read as rtspheres' intensity per steradian and lux (directional) as
 *     a sun's irradiance, one to one; inverse-square falloff; spot cones from
 *     innerConeAngle / outerConeAngle; the sun a point on the sky (angle 0);
 *   - sky: a constant grey of 0.5, neutral in colour and direction;
 *   - every placement as a top-level instance.
 *
 * Errors: RT_ERROR_INPUT, prefixed with position (scene_gltf_add) or the file's path;
 * out of memory RT_ERROR_RUNTIME. Warnings of the model become the scene's, prefixed with
 * position ("FILE:LINE:COLUMN: glTF 'PATH': WARNING"), or with the path ("PATH: WARNING")
 * for a file rendered by itself. On failure the scene keeps what was added (scene_free frees it).
 */
#ifndef RT_SCENE_GLTF_H
#define RT_SCENE_GLTF_H

#include "gltf_load.h"
#include "scene.h"
#include "status.h"

/* Where one placement of a model goes: the scene object of its mesh, placed by
 * object_to_world (relative to wherever the model itself is placed). */
typedef struct scene_gltf_placement {
    int object;
    gltf_matrix object_to_world;
} scene_gltf_placement;

/* What scene_gltf_add() added. placements is malloc'd: scene_gltf_contents_free(). */
typedef struct scene_gltf_contents {
    int first_material, first_texture, first_mesh;   /* what was added starts here */
    scene_gltf_placement *placements;
    int placement_count;
} scene_gltf_contents;

/* Moves model's meshes and image bytes into s (model keeps its other arrays; free it
 * as usual), adds its materials, textures, images, meshes and objects, and fills *out.
 * path is the model's file (for names), position what messages and warnings start with
 * (the statement's "FILE:LINE:COLUMN"; NULL for a file rendered by itself: then its path).
 * Only running out of memory fails. */
rt_status scene_gltf_add(scene *s, gltf_model *model, const char *path, const char *position,
                         scene_gltf_contents *out, rt_error *error);

/* Frees contents->placements and zeroes *contents. */
void scene_gltf_contents_free(scene_gltf_contents *contents);

/* Makes *out the scene of the glTF file at path (see above); camera_name NULL or "" picks
 * the first camera. On failure *out is freed. Images are left for scene_load_assets(). */
rt_status scene_gltf_load_file(const char *path, const char *camera_name, scene *out, rt_error *error);

/* Whether path names a glTF file by its extension (.gltf or .glb, any case). */
bool scene_gltf_is_model_path(const char *path);

#endif
