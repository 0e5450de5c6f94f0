/* packed_layout.h: the one definition of the packed scene records, shared by C and GLSL.
 *
 * This file is included by the C packer (core/pack*.c, through pack_internal.h) and
 * prepended, byte for byte, to the GLSL tracer when the shader is built (see
 * core/shader_sources.S). It must therefore stay
 * valid in both languages: only comments, include guards and #define of plain integers.
 *
 * The packed scene is an array of texels of four 32-bit unsigned integers (GL_RGBA32UI).
 * Integers (type tags, indices, counts) are stored as they are; floats are stored as their
 * bit pattern (C: memcpy; GLSL: uintBitsToFloat). No index is ever a float, so there is no
 * precision limit at 2^24 as the seed report's At() had. PACKED_NONE marks "no index".
 *
 * The array is uploaded as one buffer texture (GL_TEXTURE_BUFFER, GL_RGBA32UI), which the
 * shader reads as a read-only uimageBuffer: texel i is imageLoad(packed_scene, i), and the
 * scene's size is bounded by GL_MAX_TEXTURE_BUFFER_SIZE texels.
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
 *   primitives  one texel each, in BVH leaf order per BVH: what a ray test reads first
 *   info        one uint per primitive, four to a texel: type tag and material
 *   shapes      the further texels of moving spheres and quads
 *   vertices    one texel per triangle vertex: position and normal
 *   uvs         (u, v) per vertex, two vertices to a texel
 *   colours     vertex colours, two vertices to a texel (only when a material uses them)
 *   nodes       PACKED_NODE_STRIDE texels each; the two children of an interior node are
 *               contiguous (left = first, right = first + 1)
 *   threaded    the BVH again as PACKED_THREADED_ORDERS lists of items, one per ray octant
 *               (only for scenes of still spheres and quads in one level; see there)
 *   instances   PACKED_INSTANCE_STRIDE texels each
 *   textures    PACKED_TEXTURE_STRIDE texels each
 *   images      PACKED_IMAGE_STRIDE texels each (a record), pixels elsewhere in the section
 *   lights      PACKED_LIGHT_STRIDE texels each, for light sampling
 *   environment the environment map's sampling distribution (see lights)
 *   light tree  PACKED_LIGHT_TREE_NODE_STRIDE texels a node, with more than
 *               LIGHT_LOCAL_CHOICE_MAX lights (core/tracer_interface.h; see lights)
 */
#ifndef RT_PACKED_LAYOUT_H
#define RT_PACKED_LAYOUT_H

/* Bumped whenever a record below changes meaning. */
#define PACKED_LAYOUT_VERSION 9
#define PACKED_NONE 4294967295u

/* ---- header (7 texels), field i is component i % 4 of texel i / 4 */
#define PACKED_MAGIC 1381258067
#define PACKED_HEADER_TEXELS 7
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
#define PACKED_HEADER_INFO_OFFSET 10
#define PACKED_HEADER_DEFAULT_MATERIAL 11
#define PACKED_HEADER_TEXTURE_OFFSET 12
#define PACKED_HEADER_TEXTURE_COUNT 13
#define PACKED_HEADER_IMAGE_OFFSET 14
#define PACKED_HEADER_IMAGE_COUNT 15
#define PACKED_HEADER_LIGHT_OFFSET 16
#define PACKED_HEADER_LIGHT_COUNT 17
#define PACKED_HEADER_ENVIRONMENT_OFFSET 18
#define PACKED_HEADER_AREA_LIGHT_COUNT 19
#define PACKED_HEADER_SHAPE_OFFSET 20
#define PACKED_HEADER_VERTEX_OFFSET 21
#define PACKED_HEADER_UV_OFFSET 22
#define PACKED_HEADER_VERTEX_COUNT 23
#define PACKED_HEADER_COLOR_OFFSET 24    /* PACKED_NONE: no vertex colour section */
#define PACKED_HEADER_LIGHT_TREE_OFFSET 25   /* PACKED_NONE: no light tree */
#define PACKED_HEADER_THREADED_OFFSET 26     /* the threaded walk (see there); 0 items: none */
#define PACKED_HEADER_THREADED_ITEMS 27

