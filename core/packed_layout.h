/* packed_layout.h: the one definition of the packed scene records, shared by C and GLSL.
 *
 * This file is included by the C packer (core/pack.c) and prepended, byte for byte, to the
 * GLSL tracer when the shader is built (see core/shader_sources.S). It must therefore stay
 * valid in both languages: only comments, include guards and #define of plain integers.
 *
 * The packed scene is an array of texels of four 32-bit unsigned integers (GL_RGBA32UI).
 * Integers (type tags, indices, counts) are stored as they are; floats are stored as their
 * bit pattern (C: memcpy; GLSL: uintBitsToFloat). No index is ever a float, so there is no
 * precision limit at 2^24 as the seed report's At() had. PACKED_NONE marks "no index".
 *
 * The array is uploaded as one buffer texture (GL_TEXTURE_BUFFER, GL_RGBA32UI; a
 * usamplerBuffer in the shader): texel i is texelFetch(packed_scene, i), and the scene's
 * size is bounded by GL_MAX_TEXTURE_BUFFER_SIZE texels.
 *
 * Geometry is two-level, as in hardware ray tracing APIs: one node array holds the top-level
 * BVH (root: node 0) over world primitives and instances, and one bottom-level BVH per
 * object (mesh or group), whose root an instance names. Primitives of all levels share one
 * array; a top-level leaf may hold PRIMITIVE_INSTANCE records, which send the ray, moved
 * into the object's coordinates, into that object's BVH.
 *
 * Sections (offsets and counts in the header):
 *   header      PACKED_HEADER_TEXELS texels at texel 0
 *   materials   PACKED_MATERIAL_STRIDE texels each
 *   primitives  PACKED_PRIMITIVE_STRIDE texels each, in BVH leaf order per BVH
 *   attributes  PACKED_ATTRIBUTE_STRIDE texels each: per-triangle vertex normals and uvs
 *   nodes       PACKED_NODE_STRIDE texels each; the two children of an interior node are
 *               contiguous (left = first, right = first + 1)
 *   instances   PACKED_INSTANCE_STRIDE texels each
 *   textures    PACKED_TEXTURE_STRIDE texels each
 *   images      PACKED_IMAGE_STRIDE texels each (a record), pixels elsewhere in the section
 *   lights      PACKED_LIGHT_STRIDE texels each, for light sampling
 *   environment the environment map's sampling distribution (see lights)
 */
#ifndef RT_PACKED_LAYOUT_H
#define RT_PACKED_LAYOUT_H

/* Bumped whenever a record below changes meaning. */
#define PACKED_LAYOUT_VERSION 2
#define PACKED_NONE 4294967295u

/* ---- header (4 texels), field i is component i % 4 of texel i / 4 */
#define PACKED_MAGIC 1381258067
#define PACKED_HEADER_TEXELS 5
#define PACKED_HEADER_MAGIC 0
#define PACKED_HEADER_VERSION 1
#define PACKED_HEADER_MATERIAL_OFFSET 2
#define PACKED_HEADER_MATERIAL_COUNT 3
#define PACKED_HEADER_PRIMITIVE_OFFSET 4
#define PACKED_HEADER_PRIMITIVE_COUNT 5
#define PACKED_HEADER_NODE_OFFSET 6
#define PACKED_HEADER_NODE_COUNT 7
#define PACKED_HEADER_INSTANCE_OFFSET 8
#define PACKED_HEADER_INSTANCE_COUNT 9
#define PACKED_HEADER_ATTRIBUTE_OFFSET 10
#define PACKED_HEADER_DEFAULT_MATERIAL 11
#define PACKED_HEADER_TEXTURE_OFFSET 12
#define PACKED_HEADER_TEXTURE_COUNT 13
#define PACKED_HEADER_IMAGE_OFFSET 14
#define PACKED_HEADER_IMAGE_COUNT 15
#define PACKED_HEADER_LIGHT_OFFSET 16
#define PACKED_HEADER_LIGHT_COUNT 17
#define PACKED_HEADER_ENVIRONMENT_OFFSET 18

/* ---- materials: 4 texels
 *   texel 0 = (type tag, albedo.r, albedo.g, albedo.b)
 *   texel 1 = (emission.r, emission.g, emission.b, fuzz)        emission is colour x strength
 *   texel 2 = (index of refraction, albedo texture, emission texture, normal map image)
 *             (texture and image indices, or PACKED_NONE)
 *   texel 3 = (Phong exponent, Phong specular colour.rgb)      Whitted integrator only */
#define PACKED_MATERIAL_STRIDE 4
#define MATERIAL_LAMBERTIAN 0
#define MATERIAL_METAL 1
#define MATERIAL_DIELECTRIC 2
#define MATERIAL_EMISSIVE 3
#define MATERIAL_TYPE_COUNT 4

