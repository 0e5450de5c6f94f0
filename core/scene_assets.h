/* scene_assets.h: loading the files a parsed scene names: OBJ and PLY meshes (obj_load.h,
 * ply_load.h) and images (image_io.h), into the scene's own arrays. (A glTF model's meshes
 * come filled by the parser's gltf statement, its images with their bytes: scene_gltf.h.)
 *
 * The parser records each mesh and image with its resolved path and the "file:line:column"
 * of the first statement naming it, and leaves the arrays empty; scene_load_assets() fills
 * them. Everything here is plain C and calls no GL.
 *
 * Meshes (scene_mesh), by the file's extension: ".ply" (any case) is read by ply_load():
 * positions, normals, uvs and colours as it returns them, the colours decoded from sRGB
 * to linear (image_srgb_decode), every triangle's material the mesh's default_material.
 * Any other name is an OBJ file: positions, normals (or NULL), uvs (or NULL), indices,
 * vertex and triangle counts as obj_load() returns them, and triangle_materials, one
 * scene material index per triangle (or -1: the instance's material applies):
 *   - a triangle without `usemtl` gets the mesh's default_material (which may be -1);
 *   - a `usemtl NAME` where NAME is one of the scene's own materials (those it had before
 *     this call) uses that material: the scene wins over the MTL file;
 *   - otherwise an MTL material of that name becomes a scene material, added once per
 *     (mesh, name) and called "<mesh file name>:<NAME>" (cut to SCENE_NAME_MAX - 1 bytes):
 *       emissive    when Ke has a component > 0: emission = Ke (negatives as 0)
 *       dielectric  else when dissolve d < 1 (a file with only Tr has d = 1 - Tr):
 *                   index of refraction Ni, or 1.5 when Ni is missing, 1 or not positive
 *                   (tinyobjloader reports a missing Ni as 1, and exporters write "Ni 1"
 *                   for opaque materials)
 *       metal       else when Ks is bright (largest component > 0.5) and Kd dark (largest
 *                   component <= 0.1): albedo Ks, fuzz sqrt(2 / (Ns + 2)) (Phong exponent
 *                   to roughness: Ns 1000 gives 0.04, Ns 0 gives 1)
 *       lambertian  else: albedo Kd
 *     Colours are clamped to [0, 1] (emission only to >= 0);
 *   - a `usemtl` name that neither the scene nor a (readable) MTL file defines gets the
 *     default_material, like a triangle without `usemtl`.
 *
 * Images (scene_image): width, height and pixels as RGBA 32-bit floats in linear light,
 * rows top to bottom; an image with encoded bytes (a glTF model's) is decoded from them
 * (image_read_memory) and the bytes freed, the others read from their path. Colour is decoded to linear by the file's colour space
 * (image_read_linear(): sRGB for PNG and JPEG, so 8-bit 128 becomes about 0.2158);
 * alpha is kept as stored. Channels: R, G, B and A by name when the file has R, G and B;
 * otherwise by count: 1 is grey (copied to R, G and B), 2 grey and alpha, 3 RGB, 4 or
 * more RGBA from the first four. A missing alpha is 1.
 *
 * Sky box (sky.type SKY_BOX): after loading, the six faces must be square and all the
 * size of the +X face. Every message about a face's image names the face (+X, -X, +Y, -Y,
 * +Z, -Z), also when the file cannot be read.
 *
 * Volumes: a mesh of fewer than 4 triangles placed as a volume's boundary cannot be closed
 * and is an error (the parser checks the flat shapes the same way); larger meshes are
 * not checked for being closed.
 *
 * Warnings: what obj_load() warns about (a missing or unreadable MTL file, tinyobjloader's
 * warnings) is added to s->warnings (scene.h), one entry per warning, as
 * "FILE:LINE:COLUMN: mesh 'PATH': WARNING" (the position of the statement naming the mesh;
 * past OBJ_MAX_WARNINGS of a mesh, one more entry says how many were left out). Nothing
 * is printed: the caller shows them.
 *
 * Errors: RT_ERROR_INPUT, prefixed with the position of the statement that named the
 * file, e.g. "scenes/x.txt:12:6: cannot read mesh 'scenes/y.obj': No such file or
 * directory", "...: cannot read image 'scenes/t.png': it is 20000x100 pixels, more than
 * 16384 on a side", "...: sky box: the +Y face 'scenes/py.png' is 256x256, the +X face is
 * 512x512", "...: sky box: cannot read the -Z face image 'scenes/nz.png': No such file or
 * directory". Mesh reasons are obj_load()'s or ply_load()'s (with "line N: " for a line of
 * the OBJ file or a PLY header).
 * An image with a NaN or infinite pixel is refused. Out of memory: RT_ERROR_RUNTIME.
 *
 * On failure the scene keeps what was loaded before the error (and the materials added
 * for it); scene_free() releases everything either way. Meshes whose positions and images
 * whose pixels are already set are skipped, so a second call loads only what is missing.
 */
#ifndef RT_SCENE_ASSETS_H
#define RT_SCENE_ASSETS_H

#include "scene.h"
#include "status.h"

/* The largest image side accepted: what every OpenGL 4.5 GPU's textures hold. */
#define SCENE_IMAGE_MAX_SIDE 16384

/* Loads every mesh and image the scene names into its arrays (see above). */
rt_status scene_load_assets(scene *s, rt_error *error);

#endif