/* ---- materials: 6 texels
 *   texel 0 = (type tag | flags, albedo.r, albedo.g, albedo.b)    albedo: pbr's base colour
 *   texel 1 = (emission.r, emission.g, emission.b, fuzz)        emission is colour x strength
 *   texel 2 = (index of refraction, albedo texture, emission texture, normal map image)
 *             (texture and image indices, or PACKED_NONE)
 *   texel 3 = (Phong exponent, Phong specular colour.rgb)      Whitted integrator only
 *   emitters (emissive, pbr): texel 1 .w = the light group (scene.h light_groups; fuzz is
 *   metal's)
 *   texel 4 = (metallic, roughness, transmission, metallic-roughness image)        pbr only
 *   texel 5 = (alpha, alpha cutoff, alpha image, 0)                                pbr only
 * The type word is the MATERIAL_* tag in its low MATERIAL_TYPE_BITS bits and MATERIAL_FLAG_*
 * bits above them. pbr: roughness is perceptual (GGX alpha = roughness^2); the
 * metallic-roughness image (PACKED_NONE: none) multiplies roughness by its G channel and
 * metallic by its B channel (glTF's packing); with MATERIAL_FLAG_ALPHA_MASK, a hit where
 * alpha x the alpha image's A channel (the albedo texture's image; PACKED_NONE: 1) is below
 * the cutoff is no hit at all. */
#define PACKED_MATERIAL_STRIDE 6
#define MATERIAL_LAMBERTIAN 0
#define MATERIAL_METAL 1
#define MATERIAL_DIELECTRIC 2
#define MATERIAL_EMISSIVE 3
#define MATERIAL_PBR 4               /* glTF metallic-roughness (scene.h scene_material "pbr") */
#define MATERIAL_TYPE_COUNT 5
#define MATERIAL_TYPE_BITS 8
#define MATERIAL_TYPE_MASK 255
#define MATERIAL_FLAG_ONE_SIDED 256       /* emits only from its front face (emissive, pbr) */
#define MATERIAL_FLAG_VERTEX_COLORS 512   /* pbr: base colour x the vertex colours */
#define MATERIAL_FLAG_ALPHA_MASK 1024     /* pbr: alpha-tested (texel 5) */

/* ---- primitives: one texel each (a leaf's primitives are contiguous)
 *   sphere:         (centre.xyz, radius)
 *   moving sphere:  (first texel of its shape record, 0, 0, tag); the record is 2 texels:
 *                   (centre at time 0 .xyz, radius), (centre at time 1 .xyz, 0)
 *   triangle:       (vertex 0, vertex 1, vertex 2, tag): indices into the vertex section
 *   quad:           (first texel of its shape record, 0, 0, tag); the record is 3 texels:
 *                   (corner Q.xyz, 0), (edge u.xyz, 0), (edge v.xyz, 0). Shape records
 *                   follow one another in slot order from the shape section's start, so
 *                   in a scene of quads alone (one BVH level) quad k's is at
 *                   shape_offset + 3k: the tracer's quad-only variant reads it from there
 *                   without the record (glsl/traverse.glsl leaf_record)
 *   instance:       (instance index, 0, 0, tag)   (only in top-level leaves)
 * tag = PRIMITIVE_RECORD_TAG + type tag: no sphere's w (a positive float's bits, below
 * 2139095040) is that large, so a ray test reads the type from the record itself.
 * The emissive world primitives are the first PACKED_HEADER_AREA_LIGHT_COUNT lights, in
 * primitive order: a primitive's light is found by a binary search over them. */
#define PACKED_PRIMITIVE_STRIDE 1
#define PRIMITIVE_SPHERE 0
#define PRIMITIVE_MOVING_SPHERE 1
#define PRIMITIVE_TRIANGLE 2
#define PRIMITIVE_QUAD 3
#define PRIMITIVE_INSTANCE 4
#define PRIMITIVE_TYPE_COUNT 5
#define PRIMITIVE_RECORD_TAG 4294967280u
#define PACKED_MOVING_SPHERE_TEXELS 2
#define PACKED_QUAD_TEXELS 3

/* ---- primitive info: one uint per primitive; primitive i's is component i % 4 of info
 * texel i / 4:
 *   type tag << PRIMITIVE_INFO_TYPE_SHIFT | PRIMITIVE_INFO_HAS_UVS (triangles whose
 *   vertices carry uvs; otherwise uv is the barycentric or edge coordinates) | material
 *   index (PRIMITIVE_NO_MATERIAL: the instance's, else the default) */
#define PRIMITIVE_INFO_TYPE_SHIFT 29
#define PRIMITIVE_INFO_HAS_UVS 268435456
#define PRIMITIVE_INFO_MATERIAL_MASK 268435455
#define PRIMITIVE_NO_MATERIAL 268435455