/* ---- primitives: 4 texels
 *   texel 0 = (type tag, material index or PACKED_NONE (the instance's), attribute record
 *              index or PACKED_NONE, instance index for PRIMITIVE_INSTANCE, else the light
 *              index of an emissive world primitive or PACKED_NONE)
 *   sphere:         texel 1 = (centre.xyz, radius)
 *   moving sphere:  texel 1 = (centre at time 0 .xyz, radius), texel 2 = (centre at time 1 .xyz, 0)
 *   triangle:       texel 1 = (v0.xyz, 0), texel 2 = (v1 - v0 .xyz, 0), texel 3 = (v2 - v0 .xyz, 0)
 *   quad:           texel 1 = (corner Q.xyz, 0), texel 2 = (edge u.xyz, 0), texel 3 = (edge v.xyz, 0)
 *   instance:       (only in top-level leaves) texel 0 .w = instance index */
#define PACKED_PRIMITIVE_STRIDE 4
#define PRIMITIVE_SPHERE 0
#define PRIMITIVE_MOVING_SPHERE 1
#define PRIMITIVE_TRIANGLE 2
#define PRIMITIVE_QUAD 3
#define PRIMITIVE_INSTANCE 4
#define PRIMITIVE_TYPE_COUNT 5

/* ---- triangle attributes: 4 texels (meshes with normals or uvs)
 *   texel 0 = (n0.xyz, uv0.x)  texel 1 = (n1.xyz, uv0.y)  texel 2 = (n2.xyz, uv1.x)
 *   texel 3 = (uv1.y, uv2.x, uv2.y, flags: ATTRIBUTE_HAS_NORMALS | ATTRIBUTE_HAS_UVS) */
#define PACKED_ATTRIBUTE_STRIDE 4
#define ATTRIBUTE_HAS_NORMALS 1
#define ATTRIBUTE_HAS_UVS 2

/* ---- BVH nodes: 2 texels
 *   texel 0 = (box_min.x, box_min.y, box_min.z, first)
 *   texel 1 = (box_max.x, box_max.y, box_max.z, count)
 * count == 0: interior node, children are nodes first and first + 1.
 * count  > 0: leaf, primitives first .. first + count - 1 of the primitive section. */
#define PACKED_NODE_STRIDE 2

/* ---- instances: 5 texels
 *   texel 0 = (root node of the object's BVH, material override or PACKED_NONE, flags, 0)
 *   texels 1-3 = rows of the 3x4 world-to-object matrix (object = M * (world, 1))
 *   texel 4 = (volume density, volume albedo.rgb) */
#define PACKED_INSTANCE_STRIDE 5
#define INSTANCE_VOLUME 1

/* ---- textures: 2 texels
 *   texel 0 = (type tag, a, b, image)    checker: a, b = the two textures; image: image index
 *   texel 1 = (colour.rgb, scale)        constant: colour; checker/noise: scale */
#define PACKED_TEXTURE_STRIDE 2
#define TEXTURE_CONSTANT 0
#define TEXTURE_CHECKER 1
#define TEXTURE_NOISE 2
#define TEXTURE_TURBULENCE 3
#define TEXTURE_MARBLE 4
#define TEXTURE_IMAGE 5
#define TEXTURE_TYPE_COUNT 6

/* ---- images: 1 texel record = (first pixel texel, width, height, 0); pixels are RGBA
 * float bits, one texel each, rows top to bottom, after all the records */
#define PACKED_IMAGE_STRIDE 1

/* ---- lights: 4 texels (what next-event estimation samples, chosen by power)
 *   texel 0 = (type tag, primitive slot (area lights), 0, 0) -- see below for the others
 *   texel 1 = (position.xyz (point, spot) or direction towards the light (sun), cdf)
 *             cdf: the probability of choosing this light or any before it
 *   texel 2 = (intensity colour.rgb (point, spot: per steradian; sun: irradiance), 0)
 *   texel 3 = (spot direction.xyz, cos of the spot's inner half-angle)
 *   point, spot, sun: texel 0 .yzw = polynomial attenuation c, l, q (all 0: inverse square),
 *   texel 1 .xyz = position (point, spot) or the direction towards the sun, texel 2 .w = cos
 *   of the spot's outer half-angle or of the sun's angular radius.
 * Area lights are emissive world primitives (spheres, quads, triangles): their radiance is
 * their material's emission.
 * environment (an equirectangular sky): texel 0 = (LIGHT_ENVIRONMENT, image width, image
 * height, 0); it is importance-sampled by the environment section: one float per texel
 * (in .x): the cumulative distribution over rows (height values), then for each row the
 * cumulative distribution over its pixels (width values), of luminance x sin(latitude). */
#define PACKED_LIGHT_STRIDE 4
#define LIGHT_SPHERE 0
#define LIGHT_QUAD 1
#define LIGHT_TRIANGLE 2
#define LIGHT_POINT 3
#define LIGHT_SPOT 4
#define LIGHT_SUN 5
#define LIGHT_ENVIRONMENT 6
#define LIGHT_TYPE_COUNT 7

/* Deepest BVH per level (the builder never exceeds it; deeper nodes become leaves). The
 * shader's stack holds a top-level path, one leaf's instances and a bottom-level path:
 * 2 * BVH_MAX_DEPTH + 2 * BVH_MAX_LEAF_SIZE entries, so it can never overflow. Small on
 * purpose: llvmpipe keeps the stack in memory and a larger one costs ~20% speed. */
#define BVH_MAX_DEPTH 24
#define BVH_MAX_LEAF_SIZE 4

#endif
