/* obj_load.h: reading a Wavefront OBJ file (and its MTL files) into a flat triangle mesh,
 * through tinyobjloader (a thin C shim over C++, like image_io.cpp).
 *
 * tinyobjloader (Debian's 2.0.0rc10) reads the file; obj_load() validates what it returns.
 * So the file means what tinyobjloader reads in it: a number it cannot read ("abc", "nan",
 * "inf") is 0, missing numbers of a v, vn or vt line are 0 and extra ones are ignored, a
 * statement it does not know is skipped; a face index that is 0 or not a number stops it.
 *
 * What comes back:
 *   - one vertex per distinct (position, normal, uv) corner of the file, so that a
 *     position used with two normals (a hard edge) becomes two vertices;
 *   - triangles: tinyobjloader triangulates quads along their shorter diagonal and larger
 *     polygons by ear clipping; faces it cannot triangulate (collinear corners) give fewer
 *     triangles, and faces it drops give none (fewer than 3 corners, or a quad with an
 *     index out of range: it warns);
 *   - per triangle, the material named by the last `usemtl` before it (or -1), as an index
 *     into materials: every material the MTL files define, and every name a `usemtl`
 *     uses that none defines where it is used.
 *
 * Normals: NULL when no face corner of the file names one (the renderer shades flat).
 * When some corners name normals and others do not, the others get their triangle's
 * geometric normal (zero for a degenerate triangle). Normals are made unit length, also
 * near the float range (a zero normal in the file stays zero).
 * UVs: NULL when no corner names one; otherwise corners without one get (0, 0). UVs are
 * as in the file (v upwards, the OBJ convention).
 *
 * MTL files: for each `mtllib` line tinyobjloader asks for its files in turn until one
 * loads; they are looked up relative to the OBJ file's directory (absolute paths as they
 * are), and their materials count from that line on. A missing MTL file is not an error:
 * the mesh loads, the names its `usemtl` lines use are still listed (defined = false),
 * and warnings say which file is missing.
 *
 * Warnings (warnings, warning_count): what does not stop the load but is worth telling:
 * an unreadable MTL file ("cannot read material library 'PATH': REASON; its materials
 * are left out"), and every warning tinyobjloader gives for the OBJ file or an MTL file,
 * one per line as it writes them, as "tinyobjloader: TEXT" (an MTL file's as
 * "tinyobjloader, in 'MTL PATH': TEXT"). Not its "material [ 'NAME' ] not found in .mtl":
 * that name becomes a material (defined = false) instead. Each once, in the order found;
 * obj_load() prints nothing.
 *
 * Errors (RT_ERROR_INPUT, the message "OBJ: cannot read 'PATH': REASON"):
 *   - a missing or unreadable file, a directory (errno's reason, "it is a directory");
 *   - a NUL byte ("line N: a NUL byte (is it a binary file?)": tinyobjloader would
 *     silently drop the rest of its line);
 *   - what tinyobjloader refuses, in its words with its line number ("tinyobjloader:
 *     Failed parse `f' line(e.g. zero value for face index. line 4.)");
 *   - what validating its arrays finds, named by the place in them (tinyobjloader keeps
 *     no line numbers there): "vertex 12 has a coordinate that is not a finite number
 *     (beyond the range of a float)" (likewise "normal", "texture coordinate");
 *     "triangle 7: vertex index 40 is out of range: the file has 30 vertices" (triangles
 *     counted in file order after triangulation; likewise normal and texture coordinate
 *     indices); "triangle 7: a relative vertex index points before the first vertex";
 *     no triangles ("has no faces", followed by tinyobjloader's warnings when it dropped
 *     faces); more than 2^31 - 1 vertices or triangles; a non-finite value in an MTL
 *     colour ("material 'NAME' of 'PATH' has a value that is not a finite number").
 * Out of memory: RT_ERROR_RUNTIME. No C++ exception crosses into C.
 */
#ifndef RT_OBJ_LOAD_H
#define RT_OBJ_LOAD_H

#include <stdbool.h>
#include <stdint.h>

#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OBJ_NAME_MAX 256
#define OBJ_MAX_WARNINGS 8       /* warnings kept per mesh; more are only counted */
#define OBJ_WARNING_MAX 256      /* bytes of one warning, with the NUL */

/* One material: from an MTL file (defined), or only named by a `usemtl` (not defined:
 * no MTL file loaded by then defines it; the colours are then zero and meaningless). */
typedef struct obj_material {
    char name[OBJ_NAME_MAX];     /* as in the file, cut to OBJ_NAME_MAX - 1 bytes */
    bool defined;
    float diffuse[3];            /* Kd */
    float specular[3];           /* Ks */
    float emission[3];           /* Ke */
    float shininess;             /* Ns (tinyobjloader's default when missing: 1) */
    float index_of_refraction;   /* Ni (default when missing: 1, like an explicit "Ni 1") */
    float dissolve;              /* d, or 1 - Tr; 1 is opaque (the default) */
} obj_material;

/* A triangle mesh. Arrays are malloc'd (free() each, or obj_mesh_free()), so a caller
 * may take them over by copying the pointer and setting the field to NULL. */
typedef struct obj_mesh {
    float *positions;            /* 3 per vertex */
    float *normals;              /* 3 per vertex, or NULL */
    float *uvs;                  /* 2 per vertex, or NULL */
    uint32_t *indices;           /* 3 per triangle, counter-clockwise as in the file */
    int *triangle_materials;     /* per triangle: index into materials, or -1 (no usemtl) */
    int vertex_count, triangle_count;   /* both >= 1 after a successful load */
    obj_material *materials;     /* NULL when material_count is 0 */
    int material_count;
    int warning_count;           /* warnings found; may exceed OBJ_MAX_WARNINGS */
    char warnings[OBJ_MAX_WARNINGS][OBJ_WARNING_MAX];   /* the first of them (see above) */
} obj_mesh;

/* Reads the OBJ file at path into *out (zeroed first; on failure left zeroed). */
rt_status obj_load(const char *path, obj_mesh *out, rt_error *error);

/* Frees the arrays of *mesh (not mesh itself) and zeroes it. NULL is allowed. */
void obj_mesh_free(obj_mesh *mesh);

#ifdef __cplusplus
}
#endif

#endif
