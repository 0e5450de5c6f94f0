/* ply_load.h: reading a PLY file (the Stanford polygon format of scanned meshes) into a flat
 * triangle mesh. A small strict reader of its own: Debian 12 packages no PLY library
 * lighter than assimp.
 *
 * What it reads:
 *   - the header: "ply", then "format ascii 1.0", "format binary_little_endian 1.0" or
 *     "format binary_big_endian 1.0", "comment" and "obj_info" lines (ignored), "element
 *     NAME COUNT", "property TYPE NAME" and "property list COUNT_TYPE ITEM_TYPE NAME", and
 *     "end_header". Types: char uchar short ushort int uint float double and their
 *     int8 uint8 int16 uint16 int32 uint32 float32 float64 spellings. Lines end with "\n"
 *     or "\r\n";
 *   - element "vertex": x y z (required), nx ny nz (all three or none), a texture
 *     coordinate as s t, u v, texture_u texture_v or texture_s texture_t (a pair or none),
 *     red green blue (all three or none); any numeric type for each;
 *   - element "face": its list "vertex_indices" (or "vertex_index") of any integer types:
 *     polygons of 3 or more corners, fan-triangulated from the first corner in file order
 *     (corner 0, k, k + 1), so a convex polygon keeps its winding;
 *   - every other element and property is skipped by its declared type (lists too);
 *     elements may come in any order.
 * ASCII data is a stream of numbers separated by white space (line ends are not checked);
 * binary data is packed values of the declared types in the declared byte order.
 *
 * What comes back (ply_mesh): the vertices as the file has them (no welding, none
 * dropped), positions as floats; normals made unit length (a zero normal stays zero), or
 * NULL; uvs as in the file (v upwards, as OBJ and the renderer use them), or NULL; colours
 * in [0, 1] as the file encodes them, or NULL: an integer type is divided by its largest
 * value (uchar 255), a float taken as it is, both clamped to [0, 1] (the asset loader
 * decodes them from sRGB: scene_assets.h); indices, 3 per triangle.
 *
 * Errors (RT_ERROR_INPUT, the message "PLY: cannot read 'PATH': REASON"):
 *   - a missing or unreadable file, a directory (errno's reason, "it is a directory");
 *   - a header it does not know, named by its line: "line 1: not a PLY file (it does not
 *     start with a 'ply' line)", "line 2: unknown format 'X' (expected ascii,
 *     binary_little_endian or binary_big_endian)", "line 5: unknown type 'float16' of
 *     property 'x'", "line 4: a property before any element", "the header has no
 *     end_header line", the same element twice, a count that is not a whole number from 0
 *     to 2^31 - 1;
 *   - a vertex element without x, y or z, with only some of nx ny nz, red green blue or a
 *     texture coordinate pair, a property of those names that is a list, a face element
 *     without a vertex_indices list, or with an index list of a float type; no vertex or
 *     face element, or no faces;
 *   - data that does not match the header, named by the element: "the data ends inside
 *     vertex 17 (the header declares 100 vertices)", "line 9: expected a number for
 *     property 'y' of vertex 5, found 'abc'", "line 9: the value 300 of 'vertex_indices'
 *     of face 2 does not fit its type uchar" (ASCII values are checked against their
 *     declared types), "face 3 has 2 corners; a face needs at least 3", "face 7: vertex
 *     index 40 is out of range: the file has 30 vertices", "vertex 12: 'x' is not a finite
 *     number (NaN, infinite or beyond the range of a float)", "12 bytes after the last
 *     element" (binary), "line 40: 'junk' after the last element" (ASCII);
 *   - more than 2^31 - 1 triangles.
 * Counts are checked against the size of the file before anything is allocated for
 * them, so a short file declaring a billion vertices fails at once. Out of memory:
 * RT_ERROR_RUNTIME. On failure *out is left zeroed.
 */
#ifndef RT_PLY_LOAD_H
#define RT_PLY_LOAD_H

#include <stddef.h>
#include <stdint.h>

#include "status.h"

/* A triangle mesh. Arrays are malloc'd (free() each, or ply_mesh_free()), so a caller may
 * take them over by copying the pointer and setting the field to NULL. */
typedef struct ply_mesh {
    float *positions;            /* 3 per vertex */
    float *normals;              /* 3 per vertex, or NULL */
    float *uvs;                  /* 2 per vertex, or NULL */
    float *colors;               /* 3 per vertex, in [0, 1] as encoded in the file, or NULL */
    uint32_t *indices;           /* 3 per triangle, in the file's winding */
    int vertex_count, triangle_count;   /* both >= 1 after a successful load */
} ply_mesh;

/* Reads the PLY file at path into *out (zeroed first; on failure left zeroed). */
rt_status ply_load(const char *path, ply_mesh *out, rt_error *error);

/* The same for a file's bytes in memory (the fuzz harness, tests); name is the path that
 * messages show. */
rt_status ply_load_memory(const void *bytes, size_t size, const char *name, ply_mesh *out, rt_error *error);

/* Frees the arrays of *mesh (not mesh itself) and zeroes it. NULL is allowed. */
void ply_mesh_free(ply_mesh *mesh);

#endif