/* ---- vertices: one texel each: (position.xyz, normal), the normal a unit vector
 * octahedron-mapped to two signed 16-bit fractions (GLSL unpackSnorm2x16: x low half), or
 * VERTEX_NO_NORMAL (flat shading). Mesh vertices are stored once per mesh however often it
 * is placed (and once more per placement baked into the world).
 * ---- uvs: vertex i's (u, v) are components 2 (i % 2) and 2 (i % 2) + 1 of uv texel
 * i / 2; v points up (v = 1: an image's top row).
 * ---- colours: vertex i's linear (r, g) and (b, 1) as pairs of unsigned 16-bit fractions
 * (GLSL unpackUnorm2x16: first value low) are components 2 (i % 2) and 2 (i % 2) + 1 of
 * colour texel i / 2; white for vertices whose mesh has no colours. The section exists
 * only when a material with MATERIAL_FLAG_VERTEX_COLORS is used by a mesh with colours. */
#define VERTEX_NO_NORMAL 4294967295u

/* ---- BVH nodes: 2 texels
 *   texel 0 = (box_min.x, box_min.y, box_min.z, first)
 *   texel 1 = (box_max.x, box_max.y, box_max.z, count)
 * count == 0: interior node, children are nodes first and first + 1.
 * count  > 0: leaf, primitives first .. first + count - 1 of the primitive section.
 * first is below 2^PACKED_FIRST_BITS (the packer refuses larger scenes): the shader's
 * traversal stack keeps first and count in one word (glsl/traverse.glsl). */
#define PACKED_NODE_STRIDE 2
#define PACKED_FIRST_BITS 29

/* ---- threaded walk: PACKED_THREADED_ORDERS lists of PACKED_HEADER_THREADED_ITEMS items,
 * stride texels an item (PACKED_THREADED_QUAD_ITEM_STRIDE when the scene has quads, else
 * PACKED_THREADED_ITEM_STRIDE), list o at threaded_offset + o x items x stride. Written
 * only for a scene of still spheres and quads in one BVH level (no instances, triangles or
 * moving spheres) whose lists take at most PACKED_THREADED_MAX_TEXELS texels; the tracer's
 * variants for such scenes walk it instead of the nodes (glsl/traverse.glsl
 * trace_threaded), unless a material has an alpha mask (the stack's walk tests it). Each
 * list is the top-level BVH in depth-first order, with the children of every interior node
 * in the order a ray of octant o meets them along the axis that separates their centres
 * most, and every leaf replaced by its primitives; the root's own box has no item (nearly
 * every ray starts inside it, and one that misses it misses every box in it). A ray's
 * octant has bit k set when component k of its inverse direction is negative, the inverse
 * taken of a direction whose components have a magnitude of at least
 * TRAVERSAL_SMALLEST_DIRECTION (smaller ones become that with their sign, -0 as +0:
 * glsl/intersect.glsl traversal_ray), so that the box test sees no infinity and no NaN. An
 * item (a third texel only with stride 3; 0 where not named):
 *   interior node: (near.xyz, skip), (far.xyz, 0): the box's corners as a ray of octant o
 *                  meets them: near.k = box_min.k, far.k = box_max.k, swapped where bit k
 *                  is set; so the slab test needs no minimum and maximum per axis
 *   sphere:        (centre.xyz, skip), (radius, 0, 0, THREADED_SPHERE | slot)
 *   quad:          (Q.xyz, skip), (u.xyz, THREADED_QUAD | slot), (v.xyz, 0), as its shape
 *                  record holds them
 * skip is the index of the item after its subtree (a primitive's: the next item), where a
 * walk goes on when the box is missed; a box hit goes on at the next item. The walk ends
 * at index items. slot is the primitive's slot (below 2^PACKED_FIRST_BITS). No stack: a
 * walk is one index (docs/performance.md, the log). */
#define PACKED_THREADED_ORDERS 8
#define PACKED_THREADED_ITEM_STRIDE 2
#define PACKED_THREADED_QUAD_ITEM_STRIDE 3
#define PACKED_THREADED_MAX_TEXELS 4194304   /* 64 MiB */
#define THREADED_SPHERE 2147483648u
#define THREADED_QUAD 1073741824u
#define THREADED_SLOT_MASK 1073741823u
#define TRAVERSAL_SMALLEST_DIRECTION 1e-30

