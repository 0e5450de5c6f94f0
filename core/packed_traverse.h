/* packed_traverse.h: the packed scene read back on the CPU (plain C, no GPU): its records
 * decoded, and the shader's traversal (nearest hit, the volumes around a point) walked in
 * C over the same texels. For tests, CPU tools and the camera-in-medium lookup
 * (render.c); the packer (pack.h) writes what this reads, by packed_layout.h.
 *
 * Every function takes a packed_scene that pack_scene() filled and reads only its texels
 * and offsets; indices must be in range (nothing is checked).
 */
#ifndef RT_PACKED_TRAVERSE_H
#define RT_PACKED_TRAVERSE_H

#include <stdbool.h>
#include <stdint.h>

#include "pack.h"

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

/* Decodes a normal of the vertex section (pack.h: packed_encode_normal) to a unit vector,
 * as the shader does. */
void packed_decode_normal(uint32_t bits, float normal[3]);

/* Nearest hit of a world-space ray (any direction length) at the given time (for moving
 * spheres), walking the packed BVHs exactly as the shader does (nearer child first, into
 * instances). Returns true and fills *hit when something is hit with t in (0, t_max).
 * Boundaries of volume instances count as hits, as in the shader (which enters or leaves
 * the medium there). */
bool packed_intersect_nearest(const packed_scene *packed, const float origin[3], const float direction[3],
                              float time, float t_max, packed_hit *hit);

/* The shader's shadow ray (glsl/traverse.glsl trace_rays) from origin along direction
 * (any length) at the given time, walked as the shader walks it: true (blocked) when it
 * met, with t in (0, t_max), something other than the world primitive light_slot
 * (PACKED_NONE: none is the light) and, when volumes, the boundaries of volume instances;
 * it stops at the first such blocker it meets, in the walk's order, not the nearest.
 * Otherwise false, and *hit is the nearest of what it passed (t = t_max and primitive
 * PACKED_NONE when nothing). Hits beyond a passable one already met are not looked for,
 * so the shader steps through volume boundaries one at a time (glsl/media.glsl). */
bool packed_shadow_blocked(const packed_scene *packed, const float origin[3], const float direction[3], float time,
                           float t_max, uint32_t light_slot, bool volumes, packed_hit *hit);

/* The threaded walk (packed_layout.h "threaded walk") of glsl/traverse.glsl
 * trace_threaded for one world ray, step for step: the list of the direction's octant,
 * item by item. Nearest hit (shadow false): fills *hit (t = t_max and primitive PACKED_NONE
 * when nothing) and returns false. Shadow ray (shadow true): returns true at the first
 * sphere or quad met, in the list's order, nearer than the nearest so far and other than
 * light_slot (blocked); else false, with *hit the nearest light_slot hit or none.
 * items_visited (NULL: not wanted) gets the number of items the walk tested. With no
 * threaded walk in the scene (threaded_items 0), nothing is hit. */
bool packed_threaded_walk(const packed_scene *packed, const float origin[3], const float direction[3], float t_max,
                          bool shadow, uint32_t light_slot, packed_hit *hit, uint32_t *items_visited);

/* Texels an item of the threaded walk takes in packed (packed_layout.h): 3 when the scene
 * has quads, else 2. */
uint32_t packed_threaded_stride(const packed_scene *packed);

/* The volumes containing point, packed as the shader keeps a path's media: the volume
 * instance number + 1 of the innermost in the low 16 bits, of the next one out in the high
 * 16 bits; 0 when the point is in no volume. Found by walking a ray from the point and
 * noting which volume boundaries it leaves (closed boundaries assumed). */
uint32_t packed_media_at(const packed_scene *packed, const float point[3]);

#endif
