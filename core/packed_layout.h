/* packed_layout.h: the one definition of the packed scene records, shared by C and GLSL.
 *
 * This file is included by the C packer (core/pack.c) and prepended, byte for byte, to the
 * GLSL tracer when the shader is built (see core/shader_sources.S). It must therefore stay
 * valid in both languages: only comments, include guards and #define of plain integers.
 *
 * The packed scene is an array of texels of four 32-bit unsigned integers (GL_RGBA32UI).
 * Integers (type tags, indices, counts) are stored as they are; floats are stored as their
 * bit pattern (C: memcpy; GLSL: uintBitsToFloat). No index is ever a float, so there is no
 * precision limit at 2^24 as the seed report's At() had.
 *
 * Texel i lives at (i mod width, i div width) of a square-ish 2D texture whose width is a
 * power of two chosen at upload time (uniform `packed_width_log2` in the shader).
 *
 * Sections, in this order, each starting at the texel offset written in the header:
 *   header     PACKED_HEADER_TEXELS texels at texel 0
 *   materials  material_count records of PACKED_MATERIAL_STRIDE texels
 *   primitives primitive_count records of PACKED_PRIMITIVE_STRIDE texels, in BVH leaf order
 *   nodes      node_count BVH nodes of PACKED_NODE_STRIDE texels; root is node 0; the two
 *              children of an interior node are contiguous (left = first, right = first + 1)
 */
#ifndef RT_PACKED_LAYOUT_H
#define RT_PACKED_LAYOUT_H

/* Bumped whenever a record below changes meaning. */
#define PACKED_LAYOUT_VERSION 1

/* ---- header: texel 0 = (magic, version, material_offset, material_count)
 *              texel 1 = (primitive_offset, primitive_count, node_offset, node_count) */
#define PACKED_MAGIC 1381258067
#define PACKED_HEADER_TEXELS 2
#define PACKED_HEADER_MAGIC 0
#define PACKED_HEADER_VERSION 1
#define PACKED_HEADER_MATERIAL_OFFSET 2
#define PACKED_HEADER_MATERIAL_COUNT 3
#define PACKED_HEADER_PRIMITIVE_OFFSET 4
#define PACKED_HEADER_PRIMITIVE_COUNT 5
#define PACKED_HEADER_NODE_OFFSET 6
#define PACKED_HEADER_NODE_COUNT 7

/* ---- materials: 4 texels
 *   texel 0 = (type tag, albedo.r, albedo.g, albedo.b)
 *   texel 1 = (emission.r, emission.g, emission.b, fuzz)        emission is colour x strength
 *   texel 2 = (index of refraction, reserved, reserved, reserved)
 *   texel 3 = reserved (textures, Phong exponent: issue 3 and 4) */
#define PACKED_MATERIAL_STRIDE 4
#define MATERIAL_LAMBERTIAN 0
#define MATERIAL_METAL 1
#define MATERIAL_DIELECTRIC 2
#define MATERIAL_EMISSIVE 3
#define MATERIAL_TYPE_COUNT 4

/* ---- primitives: 3 texels
 *   texel 0 = (type tag, material index, reserved, reserved)
 *   texel 1 = sphere: (center.x, center.y, center.z, radius)
 *   texel 2 = reserved (moving sphere: centre at shutter close; instance: transform offset) */
#define PACKED_PRIMITIVE_STRIDE 3
#define PRIMITIVE_SPHERE 0
#define PRIMITIVE_TYPE_COUNT 1

/* ---- BVH nodes: 2 texels
 *   texel 0 = (box_min.x, box_min.y, box_min.z, first)
 *   texel 1 = (box_max.x, box_max.y, box_max.z, count)
 * count == 0: interior node, children are nodes first and first + 1.
 * count  > 0: leaf, primitives first .. first + count - 1 of the primitive section. */
#define PACKED_NODE_STRIDE 2

/* Deepest BVH the shader's traversal stack holds (the builder never exceeds it). */
#define BVH_MAX_DEPTH 48

#endif