/* ---- instances: 5 texels
 *   texel 0 = (first, material override or PACKED_NONE, flags, count): first and count
 *             are those of the root node of the object's BVH (see nodes), so that entering
 *             the object needs no fetch of its root
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

/* ---- images: 1 texel record = (first pixel texel, width, height, wrap); pixels are RGBA
 * float bits, one texel each, rows top to bottom, after all the records. wrap: how a
 * lookup outside [0, 1] folds, IMAGE_WRAP_* of u in bits 0-1 and of v in bits 2-3 (glTF's
 * samplers; every other image repeats) */
#define PACKED_IMAGE_STRIDE 1
#define IMAGE_WRAP_REPEAT 0
#define IMAGE_WRAP_CLAMP 1
#define IMAGE_WRAP_MIRROR 2
#define IMAGE_WRAP_V_SHIFT 2

/* ---- lights: 5 texels (what next-event estimation samples: see glsl/lights.glsl for how
 * one is chosen: by power, or by its estimated irradiance at the point)
 *   texel 0 = (type tag, primitive slot (area lights), 0, 0) -- see below for the others
 *   texel 1 = (position.xyz (point, spot) or direction towards the light (sun), cdf)
 *             cdf: the probability of choosing this light or any before it
 *   texel 2 = (intensity colour.rgb (point, spot: per steradian; sun: irradiance), 0)
 *   texel 3 = (spot direction.xyz, cos of the spot's inner half-angle)
 *   texel 4 = (light group (scene.h light_groups; the environment: the sky's), trail, 0, 0)
 *             trail: the way to the light's leaf in the light tree (below; 0 when there is
 *             none): bit k is set when the walk from the root takes the second child at
 *             depth k; the walk ends at the leaf
 *   point, spot, sun: texel 0 .yzw = polynomial attenuation c, l, q (all 0: inverse square),
 *   texel 1 .xyz = position (point, spot) or the direction towards the sun, texel 2 .w = cos
 *   of the spot's outer half-angle or of the sun's angular radius.
 * Area lights are emissive world primitives (spheres, quads, triangles), listed first and
 * in primitive order (see primitives): their radiance is their material's emission;
 * texel 1 .xyz = their centre, texel 2 = (unit normal.xyz (spheres: 0), emitted
 * luminance x area), texel 3 .x = their area.
 * environment (an equirectangular sky): texel 0 = (LIGHT_ENVIRONMENT, image width, image
 * height, 0), texel 2 .w = the irradiance it gives (pi x its mean luminance x the sky's
 * intensity); it is importance-sampled by the environment section: one float per texel
 * (in .x): the cumulative distribution over rows (height values), then for each row the
 * cumulative distribution over its pixels (width values), of luminance x sin(latitude).
 *
 * light tree (scenes of more than LIGHT_LOCAL_CHOICE_MAX lights; core/light_tree.h builds
 * it): a binary tree over the lights, one light a leaf, root at node 0, an interior
 * node's children contiguous (first, first + 1). The shader walks it from the root to
 * choose a light for a point, each child in proportion to an estimate of what its lights
 * give the point (glsl/lights.glsl). A node is 3 texels:
 *   texel 0 = (box min.xyz of its finite lights, their intensity: the sum of what an
 *             estimate divides by the squared distance)
 *   texel 1 = (box max.xyz, irradiance of its infinite lights (sun, environment))
 *   texel 2 = (axis of the cone of its flat lights' normals and spots' directions (of a
 *             node of infinite lights alone: of the directions they come from),
 *             octahedral (packed_encode_normal of core/pack.h), cosine of the cone's
 *             half-angle (-1: lights that shine every way), child: interior: its first
 *             child's node index; leaf: the light's index | LIGHT_TREE_LEAF, flags:
 *             LIGHT_TREE_ONE_SIDED when its lights are all spots, which shine within the
 *             cone about +axis and nowhere else; otherwise the cone holds each light's
 *             normal or its negation, as emitters are two-sided) */
#define PACKED_LIGHT_STRIDE 5
#define PACKED_LIGHT_TREE_NODE_STRIDE 3
#define LIGHT_TREE_LEAF 2147483648u
#define LIGHT_TREE_ONE_SIDED 1u
#define LIGHT_TREE_MAX_DEPTH 32        /* a trail's bits */
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
 * purpose: llvmpipe keeps the stack in memory, and a larger one was slower
 * (docs/performance.md). */
#define BVH_MAX_DEPTH 24
#define BVH_MAX_LEAF_SIZE 4

#endif
