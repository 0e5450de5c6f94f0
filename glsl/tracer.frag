// tracer.frag: the path tracer. One invocation per pixel per pass.
//
// Compiled as "#version 450 core" + core/packed_layout.h + glsl/random.glsl + this file,
// so every record offset and type tag below comes from the one shared layout definition.
//
// Why passes: llvmpipe silently ends all loops of one invocation after 65,535 iterations
// in total, and GPU drivers kill long draws. So a pixel does at most pass_work_budget
// units of work per pass (a unit is one BVH node visit or one primitive test), keeps an
// unfinished path in the state textures and continues it in the next pass. One
// traversal may run past the budget (it cannot be suspended) but never past
// TRAVERSAL_HARD_CAP; a traversal cut there is counted in statistics.y and reported as
// an error by the host, so a wrong image is never silent.
//
// Random numbers are a pure function of (pixel, sample index, seed, bounce): the same
// sample renders the same whatever the pass split or the machine.

#ifndef RTSPHERES_AOV_PASS
layout(location = 0) out vec4 out_origin;       // ray origin of the path in flight
layout(location = 1) out vec4 out_direction;    // ray direction (unit)
layout(location = 2) out vec4 out_throughput;   // path throughput so far
layout(location = 3) out vec4 out_radiance;     // radiance gathered by the path in flight
layout(location = 4) out uvec4 out_counters;    // x: samples started, y: bounce (0: no path in
                                                // flight), z: media the path is in (two 16-bit
                                                // volume instance numbers + 1, inner low)
layout(location = 5) out vec4 out_accumulated;  // rgb: sum over finished samples, a: finished samples
layout(location = 6) out vec4 out_statistics;   // x: path segments traced, y: traversal overflows,
                                                // z: sum of squared luminance of finished samples

#else
// The AOV pass (compiled with RTSPHERES_AOV_PASS defined): first-hit albedo, normal and
// depth, averaged over a few jittered camera rays, to guide the denoiser.
layout(location = 0) out vec4 out_albedo_depth;  // rgb: albedo, a: distance to the first hit (0: none)
layout(location = 1) out vec4 out_normal;        // xyz: world shading normal, w: share of rays that hit
uniform int aov_samples;
#endif
#ifndef RTSPHERES_AOV_PASS
uniform sampler2D state_origin;
uniform sampler2D state_direction;
uniform sampler2D state_throughput;
uniform sampler2D state_radiance;
uniform usampler2D state_counters;
uniform sampler2D state_accumulated;
uniform sampler2D state_statistics;
#endif

uniform usamplerBuffer packed_scene;

uniform ivec2 image_size;       // the region this render covers (the whole image or a crop)
uniform ivec2 region_origin;    // its top-left pixel in the full image (row 0 at the top)
uniform ivec2 full_size;        // the full image: camera and random numbers use its pixels
uniform vec3 camera_origin;
uniform vec3 camera_lower_left;
uniform vec3 camera_horizontal;
uniform vec3 camera_vertical;
uniform vec3 camera_u;
uniform vec3 camera_v;
uniform float lens_radius;
uniform float shutter_open;
uniform float shutter_close;
uniform uint camera_media;      // media the camera is in, packed like out_counters.z
#ifdef RTSPHERES_SKY_TYPE
const int sky_type = RTSPHERES_SKY_TYPE;   // compiled in for this scene (gpu.h)
#else
uniform int sky_type;
#endif
uniform vec3 sky_bottom;
uniform vec3 sky_top;
uniform float sky_intensity;
uniform float sky_rotation;     // radians about +Y
uniform uint sky_faces[6];      // sky box: image indices +X -X +Y -Y +Z -Z
uniform uint sky_environment;   // equirectangular image index
uniform uint seed;
uniform uint sample_start;
uniform uint samples_per_pixel;
uniform uint max_depth;
uniform uint russian_roulette_depth;
uniform int pass_work_budget;   // work units a pixel may start in this pass
uniform int work_cap;           // no invocation ever does more (see below)
uniform int light_sampling;     // 0: BSDF sampling only (for tests of the estimators)
#ifdef RTSPHERES_INTEGRATOR
const int integrator = RTSPHERES_INTEGRATOR;   // compiled in for this render (gpu.h)
#else
uniform int integrator;         // 0: path tracing, 1: Whitted with Phong shading
#endif
uniform vec3 ambient;           // Whitted: ambient light

layout(binding = 0, offset = 0) uniform atomic_uint unfinished_pixels;
layout(binding = 0, offset = 4) uniform atomic_uint samples_finished;

const float INFINITY = 1.0 / 0.0;
const float PI = 3.14159265358979;
const int SKY_CONSTANT = 1;
const int SKY_BOX = 2;
const int SKY_ENVIRONMENT = 3;
const uint NONE = PACKED_NONE;
const int STACK_SIZE = 2 * BVH_MAX_DEPTH + 2 * BVH_MAX_LEAF_SIZE;

// Variants (gpu.h GPU_OMIT_*): code for what the scene lacks is left out, because
// llvmpipe runs both sides of every branch and so pays for all code in a loop.
#if defined(RTSPHERES_OMIT_TRIANGLES) && defined(RTSPHERES_OMIT_QUADS) && defined(RTSPHERES_OMIT_MOVING_SPHERES) \
    && defined(RTSPHERES_OMIT_INSTANCES)
#define RTSPHERES_ONLY_SPHERES 1
#endif
#if defined(RTSPHERES_OMIT_SPHERES) && defined(RTSPHERES_OMIT_QUADS) && defined(RTSPHERES_OMIT_INSTANCES)
#define RTSPHERES_ONLY_TRIANGLES 1
#endif
#if defined(RTSPHERES_OMIT_TRIANGLES) && defined(RTSPHERES_OMIT_QUADS)
#define RTSPHERES_OMIT_FLAT 1
#endif

// ---- the work bound ----------------------------------------------------------------
//
// llvmpipe ends all loops of one shader invocation once they have run 65,535 iterations
// together, silently, and it runs the pixels of one SIMD vector (8 lanes at 256 bits) as
// one invocation: every loop runs until its slowest lane is done, and at least once
// even when no lane needs it. So work counts, per pixel, every loop iteration the pixel
// runs (every loop below adds to it) plus SEGMENT_WORK for each path segment, which is
// at least the number of loops a segment passes through. Then a vector's iterations are
// at most (lanes + 1) x the largest pixel's work, and the host picks work_cap (and the
// largest budget) so that stays under the cap (gpu.c); a pixel that would pass work_cap
// stops and sets overflow, which the host turns into an error: never a silently wrong
// image. tests/render/test-pass-budget.sh checks images do not depend on the budget.
const int SEGMENT_WORK = 64;
int work;            // this invocation's work so far
bool overflow;       // work_cap was reached: the path in flight is cut short

// Counts one loop iteration; false (and overflow set) when the cap is reached.
bool count_work()
{
    work++;
    if (work > work_cap)
        overflow = true;
    return !overflow;
}

// ---- packed scene access ---------------------------------------------------------

uvec4 packed_texel(uint index)
{
    return texelFetch(packed_scene, int(index));
}

vec3 packed_xyz(uvec4 texel) { return uintBitsToFloat(texel.xyz); }
vec4 packed_vec4(uint index) { return uintBitsToFloat(packed_texel(index)); }

// A vertex normal from its octahedral encoding (pack.c packed_encode_normal).
vec3 decode_normal(uint bits)
{
    vec2 f = unpackSnorm2x16(bits);
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return normalize(n);
}

uint material_offset;
uint primitive_offset;
uint node_offset;
uint node_count;
uint instance_offset;
uint info_offset;
uint shape_offset;
uint vertex_offset;
uint uv_offset;
uint area_light_count;
uint default_material;
uint texture_offset;
uint image_offset;
uint light_offset;
uint light_count;
uint environment_offset;

// ---- random numbers (glsl/random.glsl, prepended) ----------------------------------

uvec2 rng_pixel;     // pixel in image coordinates (row 0 at the top)
uint rng_sample;     // absolute sample index
uint rng_seed_hash;

// Four uniform numbers in [0, 1) for one (bounce, stream) of the current sample.
vec4 random4(uint bounce, uint stream)
{
    return random_numbers(rng_pixel, rng_sample, rng_seed_hash, bounce * 8u + stream);
}

// ---- geometry --------------------------------------------------------------------

struct Hit {
    float t;
    uint primitive;   // slot in the primitive section
    uint instance;    // NONE: a world primitive
    vec2 barycentric; // triangles: (b1, b2) of v1, v2; quads: (a, b) along the edges
};

// Nearest root of |origin + t*direction - center| = radius with t in (0, t_max), or
// INFINITY, for a direction of any length (instances scale it). The discriminant is
// computed from the squared distance of the centre to the ray's closest point, which
// keeps float32 precise for the radius-1000 ground sphere (Haines et al., Ray Tracing
// Gems, ch. 7).
float intersect_sphere(vec3 center, float radius, vec3 origin, vec3 direction, float t_max)
{
    float direction_length = length(direction);
    vec3 unit = direction / direction_length;
    vec3 to_origin = origin - center;
    float b = dot(to_origin, unit);
    vec3 closest_offset = to_origin - b * unit;
    float discriminant = radius * radius - dot(closest_offset, closest_offset);
    if (discriminant < 0.0)
        return INFINITY;
    float root = sqrt(discriminant);
    float c = dot(to_origin, to_origin) - radius * radius;
    float q = -b - (b >= 0.0 ? root : -root);
    float t_near = c / q / direction_length;
    float t_far = q / direction_length;
    if (t_near > t_far) { float swap = t_near; t_near = t_far; t_far = swap; }
    if (t_near > 0.0 && t_near < t_max)
        return t_near;
    if (t_far > 0.0 && t_far < t_max)
        return t_far;
    return INFINITY;
}

// Moller-Trumbore for a triangle (corner, edge1, edge2), or the parallelogram spanned by
// the same vectors when quad is true. Returns t and the two edge coordinates.
float intersect_flat(vec3 corner, vec3 edge1, vec3 edge2, bool quad, vec3 origin, vec3 direction, float t_max,
                     out vec2 coordinates)
{
    coordinates = vec2(0.0);
    vec3 p = cross(direction, edge2);
    float determinant = dot(edge1, p);
    if (abs(determinant) < 1e-20)
        return INFINITY;
    float inverse = 1.0 / determinant;
    vec3 s = origin - corner;
    float u = dot(s, p) * inverse;
    vec3 q = cross(s, edge1);
    float v = dot(direction, q) * inverse;
    bool inside = quad ? (u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) : (u >= 0.0 && v >= 0.0 && u + v <= 1.0);
    if (!inside)
        return INFINITY;
    float t = dot(edge2, q) * inverse;
    coordinates = vec2(u, v);
    return t > 0.0 && t < t_max ? t : INFINITY;
}

// Entry distance of the ray into a box, or INFINITY when it misses or enters beyond t_max.
float intersect_box(vec3 box_min, vec3 box_max, vec3 origin, vec3 inverse_direction, float t_max)
{
    vec3 t0 = (box_min - origin) * inverse_direction;
    vec3 t1 = (box_max - origin) * inverse_direction;
    vec3 t_small = min(t0, t1);
    vec3 t_large = max(t0, t1);
    float enter = max(max(t_small.x, t_small.y), max(t_small.z, 0.0));
    float leave = min(min(t_large.x, t_large.y), min(t_large.z, t_max));
    return enter <= leave ? enter : INFINITY;
}

float node_entry_distance(uint node, vec3 origin, vec3 inverse_direction, float t_max)
{
    uint base = node_offset + node * uint(PACKED_NODE_STRIDE);
    return intersect_box(packed_xyz(packed_texel(base)), packed_xyz(packed_texel(base + 1u)), origin,
                         inverse_direction, t_max);
}

// ---- primitive records (packed_layout.h "primitives") ------------------------------

// The info word of a primitive: type tag, uvs flag, material.
uint primitive_info(uint slot)
{
    return packed_texel(info_offset + slot / 4u)[slot % 4u];
}

uint primitive_type(uint info) { return info >> uint(PRIMITIVE_INFO_TYPE_SHIFT); }

// The type of a primitive from its record (packed_layout.h: every record but a sphere's
// has a tag in w), known at compile time in the variants with one kind of primitive.
uint record_type(uvec4 record)
{
#if defined(RTSPHERES_ONLY_SPHERES)
    return uint(PRIMITIVE_SPHERE);
#elif defined(RTSPHERES_ONLY_TRIANGLES)
    return uint(PRIMITIVE_TRIANGLE);
#else
    return record.w >= PRIMITIVE_RECORD_TAG ? record.w - PRIMITIVE_RECORD_TAG : uint(PRIMITIVE_SPHERE);
#endif
}

// A primitive's geometry as the layout of the tests has it: sphere (centre, radius) in a;
// moving sphere (centre at time 0, radius) in a, (centre at time 1) in b; triangle and
// quad: corner in a, edges in b and c; for a triangle, normal_words are its vertices'
// encoded normals. The texels behind the record are fetched in one place for every type
// (a triangle's vertices, a shape record): llvmpipe runs every branch, so per-type
// fetches would all be paid.
void primitive_geometry(uvec4 record, uint type, out vec4 a, out vec4 b, out vec4 c, out uvec3 normal_words)
{
    a = uintBitsToFloat(record);
    b = vec4(0.0);
    c = vec4(0.0);
    normal_words = uvec3(VERTEX_NO_NORMAL);
#ifndef RTSPHERES_ONLY_SPHERES
    bool triangle = type == uint(PRIMITIVE_TRIANGLE);
    bool behind = type != uint(PRIMITIVE_SPHERE) && type != uint(PRIMITIVE_INSTANCE);
    uvec3 address = triangle ? uvec3(vertex_offset) + record.xyz : uvec3(record.x, record.x + 1u, record.x + 2u);
    address = behind ? address : uvec3(0u);
    uvec4 g0 = packed_texel(address.x), g1 = packed_texel(address.y);
#ifdef RTSPHERES_OMIT_FLAT
    uvec4 g2 = uvec4(0u);
#else
    uvec4 g2 = packed_texel(address.z);
#endif
    if (behind) {
        vec4 f0 = uintBitsToFloat(g0), f1 = uintBitsToFloat(g1), f2 = uintBitsToFloat(g2);
        a = triangle ? vec4(f0.xyz, 0.0) : f0;
        b = triangle ? vec4(f1.xyz - f0.xyz, 0.0) : f1;
        c = triangle ? vec4(f2.xyz - f0.xyz, 0.0) : f2;
        if (triangle)
            normal_words = uvec3(g0.w, g1.w, g2.w);
    }
#endif
}

// The vertex normals of a triangle whose vertex texels' w are bits (false when a vertex
// has none: then it is shaded flat).
bool vertex_normals(uvec3 bits, out vec3 n0, out vec3 n1, out vec3 n2)
{
    n0 = decode_normal(bits.x);
    n1 = decode_normal(bits.y);
    n2 = decode_normal(bits.z);
    return all(notEqual(bits, uvec3(VERTEX_NO_NORMAL)));
}

vec2 vertex_uv(uint vertex)
{
    uvec4 texel = packed_texel(uv_offset + vertex / 2u);
    return uintBitsToFloat((vertex & 1u) == 0u ? texel.xy : texel.zw);
}

// Tests one primitive (by slot, its record already read) of the current level; on a
// nearer hit updates hit.
void intersect_primitive(uint slot, uvec4 record, uint type, vec3 origin, vec3 direction, float time, uint instance,
                         inout Hit hit)
{
    vec4 a, b, c;
    uvec3 normal_words;
    primitive_geometry(record, type, a, b, c, normal_words);
    float t = INFINITY;
    vec2 coordinates = vec2(0.0);
#ifdef RTSPHERES_ONLY_SPHERES
    t = intersect_sphere(a.xyz, a.w, origin, direction, hit.t);
#else
    bool flat_primitive = type == uint(PRIMITIVE_TRIANGLE) || type == uint(PRIMITIVE_QUAD);
#ifndef RTSPHERES_OMIT_MOVING_SPHERES
    if (type == uint(PRIMITIVE_MOVING_SPHERE))
        a.xyz = mix(a.xyz, b.xyz, time);
#endif
#ifndef RTSPHERES_OMIT_SPHERES
    if (!flat_primitive)
        t = intersect_sphere(a.xyz, a.w, origin, direction, hit.t);
#endif
#ifndef RTSPHERES_OMIT_FLAT
    if (flat_primitive)
        t = intersect_flat(a.xyz, b.xyz, c.xyz, type == uint(PRIMITIVE_QUAD), origin, direction, hit.t, coordinates);
#endif
#endif
    if (t < hit.t) {
        hit.t = t;
        hit.primitive = slot;
        hit.instance = instance;
        hit.barycentric = coordinates;
    }
}

// Moves a world ray into an instance's object coordinates (the direction is not
// renormalised, so t keeps meaning the world ray's parameter).
void to_object(uint instance, vec3 origin, vec3 direction, out vec3 object_origin, out vec3 object_direction)
{
    uint base = instance_offset + instance * uint(PACKED_INSTANCE_STRIDE);
    vec4 row0 = packed_vec4(base + 1u), row1 = packed_vec4(base + 2u), row2 = packed_vec4(base + 3u);
    object_origin = vec3(dot(row0.xyz, origin) + row0.w, dot(row1.xyz, origin) + row1.w, dot(row2.xyz, origin) + row2.w);
    object_direction = vec3(dot(row0.xyz, direction), dot(row1.xyz, direction), dot(row2.xyz, direction));
}

// Finds the nearest hit closer than t_max along the ray by walking the top-level BVH and,
// through instance records, the objects' BVHs, nearer child first, with one explicit
// stack. work counts node visits and primitive tests; overflow is set when the hard cap
// cut the traversal.
//
// The loop carries the current node as the (first, count) pair of its record rather than
// its index: both children's records are fetched anyway to test their boxes, and their w
// components are those pairs, so a node is never fetched twice (4 fetches per interior
// node instead of 6). Stack entries are such pairs too, with two markers for instances:
// count ENTER_INSTANCE (first = the instance) moves the ray into the instance's object,
// count LEAVE_INSTANCE restores the world ray.
const uint ENTER_INSTANCE_MARK = 0xfffffffeu;
const uint LEAVE_INSTANCE_MARK = 0xffffffffu;

bool trace(vec3 world_origin, vec3 world_direction, float time, float t_max, out Hit hit)
{
    hit.t = t_max;
    hit.primitive = 0u;
    hit.instance = NONE;
    hit.barycentric = vec2(0.0);
    if (node_count == 0u)
        return false;
    vec3 origin = world_origin;
    vec3 direction = world_direction;
    vec3 inverse_direction = 1.0 / direction;
    uint instance = NONE;
    uvec4 root_low = packed_texel(node_offset), root_high = packed_texel(node_offset + 1u);
    float node_entry = intersect_box(packed_xyz(root_low), packed_xyz(root_high), origin, inverse_direction, t_max);
    if (node_entry == INFINITY)
        return false;
    uint first = root_low.w, count = root_high.w;

    uint stack_first[STACK_SIZE];
    uint stack_count[STACK_SIZE];
    float stack_entry[STACK_SIZE];
    int stack_size = 0;
    for (;;) {
        if (!count_work())
            break;
#ifndef RTSPHERES_OMIT_INSTANCES
        if (count == LEAVE_INSTANCE_MARK) {
            origin = world_origin;
            direction = world_direction;
            inverse_direction = 1.0 / direction;
            instance = NONE;
        } else
#endif
        if (node_entry < hit.t) {
            if (count > 0u) {
                for (uint slot = first; slot < first + count && count_work(); slot++) {
                    uvec4 record = packed_texel(primitive_offset + slot);
                    uint type = record_type(record);
#ifndef RTSPHERES_OMIT_INSTANCES
                    if (type == uint(PRIMITIVE_INSTANCE)) {
                        if (stack_size + 2 <= STACK_SIZE) {
                            stack_count[stack_size] = LEAVE_INSTANCE_MARK;
                            stack_entry[stack_size] = -INFINITY;
                            stack_first[stack_size + 1] = record.x;
                            stack_count[stack_size + 1] = ENTER_INSTANCE_MARK;
                            stack_entry[stack_size + 1] = -INFINITY;
                            stack_size += 2;
                        } else {
                            overflow = true;   // reported as an error, never skipped silently
                        }
                    } else
#endif
                    {
                        intersect_primitive(slot, record, type, origin, direction, time, instance, hit);
                    }
                }
            } else {
                uint base = node_offset + first * uint(PACKED_NODE_STRIDE);
                uvec4 left_low = packed_texel(base), left_high = packed_texel(base + 1u);
                uvec4 right_low = packed_texel(base + 2u), right_high = packed_texel(base + 3u);
                float left_entry = intersect_box(packed_xyz(left_low), packed_xyz(left_high), origin,
                                                 inverse_direction, hit.t);
                float right_entry = intersect_box(packed_xyz(right_low), packed_xyz(right_high), origin,
                                                  inverse_direction, hit.t);
                bool right_nearer = right_entry < left_entry;
                uvec2 near_node = right_nearer ? uvec2(right_low.w, right_high.w) : uvec2(left_low.w, left_high.w);
                uvec2 far_node = right_nearer ? uvec2(left_low.w, left_high.w) : uvec2(right_low.w, right_high.w);
                float near_entry = min(left_entry, right_entry), far_entry = max(left_entry, right_entry);
                if (near_entry < INFINITY) {
                    if (far_entry < INFINITY) {
                        if (stack_size < STACK_SIZE) {
                            stack_first[stack_size] = far_node.x;
                            stack_count[stack_size] = far_node.y;
                            stack_entry[stack_size] = far_entry;
                            stack_size++;
                        } else {
                            overflow = true;
                        }
                    }
                    first = near_node.x;
                    count = near_node.y;
                    node_entry = near_entry;
                    continue;
                }
            }
        }
        if (stack_size == 0)
            break;
        stack_size--;
        first = stack_first[stack_size];
        count = stack_count[stack_size];
        node_entry = stack_entry[stack_size];
#ifndef RTSPHERES_OMIT_INSTANCES
        if (count == ENTER_INSTANCE_MARK) {
            instance = first;
            to_object(instance, world_origin, world_direction, origin, direction);
            inverse_direction = 1.0 / direction;
            uint root = node_offset + packed_texel(instance_offset + instance * uint(PACKED_INSTANCE_STRIDE)).x
                                      * uint(PACKED_NODE_STRIDE);
            uvec4 low = packed_texel(root), high = packed_texel(root + 1u);
            first = low.w;
            count = high.w;
            node_entry = intersect_box(packed_xyz(low), packed_xyz(high), origin, inverse_direction, hit.t);
        }
#endif
    }
    return hit.t < t_max;
}

// ---- images and textures ---------------------------------------------------------

// Bilinear lookup of image (index) at uv, wrapping. Texture coordinates follow OBJ and
// the Ray Tracing books: u to the right, v UP, so v = 1 is the image's top row (images are
// stored top row first).
vec3 image_lookup(uint image, vec2 uv)
{
    uvec4 record = packed_texel(image_offset + image * uint(PACKED_IMAGE_STRIDE));
    uint first = record.x;
    int width = int(record.y), height = int(record.z);
    if (width == 0 || height == 0)
        return vec3(1.0, 0.0, 1.0);
    vec2 position = vec2(fract(uv.x), 1.0 - fract(uv.y)) * vec2(width, height) - 0.5;
    ivec2 corner = ivec2(floor(position));
    vec2 weight = position - vec2(corner);
    vec3 colour = vec3(0.0);
    for (int k = 0; k < 4; k++) {
        work++;
        ivec2 texel = corner + ivec2(k & 1, k >> 1);
        texel.x = (texel.x % width + width) % width;
        texel.y = clamp(texel.y, 0, height - 1);
        float w = ((k & 1) != 0 ? weight.x : 1.0 - weight.x) * ((k >> 1) != 0 ? weight.y : 1.0 - weight.y);
        colour += w * packed_vec4(first + uint(texel.y * width + texel.x)).rgb;
    }
    return colour;
}

// Gradient noise in [-1, 1] with hashed gradients (Perlin's construction, hash instead
// of a permutation table so that no table needs uploading).
float gradient_noise(vec3 p)
{
    vec3 cell = floor(p);
    vec3 f = p - cell;
    vec3 fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float result = 0.0;
    for (int k = 0; k < 8; k++) {
        work++;
        ivec3 offset = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        uvec4 h = hash4(uvec4(uvec3(ivec3(cell) + offset), 0x5eedu));
        vec3 gradient = normalize(vec3(h.xyz >> 8u) * (2.0 / 16777216.0) - 1.0 + 1e-6);
        vec3 weight = mix(1.0 - fade, fade, vec3(offset));
        result += weight.x * weight.y * weight.z * dot(gradient, f - vec3(offset));
    }
    return result;
}

float turbulence(vec3 p)
{
    float sum = 0.0, weight = 1.0;
    for (int octave = 0; octave < 7; octave++) {
        work++;
        sum += weight * abs(gradient_noise(p));
        weight *= 0.5;
        p *= 2.0;
    }
    return sum;
}

// The colour of texture (index) at a surface point: world position p, uv.
vec3 texture_value(uint texture, vec3 p, vec2 uv)
{
    // Checkers nest at most one level: their two cells are evaluated as flat textures.
    for (int level = 0; level < 2; level++) {
        work++;
        uint base = texture_offset + texture * uint(PACKED_TEXTURE_STRIDE);
        uvec4 head = packed_texel(base);
        vec4 data = packed_vec4(base + 1u);
        if (head.x == uint(TEXTURE_CONSTANT))
            return data.rgb;
        if (head.x == uint(TEXTURE_IMAGE))
            return image_lookup(head.w, uv);
        if (head.x == uint(TEXTURE_NOISE))
            return vec3(0.5 * (1.0 + gradient_noise(data.w * p)));
        if (head.x == uint(TEXTURE_TURBULENCE))
            return vec3(turbulence(data.w * p));
        if (head.x == uint(TEXTURE_MARBLE))
            return vec3(0.5 * (1.0 + sin(data.w * p.z + 10.0 * turbulence(p))));
        // Checker: the cell parity of floor(p / scale) picks the even or the odd texture.
        ivec3 cell = ivec3(floor(p / data.w));
        texture = ((cell.x + cell.y + cell.z) & 1) == 0 ? head.y : head.z;
    }
    return vec3(1.0, 0.0, 1.0);
}

// ---- sky -------------------------------------------------------------------------

vec3 sky_radiance(vec3 direction)
{
    if (sky_type == SKY_CONSTANT)
        return sky_intensity * sky_bottom;
    if (sky_type != SKY_BOX && sky_type != SKY_ENVIRONMENT)
        return sky_intensity * mix(sky_bottom, sky_top, 0.5 * (direction.y + 1.0));
    // Turn the direction into the sky's own frame (the sky turns by +rotation about Y).
    float c = cos(sky_rotation), s = sin(sky_rotation);
    vec3 d = vec3(c * direction.x - s * direction.z, direction.y, s * direction.x + c * direction.z);
    if (sky_type == SKY_ENVIRONMENT) {
        vec2 uv = vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), 1.0 - acos(clamp(d.y, -1.0, 1.0)) / PI);
        return sky_intensity * image_lookup(sky_environment, uv);
    }
    // Cube map faces as OpenGL lays them out: major axis, then (s, t) on the face.
    vec3 a = abs(d);
    uint face;
    vec2 st;
    float major;
    if (a.x >= a.y && a.x >= a.z) {
        major = a.x;
        face = d.x > 0.0 ? 0u : 1u;
        st = d.x > 0.0 ? vec2(-d.z, -d.y) : vec2(d.z, -d.y);
    } else if (a.y >= a.z) {
        major = a.y;
        face = d.y > 0.0 ? 2u : 3u;
        st = d.y > 0.0 ? vec2(d.x, d.z) : vec2(d.x, -d.z);
    } else {
        major = a.z;
        face = d.z > 0.0 ? 4u : 5u;
        st = d.z > 0.0 ? vec2(d.x, -d.y) : vec2(-d.x, -d.y);
    }
    // (s, t) run right and down on the face image; v runs up.
    vec2 face_uv = clamp(0.5 * (st / major + 1.0), 0.00001, 0.99999);
    return sky_intensity * image_lookup(sky_faces[face], vec2(face_uv.x, 1.0 - face_uv.y));
}

// ---- shading helpers ------------------------------------------------------------

vec3 random_unit_vector(vec2 u)
{
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

vec3 random_in_unit_sphere(vec3 u)
{
    return random_unit_vector(u.xy) * pow(u.z, 1.0 / 3.0);
}

vec2 random_in_unit_disk(vec2 u)
{
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    return vec2(r * cos(phi), r * sin(phi));
}

float schlick_reflectance(float cosine, float eta_ratio)
{
    float r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
    r0 = r0 * r0;
    return r0 + (1.0 - r0) * pow(1.0 - cosine, 5.0);
}

// Offset for a new ray leaving point p: scaled with the point's magnitude because
// float32 spacing grows with it; keeps rays from re-hitting the surface they leave.
float ray_offset(vec3 p)
{
    vec3 a = abs(p);
    return 1e-4 * (1.0 + max(a.x, max(a.y, a.z)));
}

// What shading needs to know about a hit.
struct Surface {
    vec3 position;        // world
    vec3 geometric;       // world, unit, outward (the side the primitive faces)
    vec3 shading;         // world, unit, outward (interpolated vertex normals, else geometric)
    vec2 uv;
    uint material;        // material index
    bool volume_boundary; // the hit is on a volume instance's boundary
    uint instance;
};

// Computes the surface at a hit: normals (object space, moved to the world by the
// inverse transpose of the placement, which is the transpose of world-to-object), uv and
// the material (the primitive's own, else the instance's, else the default).
Surface surface_at(Hit hit, vec3 origin, vec3 direction, float time)
{
    Surface surface;
    surface.position = origin + hit.t * direction;
    surface.instance = hit.instance;
    surface.volume_boundary = false;
    uvec4 record = packed_texel(primitive_offset + hit.primitive);
    uint info = primitive_info(hit.primitive);
    uint type = primitive_type(info);
    vec4 a, b, c;
    uvec3 normal_words;
    primitive_geometry(record, type, a, b, c, normal_words);
    vec3 object_point = surface.position;
    mat3 normal_to_world = mat3(1.0);
    uint instance_material = NONE;
#ifndef RTSPHERES_OMIT_INSTANCES
    if (hit.instance != NONE) {
        uint instance_base = instance_offset + hit.instance * uint(PACKED_INSTANCE_STRIDE);
        uvec4 instance_head = packed_texel(instance_base);
        instance_material = instance_head.y;
#ifndef RTSPHERES_OMIT_VOLUMES
        surface.volume_boundary = (instance_head.z & uint(INSTANCE_VOLUME)) != 0u;
#endif
        vec4 row0 = packed_vec4(instance_base + 1u), row1 = packed_vec4(instance_base + 2u),
             row2 = packed_vec4(instance_base + 3u);
        vec3 object_direction;
        to_object(hit.instance, origin, direction, object_point, object_direction);
        object_point += hit.t * object_direction;
        // Columns are the rows of world-to-object: transpose(M) * n.
        normal_to_world = mat3(row0.xyz, row1.xyz, row2.xyz);
    }
#endif
    uint own_material = info & uint(PRIMITIVE_INFO_MATERIAL_MASK);
    surface.material = own_material != uint(PRIMITIVE_NO_MATERIAL) ? own_material
                     : instance_material != NONE ? instance_material : default_material;
#ifdef RTSPHERES_OMIT_TEXTURES
    uint normal_map = NONE;
#else
    uint normal_map = packed_texel(material_offset + surface.material * uint(PACKED_MATERIAL_STRIDE) + 2u).w;
#endif
    vec3 normal = vec3(0.0, 1.0, 0.0);
    vec3 shading_normal = normal;
    vec3 tangent = vec3(0.0);     // object-space direction of increasing u (for normal maps)
    float handedness = 1.0;
    vec2 uv = hit.barycentric;
    bool flat_primitive = type == uint(PRIMITIVE_TRIANGLE) || type == uint(PRIMITIVE_QUAD);
#ifdef RTSPHERES_OMIT_SPHERES
    flat_primitive = true;
#endif
#ifdef RTSPHERES_OMIT_FLAT
    flat_primitive = false;
#endif
#ifndef RTSPHERES_OMIT_SPHERES
    if (!flat_primitive) {
        vec3 center = a.xyz;
#ifndef RTSPHERES_OMIT_MOVING_SPHERES
        if (type == uint(PRIMITIVE_MOVING_SPHERE))
            center = mix(a.xyz, b.xyz, time);
#endif
        normal = (object_point - center) / a.w;
        shading_normal = normal;
        // Longitude/latitude of the normal as the books map spheres: u around +Y starting
        // at -X, v from 0 at the bottom to 1 at the top.
#ifndef RTSPHERES_OMIT_TEXTURES
        uv = vec2(0.5 + atan(-normal.z, normal.x) / (2.0 * PI), acos(clamp(-normal.y, -1.0, 1.0)) / PI);
#endif
        tangent = vec3(normal.z, 0.0, -normal.x);
    }
#endif
#ifndef RTSPHERES_OMIT_FLAT
    if (flat_primitive) {
        vec3 edge1 = b.xyz, edge2 = c.xyz;
        normal = cross(edge1, edge2);
        shading_normal = normal;
        tangent = edge1;      // quads and bare triangles: u runs along the first edge
#ifndef RTSPHERES_OMIT_TRIANGLES
        if (type == uint(PRIMITIVE_TRIANGLE)) {
            // Vertex normals and uvs, interpolated by barycentrics.
            vec3 weights = vec3(1.0 - hit.barycentric.x - hit.barycentric.y, hit.barycentric);
            vec3 n0, n1, n2;
            if (vertex_normals(normal_words, n0, n1, n2)) {
                vec3 interpolated = weights.x * n0 + weights.y * n1 + weights.z * n2;
                if (dot(interpolated, interpolated) > 0.0)
                    shading_normal = interpolated;
            }
#ifndef RTSPHERES_OMIT_TEXTURES
            if ((info & uint(PRIMITIVE_INFO_HAS_UVS)) != 0u) {
                vec2 uv0 = vertex_uv(record.x), uv1 = vertex_uv(record.y), uv2 = vertex_uv(record.z);
                uv = weights.x * uv0 + weights.y * uv1 + weights.z * uv2;
                // The tangent follows the uv layout: solve edge = du * T + dv * B.
                vec2 duv1 = uv1 - uv0, duv2 = uv2 - uv0;
                float determinant = duv1.x * duv2.y - duv2.x * duv1.y;
                if (abs(determinant) > 1e-12) {
                    tangent = (edge1 * duv2.y - edge2 * duv1.y) / determinant;
                    vec3 bitangent = (edge2 * duv1.x - edge1 * duv2.x) / determinant;
                    handedness = dot(cross(normal, tangent), bitangent) < 0.0 ? -1.0 : 1.0;
                }
            }
#endif
        }
#endif
    }
#endif
    if (normal_map != NONE) {
        // Tangent-space normal map, applied in object space so that the result moves to
        // the world like any normal (inverse transpose), under any placement.
        vec3 n = normalize(shading_normal);
        vec3 t = tangent - n * dot(n, tangent);
        if (dot(t, t) < 1e-20)
            t = abs(n.x) < 0.9 ? cross(n, vec3(1.0, 0.0, 0.0)) : cross(n, vec3(0.0, 1.0, 0.0));
        t = normalize(t);
        vec3 b = handedness * cross(n, t);
        vec3 mapped = image_lookup(normal_map, uv) * 2.0 - 1.0;
        shading_normal = mapped.x * t + mapped.y * b + mapped.z * n;
    }
    surface.geometric = normalize(normal_to_world * normal);
    surface.shading = normalize(normal_to_world * shading_normal);
    // Keep the shading normal on the geometric side, or light leaks through.
    if (dot(surface.shading, surface.geometric) < 0.0)
        surface.shading = surface.geometric;
    surface.uv = uv;
    return surface;
}

// Media stack in one uint: two 16-bit volume instance numbers + 1, the inner one low.
uint media_inner(uint media) { return media & 0xffffu; }

uint media_enter(uint media, uint instance)
{
    return ((media & 0xffffu) << 16) | ((instance + 1u) & 0xffffu);
}

uint media_leave(uint media, uint instance)
{
    uint number = (instance + 1u) & 0xffffu;
    if ((media & 0xffffu) == number)
        return media >> 16;
    if ((media >> 16) == number)
        return media & 0xffffu;
    return media;
}

// ---- light sampling (next-event estimation with multiple importance sampling) -----

// The probability that choose_light() picks light.
float light_probability(uint light)
{
    float cdf = packed_vec4(light_offset + light * uint(PACKED_LIGHT_STRIDE) + 1u).w;
    float before = light > 0u ? packed_vec4(light_offset + (light - 1u) * uint(PACKED_LIGHT_STRIDE) + 1u).w : 0.0;
    return cdf - before;
}

// Picks a light by power: binary search of the cumulative probabilities.
uint choose_light(float u)
{
    uint low = 0u, high = light_count - 1u;
    while (low < high) {
        work++;
        uint middle = (low + high) / 2u;
        if (u < packed_vec4(light_offset + middle * uint(PACKED_LIGHT_STRIDE) + 1u).w)
            high = middle;
        else
            low = middle + 1u;
    }
    return low;
}

// The light record head of an area light and its primitive's geometry (sphere: centre
// and radius in a; quad and triangle: corner in a, edges in b and c).
void area_light_geometry(uint light, out uvec4 head, out vec4 a, out vec4 b, out vec4 c)
{
    head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    uint type = head.x == uint(LIGHT_SPHERE) ? uint(PRIMITIVE_SPHERE)
              : head.x == uint(LIGHT_QUAD) ? uint(PRIMITIVE_QUAD) : uint(PRIMITIVE_TRIANGLE);
    uvec3 normal_words;
    primitive_geometry(packed_texel(primitive_offset + head.y), type, a, b, c, normal_words);
}

// The area light of an emissive world primitive (by slot), or NONE: the area lights
// come first in the light list, in primitive order (packed_layout.h), so a binary search.
uint area_light_of(uint slot)
{
    uint low = 0u, high = area_light_count;
    while (low < high) {
        work++;
        uint middle = (low + high) / 2u;
        if (packed_texel(light_offset + middle * uint(PACKED_LIGHT_STRIDE)).y < slot)
            low = middle + 1u;
        else
            high = middle;
    }
    return low < area_light_count && packed_texel(light_offset + low * uint(PACKED_LIGHT_STRIDE)).y == slot ? low
                                                                                                           : NONE;
}

// Solid-angle density, seen from p, of the direction light sampling would pick towards
// point x on area light (normal n there), given its record head and geometry. Spheres
// are sampled by their visible cone.
float area_light_pdf(uvec4 head, vec4 a, vec4 edge1, vec4 edge2, vec3 p, vec3 x, vec3 n)
{
    if (head.x == uint(LIGHT_SPHERE)) {
        float distance_squared = dot(a.xyz - p, a.xyz - p);
        if (distance_squared <= a.w * a.w)
            return 0.0;
        float cos_max = sqrt(max(0.0, 1.0 - a.w * a.w / distance_squared));
        return 1.0 / (2.0 * PI * max(1.0 - cos_max, 1e-12));
    }
    float area = length(cross(edge1.xyz, edge2.xyz)) * (head.x == uint(LIGHT_QUAD) ? 1.0 : 0.5);
    vec3 to_light = x - p;
    float distance_squared = dot(to_light, to_light);
    float cosine = abs(dot(n, to_light)) * inversesqrt(distance_squared);
    return cosine > 1e-8 ? distance_squared / (cosine * area) : 0.0;
}

// The same by light index.
float light_direction_pdf(uint light, vec3 p, vec3 x, vec3 n)
{
    uvec4 head;
    vec4 a, edge1, edge2;
    area_light_geometry(light, head, a, edge1, edge2);
    return area_light_pdf(head, a, edge1, edge2, p, x, n);
}

// A direction from p towards a point on light (u uniform): the direction, the distance to
// the light along it, the emitted radiance there and the solid-angle density. Returns
// false when p sees nothing of the light (inside a sphere light, behind nothing).
bool sample_light(uint light, vec3 p, vec2 u, out vec3 direction, out float distance, out vec3 emitted,
                  out float pdf)
{
    uvec4 head;
    vec4 a, edge1, edge2;
    area_light_geometry(light, head, a, edge1, edge2);
    vec3 x, n;
    vec2 uv = u;
    direction = vec3(0.0, 1.0, 0.0);
    distance = 0.0;
    pdf = 0.0;
    emitted = vec3(0.0);
    if (head.x == uint(LIGHT_SPHERE)) {
        vec3 axis = a.xyz - p;
        float distance_squared = dot(axis, axis);
        if (distance_squared <= a.w * a.w)
            return false;
        float axis_length = sqrt(distance_squared);
        axis /= axis_length;
        float cos_max = sqrt(max(0.0, 1.0 - a.w * a.w / distance_squared));
        float cos_theta = 1.0 - u.x * (1.0 - cos_max);
        float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
        float phi = 2.0 * PI * u.y;
        vec3 helper = abs(axis.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        vec3 tangent = normalize(cross(helper, axis));
        vec3 bitangent = cross(axis, tangent);
        direction = normalize(sin_theta * cos(phi) * tangent + sin_theta * sin(phi) * bitangent + cos_theta * axis);
        distance = intersect_sphere(a.xyz, a.w, p, direction, INFINITY);
        if (distance == INFINITY)
            distance = axis_length * cos_theta;  // grazing the rim: close enough
        x = p + distance * direction;
        n = normalize(x - a.xyz);
        uv = vec2(0.5 + atan(-n.z, n.x) / (2.0 * PI), acos(clamp(-n.y, -1.0, 1.0)) / PI);
        pdf = 1.0 / (2.0 * PI * max(1.0 - cos_max, 1e-12));
    } else {
        if (head.x == uint(LIGHT_TRIANGLE) && u.x + u.y > 1.0)
            uv = vec2(1.0) - u;   // fold the square onto the triangle: still uniform
        x = a.xyz + uv.x * edge1.xyz + uv.y * edge2.xyz;
        n = normalize(cross(edge1.xyz, edge2.xyz));
        vec3 to_light = x - p;
        distance = length(to_light);
        if (distance < 1e-12)
            return false;
        direction = to_light / distance;
        pdf = area_light_pdf(head, a, edge1, edge2, p, x, n);   // the geometry is at hand
        if (pdf == 0.0)
            return false;
    }
    uint material = material_offset + (primitive_info(head.y) & uint(PRIMITIVE_INFO_MATERIAL_MASK))
                                      * uint(PACKED_MATERIAL_STRIDE);
    emitted = uintBitsToFloat(packed_texel(material + 1u).xyz);
    uint emission_texture = packed_texel(material + 2u).z;
    if (emission_texture != NONE)
        emitted *= texture_value(emission_texture, x, uv);
    return true;
}

// Point, spot and sun lights seen from p: the direction to the light, its distance
// (INFINITY for the sun) and the light arriving, per unit area facing it (irradiance):
// point and spot: intensity / falloff(distance) (inverse square, or the seed report's
// c + l d + q d^2), the spot shaped by a smooth edge between its inner and outer cones;
// sun: its irradiance, from a direction drawn in its disc (soft shadows).
bool sample_delta_light(uint light, vec3 p, vec2 u, out vec3 direction, out float distance, out vec3 incident)
{
    uint base = light_offset + light * uint(PACKED_LIGHT_STRIDE);
    uvec4 head = packed_texel(base);
    vec4 where = packed_vec4(base + 1u);
    vec4 colour = packed_vec4(base + 2u);
    incident = colour.rgb;
    if (head.x == uint(LIGHT_SUN)) {
        vec3 axis = normalize(where.xyz);
        float cos_theta = 1.0 - u.x * (1.0 - colour.w);
        float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
        float phi = 2.0 * PI * u.y;
        vec3 helper = abs(axis.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        vec3 tangent = normalize(cross(helper, axis));
        vec3 bitangent = cross(axis, tangent);
        direction = normalize(sin_theta * cos(phi) * tangent + sin_theta * sin(phi) * bitangent + cos_theta * axis);
        distance = INFINITY;
        return true;
    }
    vec3 to_light = where.xyz - p;
    distance = length(to_light);
    if (distance < 1e-12)
        return false;
    direction = to_light / distance;
    vec3 attenuation = uintBitsToFloat(head.yzw);
    float falloff = attenuation == vec3(0.0) ? distance * distance
                  : attenuation.x + attenuation.y * distance + attenuation.z * distance * distance;
    incident /= max(falloff, 1e-12);
    if (head.x == uint(LIGHT_SPOT)) {
        vec4 spot = packed_vec4(base + 3u);
        incident *= smoothstep(colour.w, max(spot.w, colour.w + 1e-6), dot(-direction, spot.xyz));
    }
    return true;
}

// ---- environment map sampling ----------------------------------------------------

// Index of the first of count cumulative values (one float per texel from base) that
// exceeds u: a binary search.
uint search_cumulative(uint base, uint count, float u)
{
    uint low = 0u, high = count - 1u;
    while (low < high) {
        work++;
        uint middle = (low + high) / 2u;
        if (u < packed_vec4(base + middle).x)
            high = middle;
        else
            low = middle + 1u;
    }
    return low;
}

float cumulative_step(uint base, uint index)
{
    return packed_vec4(base + index).x - (index > 0u ? packed_vec4(base + index - 1u).x : 0.0);
}

// World direction <-> the environment image's (u, v down) coordinates, as sky_radiance
// reads them (the sky turned by sky_rotation about +Y).
vec3 environment_direction(vec2 uv)
{
    float theta = PI * uv.y, phi = 2.0 * PI * (uv.x - 0.5);
    vec3 d = vec3(sin(phi) * sin(theta), cos(theta), -cos(phi) * sin(theta));
    float c = cos(sky_rotation), s = sin(sky_rotation);
    return vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
}

// Solid-angle density with which light sampling picks direction (world) from the
// environment, given the light record's image size.
float environment_pdf(uint light, vec3 direction)
{
    uvec4 head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    uint width = head.y, height = head.z;
    float c = cos(sky_rotation), s = sin(sky_rotation);
    vec3 d = vec3(c * direction.x - s * direction.z, direction.y, s * direction.x + c * direction.z);
    vec2 uv = vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
    uint column = min(uint(uv.x * float(width)), width - 1u);
    uint row = min(uint(uv.y * float(height)), height - 1u);
    float pixel = cumulative_step(environment_offset, row)
                * cumulative_step(environment_offset + height + row * width, column);
    float sine = sin(PI * (float(row) + 0.5) / float(height));
    return sine > 0.0 ? pixel * float(width * height) / (2.0 * PI * PI * sine) : 0.0;
}

// A direction towards the environment chosen in proportion to its luminance.
bool sample_environment(uint light, vec2 u, out vec3 direction, out vec3 emitted, out float pdf)
{
    uvec4 head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    uint width = head.y, height = head.z;
    uint row = search_cumulative(environment_offset, height, u.x);
    uint row_base = environment_offset + height + row * width;
    uint column = search_cumulative(row_base, width, u.y);
    // Reuse what is left of u inside the chosen cells for the position within the pixel.
    float row_low = row > 0u ? packed_vec4(environment_offset + row - 1u).x : 0.0;
    float column_low = column > 0u ? packed_vec4(row_base + column - 1u).x : 0.0;
    float within_row = clamp((u.x - row_low) / max(cumulative_step(environment_offset, row), 1e-20), 0.0, 1.0);
    float within_column = clamp((u.y - column_low) / max(cumulative_step(row_base, column), 1e-20), 0.0, 1.0);
    vec2 uv = vec2((float(column) + within_column) / float(width), (float(row) + within_row) / float(height));
    direction = environment_direction(uv);
    pdf = environment_pdf(light, direction);
    emitted = sky_radiance(direction);
    return pdf > 0.0;
}

// The fraction of light that gets from p to the light primitive at distance along
// direction: 0 behind an opaque surface; through volume boundaries it goes on, losing
// exp(-density * length) in each medium, as the path itself would.
vec3 shadow_transmittance(vec3 p, vec3 direction, float distance, uint light_slot, uint media, float time)
{
#ifdef RTSPHERES_OMIT_VOLUMES
    // No medium anywhere: every surface in the way is opaque.
    Hit blocker;
    bool blocked = trace(p, direction, time, distance * (1.0 - 1e-4), blocker);
    return blocked && !(blocker.instance == NONE && blocker.primitive == light_slot) ? vec3(0.0) : vec3(1.0);
#else
    vec3 transmittance = vec3(1.0);
    float travelled = 0.0;
    vec3 origin = p;
    for (int crossing = 0; crossing < 8; crossing++) {
        work++;
        Hit hit;
        float remaining = distance - travelled;
        // Hits within 1e-4 of the light's distance are the light itself (or beyond it):
        // the traversal need not look that far.
        bool any = trace(origin, direction, time, remaining * (1.0 - 1e-4), hit);
        float segment = any ? hit.t : remaining;
        uint medium = media_inner(media);
        if (medium != 0u) {
            float density = packed_vec4(instance_offset + (medium - 1u) * uint(PACKED_INSTANCE_STRIDE) + 4u).x;
            transmittance *= exp(-density * segment);
        }
        if (!any || (hit.instance == NONE && hit.primitive == light_slot))
            return transmittance;
        if (hit.instance == NONE)
            return vec3(0.0);
        uint instance_base = instance_offset + hit.instance * uint(PACKED_INSTANCE_STRIDE);
        if ((packed_texel(instance_base).z & uint(INSTANCE_VOLUME)) == 0u)
            return vec3(0.0);
        Surface surface = surface_at(hit, origin, direction, time);
        bool entering = dot(direction, surface.geometric) < 0.0;
        media = entering ? media_enter(media, hit.instance) : media_leave(media, hit.instance);
        float step = hit.t + ray_offset(surface.position);
        origin += step * direction;
        travelled += step;
    }
    return vec3(0.0);
#endif
}

float power_heuristic(float chosen, float other)
{
    float a = chosen * chosen, b = other * other;
    return a + b > 0.0 ? a / (a + b) : 0.0;
}

// Direct light at a scattering point p, with ONE shadow-ray call site (GLSL inlines every
// call, and each extra copy of the BVH traversal costs llvmpipe dearly).
//   mode 0 (path tracing): next-event estimation: one light chosen by power, one point on
//     it, weighted against BSDF sampling (density bsdf_pdf) by the power heuristic; delta
//     lights (point, spot, sun) unweighted. is_phase: a volume's isotropic phase function
//     instead of the Lambertian lobe.
//   mode 1 (Whitted): ambient plus, for every light (one chosen by power when there are
//     more than WHITTED_ALL_LIGHTS), Lambert diffuse and normalised-Phong specular terms;
//     area lights are lit from a random point each sample, which averages to soft shadows.
const uint WHITTED_ALL_LIGHTS = 16u;

vec3 direct_light(int mode, vec3 p, vec3 normal, vec3 shading, vec3 view, vec3 albedo, uint material,
                  bool is_phase, uint media, float time, uint bounce)
{
    vec3 result = mode == 1 ? ambient * albedo : vec3(0.0);
    if (light_count == 0u)
        return result;
    vec4 phong = mode == 1 ? packed_vec4(material_offset + material * uint(PACKED_MATERIAL_STRIDE) + 3u) : vec4(0.0);
    bool choose = mode == 0 || light_count > WHITTED_ALL_LIGHTS;
    uint count = choose ? 1u : light_count;
    for (uint k = 0u; k < count; k++) {
        work++;
        vec4 u = mode == 0 ? random4(bounce, 5u)
                           : fract(random4(bounce, 6u + (k & 1u)) + float(k >> 1u) * 0.6180339887);
        uint light = choose ? choose_light(u.x) : k;
        float choice = choose ? light_probability(light) : 1.0;
        if (choice <= 0.0)
            continue;
        vec3 direction, emitted;
        float distance, pdf = 1.0;
        bool delta = false;
        uvec4 head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
        if (head.x == uint(LIGHT_ENVIRONMENT)) {
            if (!sample_environment(light, u.yz, direction, emitted, pdf))
                continue;
            distance = INFINITY;
        } else if (head.x >= uint(LIGHT_POINT)) {
            if (!sample_delta_light(light, p, u.yz, direction, distance, emitted))
                continue;
            delta = true;
        } else if (!sample_light(light, p, u.yz, direction, distance, emitted, pdf) || pdf <= 0.0) {
            continue;
        }
        vec3 value;
        float bsdf_pdf;
        vec3 origin = p;
        if (is_phase) {
            bsdf_pdf = 1.0 / (4.0 * PI);
            value = albedo * bsdf_pdf;
        } else {
            float cosine = dot(shading, direction);
            if (cosine <= 0.0 || dot(normal, direction) <= 0.0)
                continue;
            bsdf_pdf = cosine / PI;
            value = albedo * (cosine / PI);
            if (mode == 1) {
                vec3 reflected = reflect(-direction, shading);
                float highlight = pow(max(dot(reflected, view), 0.0), phong.x) * (phong.x + 2.0) / (2.0 * PI);
                value += phong.yzw * highlight * cosine;
            }
            origin = p + ray_offset(p) * normal;
        }
        float weight;
        if (delta)
            weight = 1.0 / choice;
        else if (mode == 1)
            weight = 1.0 / (choice * pdf);
        else
            weight = power_heuristic(choice * pdf, bsdf_pdf) / (choice * pdf);
        uint slot = delta || head.x == uint(LIGHT_ENVIRONMENT) ? NONE : head.y;
        vec3 transmittance = shadow_transmittance(origin, direction, distance, slot, media, time);
        result += transmittance * value * emitted * weight;
    }
    return result;
}

// Reads the packed scene's header (packed_layout.h) into the globals every function
// uses; light_count is the scene's, which main narrows to what the render samples.
void read_header()
{
    uvec4 header0 = packed_texel(0u), header1 = packed_texel(1u), header2 = packed_texel(2u),
          header3 = packed_texel(3u), header4 = packed_texel(4u), header5 = packed_texel(5u);
    material_offset = header0.z;
    primitive_offset = header1.x;
    node_offset = header1.z;
    node_count = header1.w;
    instance_offset = header2.x;
    info_offset = header2.z;
    default_material = header2.w;
    texture_offset = header3.x;
    image_offset = header3.z;
    light_offset = header4.x;
    light_count = header4.y;
    environment_offset = header4.z;
    area_light_count = header4.w;
    shape_offset = header5.x;
    vertex_offset = header5.y;
    uv_offset = header5.z;
}

#ifdef RTSPHERES_AOV_PASS

void main()
{
    read_header();
    light_count = 0u;
    ivec2 frag_pixel = ivec2(gl_FragCoord.xy);
    ivec2 image_pixel = ivec2(region_origin.x + frag_pixel.x, region_origin.y + (image_size.y - 1 - frag_pixel.y));
    vec2 film_pixel = vec2(float(image_pixel.x), float(full_size.y - 1 - image_pixel.y));
    rng_pixel = uvec2(image_pixel);
    rng_seed_hash = random_seed_hash(seed);
    vec3 albedo_sum = vec3(0.0), normal_sum = vec3(0.0);
    float depth_sum = 0.0, hits = 0.0, taken = 0.0;
    work = 0;
    overflow = false;
    // One invocation does all the AOV samples, so they share the work bound: a pixel
    // stops taking samples while a whole one still fits (half the cap), and averages
    // those it took.
    for (int k = 0; k < aov_samples && work < work_cap / 2; k++) {
        work += SEGMENT_WORK;
        taken += 1.0;
        rng_sample = sample_start + uint(k);
        vec4 u = random4(0u, 0u);
        vec2 film = (film_pixel + u.xy) / vec2(full_size);
        vec2 lens = lens_radius * random_in_unit_disk(u.zw);
        vec3 origin = camera_origin + lens.x * camera_u + lens.y * camera_v;
        vec3 direction = normalize(camera_lower_left + film.x * camera_horizontal + film.y * camera_vertical - origin);
        float time = mix(shutter_open, shutter_close, random4(0u, 3u).x);
        Hit hit;
        if (!trace(origin, direction, time, INFINITY, hit)) {
            albedo_sum += clamp(sky_radiance(direction), 0.0, 1.0);
            continue;
        }
        Surface surface = surface_at(hit, origin, direction, time);
        uint material = material_offset + surface.material * uint(PACKED_MATERIAL_STRIDE);
        uvec4 material0 = packed_texel(material);
        uvec4 material2 = packed_texel(material + 2u);
        vec3 albedo = uintBitsToFloat(material0.yzw);
        if (material0.x == uint(MATERIAL_DIELECTRIC))
            albedo = vec3(1.0);
        else if (material0.x == uint(MATERIAL_EMISSIVE))
            albedo = clamp(uintBitsToFloat(packed_texel(material + 1u).xyz), 0.0, 1.0);
        else if (material2.y != NONE)
            albedo *= texture_value(material2.y, surface.position, surface.uv);
        albedo_sum += albedo;
        normal_sum += dot(direction, surface.shading) < 0.0 ? surface.shading : -surface.shading;
        depth_sum += hit.t;
        hits += 1.0;
    }
    float n = max(taken, 1.0);
    out_albedo_depth = vec4(albedo_sum / n, hits > 0.0 ? depth_sum / hits : 0.0);
    vec3 normal = hits > 0.0 ? normal_sum / hits : vec3(0.0);
    out_normal = vec4(dot(normal, normal) > 0.0 ? normalize(normal) : vec3(0.0), hits / n);
}
#else
// ---- main ------------------------------------------------------------------------

void main()
{
    ivec2 frag_pixel = ivec2(gl_FragCoord.xy);
    vec4 origin_state = texelFetch(state_origin, frag_pixel, 0);
    vec3 origin = origin_state.xyz;
    // How far the ray has gone straight on (through volume boundaries) since its last
    // scattering vertex: MIS weights need that vertex, origin - since_vertex * direction.
    float since_vertex = origin_state.w;
    vec3 direction = texelFetch(state_direction, frag_pixel, 0).xyz;
    vec4 throughput_state = texelFetch(state_throughput, frag_pixel, 0);
    vec3 throughput = throughput_state.rgb;
    // The BSDF density of the direction the path left its last vertex by, when that vertex
    // also sampled a light (then an emitter hit is weighted by MIS); 0 otherwise.
    float previous_pdf = throughput_state.w;
    vec3 radiance = texelFetch(state_radiance, frag_pixel, 0).rgb;
    uvec4 counters = texelFetch(state_counters, frag_pixel, 0);
    vec4 accumulated = texelFetch(state_accumulated, frag_pixel, 0);
    vec4 statistics = texelFetch(state_statistics, frag_pixel, 0);
    uint samples_started = counters.x;
    uint bounce = counters.y;
    uint media = counters.z;

    read_header();
#ifdef RTSPHERES_OMIT_DIRECT_LIGHT
    light_count = 0u;       // the host left light sampling out: nothing to sample
#else
    light_count = light_sampling != 0 || integrator == 1 ? light_count : 0u;
#endif

    // Full-image pixel, row 0 at the top: a crop or tile renders exactly the pixels
    // (and random numbers) of the full render.
    ivec2 image_pixel = ivec2(region_origin.x + frag_pixel.x, region_origin.y + (image_size.y - 1 - frag_pixel.y));
    vec2 film_pixel = vec2(float(image_pixel.x), float(full_size.y - 1 - image_pixel.y));
    rng_pixel = uvec2(image_pixel);
    rng_seed_hash = random_seed_hash(seed);
    rng_sample = sample_start + samples_started - 1u;

    work = 0;
    overflow = false;
    uint finished_here = 0u;
    for (;;) {
        if (bounce == 0u) {
            if (samples_started >= samples_per_pixel || work >= pass_work_budget)
                break;
            // Start the next sample: a camera ray through a jittered point of the pixel,
            // from a random point of the lens (thin-lens defocus).
            rng_sample = sample_start + samples_started;
            samples_started++;
            vec4 u = random4(0u, 0u);
            vec2 film = (film_pixel + u.xy) / vec2(full_size);
            vec2 lens = lens_radius * random_in_unit_disk(u.zw);
            origin = camera_origin + lens.x * camera_u + lens.y * camera_v;
            direction = normalize(camera_lower_left + film.x * camera_horizontal
                                  + film.y * camera_vertical - origin);
            throughput = vec3(1.0);
            radiance = vec3(0.0);
            media = camera_media;
            previous_pdf = 0.0;
            since_vertex = 0.0;
            bounce = 1u;
        }
        if (work >= pass_work_budget)
            break;
        work += SEGMENT_WORK;

        // The sample's moment within the shutter: the same for all its segments.
        float time = mix(shutter_open, shutter_close, random4(0u, 3u).x);
        Hit hit;
        bool hit_something = trace(origin, direction, time, INFINITY, hit);
        statistics.x += 1.0;
        bool path_done = false;
        vec4 u = random4(bounce, 1u);
        uint segment_bounce = bounce;     // the branches below may move bounce and direction on
        vec3 incoming = direction;

        // Direct light is gathered once per segment, after the branches below decide where
        // (one call site: see direct_light).
        bool want_direct = false;
        int direct_mode = 0;
        vec3 direct_point = vec3(0.0), direct_normal = vec3(0.0), direct_shading = vec3(0.0);
        vec3 direct_albedo = vec3(0.0), direct_weight = vec3(0.0);
        uint direct_material = 0u;
        bool direct_phase = false;

        // In a medium: scatter before the surface with probability 1 - exp(-density * t).
        bool scattered_in_medium = false;
#ifdef RTSPHERES_OMIT_VOLUMES
        uint medium = 0u;
#else
        uint medium = media_inner(media);
#endif
        if (medium != 0u) {
            uint medium_base = instance_offset + (medium - 1u) * uint(PACKED_INSTANCE_STRIDE);
            vec4 volume = packed_vec4(medium_base + 4u);
            float distance = -log(1.0 - random4(bounce, 4u).x) / volume.x;
            if (distance < hit.t) {
                scattered_in_medium = true;
                origin += distance * direction;
                throughput *= volume.yzw;
                since_vertex = 0.0;
                want_direct = light_count > 0u;
                direct_point = origin;
                direct_albedo = vec3(1.0);
                direct_phase = true;
                direct_weight = throughput;
                direction = random_unit_vector(u.xy);
                previous_pdf = light_count > 0u ? 1.0 / (4.0 * PI) : 0.0;
                bounce++;
                if (bounce > max_depth)
                    path_done = true;
            }
        }

        if (scattered_in_medium) {
            // done above
        } else if (!hit_something) {
            // Light sampling could have picked this sky direction too: weight by MIS.
            float weight = 1.0;
            if (previous_pdf > 0.0 && sky_type == SKY_ENVIRONMENT && light_count > 0u && integrator == 0) {
                uint last = light_count - 1u;
                if (packed_texel(light_offset + last * uint(PACKED_LIGHT_STRIDE)).x == uint(LIGHT_ENVIRONMENT))
                    weight = power_heuristic(previous_pdf, light_probability(last) * environment_pdf(last, direction));
            }
            radiance += throughput * sky_radiance(direction) * weight;
            path_done = true;
        } else {
            Surface surface = surface_at(hit, origin, direction, time);
            vec3 p = surface.position;
            bool front_face = dot(direction, surface.geometric) < 0.0;
            vec3 normal = front_face ? surface.geometric : -surface.geometric;
            vec3 shading = front_face ? surface.shading : -surface.shading;
            vec3 next_direction = direction;
            if (surface.volume_boundary) {
                // Crossing a medium's boundary: the ray goes on unchanged.
                media = front_face ? media_enter(media, surface.instance) : media_leave(media, surface.instance);
                since_vertex += hit.t;
            } else {
                since_vertex = 0.0;
                uint material = material_offset + surface.material * uint(PACKED_MATERIAL_STRIDE);
                uvec4 material0 = packed_texel(material);
                uvec4 material1 = packed_texel(material + 1u);
                uvec4 material2 = packed_texel(material + 2u);
                uint material_type = material0.x;
                vec3 albedo = uintBitsToFloat(material0.yzw);
#ifndef RTSPHERES_OMIT_TEXTURES
                if (material2.y != NONE)
                    albedo *= texture_value(material2.y, p, surface.uv);
#endif
                if (integrator == 1 && material_type != uint(MATERIAL_EMISSIVE)
                    && material_type != uint(MATERIAL_DIELECTRIC)) {
                    // Whitted: local Phong shading; metals also reflect, diffuse ends here.
                    want_direct = true;
                    direct_mode = 1;
                    direct_point = p;
                    direct_normal = normal;
                    direct_shading = shading;
                    direct_albedo = albedo;
                    direct_material = surface.material;
                    direct_weight = throughput;
                    if (material_type == uint(MATERIAL_METAL)) {
                        next_direction = reflect(direction, shading);
                        throughput *= albedo;
                        if (dot(next_direction, normal) <= 0.0)
                            path_done = true;
                    } else {
                        path_done = true;
                    }
                }
#ifndef RTSPHERES_OMIT_EMITTERS
                else if (material_type == uint(MATERIAL_EMISSIVE)) {
                    vec3 emission = uintBitsToFloat(material1.xyz);
#ifndef RTSPHERES_OMIT_TEXTURES
                    if (material2.z != NONE)
                        emission *= texture_value(material2.z, p, surface.uv);
#endif
                    // Light sampling could have found this emitter too: weight by MIS.
                    float weight = 1.0;
                    uint light = previous_pdf > 0.0 && hit.instance == NONE ? area_light_of(hit.primitive) : NONE;
                    if (light != NONE && light < light_count) {
                        vec3 vertex = origin - since_vertex * direction;
                        float light_pdf = light_probability(light) * light_direction_pdf(light, vertex, p, surface.geometric);
                        weight = power_heuristic(previous_pdf, light_pdf);
                    }
                    radiance += throughput * emission * weight;
                    path_done = true;
                }
#endif
                else if (material_type == uint(MATERIAL_LAMBERTIAN)) {
                    want_direct = light_count > 0u;
                    direct_point = p;
                    direct_normal = normal;
                    direct_shading = shading;
                    direct_albedo = albedo;
                    direct_weight = throughput;
                    // normal + a uniform unit vector is cosine-distributed about the normal.
                    next_direction = shading + random_unit_vector(u.xy);
                    float length_squared = dot(next_direction, next_direction);
                    next_direction = length_squared > 1e-12 ? next_direction * inversesqrt(length_squared) : shading;
                    if (dot(next_direction, normal) <= 0.0)
                        next_direction = reflect(next_direction, normal);
                    throughput *= albedo;
                    previous_pdf = light_count > 0u ? max(dot(shading, next_direction), 0.0) / PI : 0.0;
                } else if (material_type == uint(MATERIAL_METAL)) {
                    previous_pdf = 0.0;
                    float fuzz = uintBitsToFloat(material1.w);
                    vec3 reflected = reflect(direction, shading);
                    next_direction = normalize(reflected + fuzz * random_in_unit_sphere(u.xyz));
                    throughput *= albedo;
                    if (dot(next_direction, normal) <= 0.0)
                        path_done = true;   // scattered below the surface: absorbed
                } else {
                    previous_pdf = 0.0;
                    float ior = uintBitsToFloat(material2.x);
                    float eta_ratio = front_face ? 1.0 / ior : ior;
                    float cosine = min(dot(-direction, shading), 1.0);
                    float sine = sqrt(max(0.0, 1.0 - cosine * cosine));
                    if (eta_ratio * sine > 1.0 || schlick_reflectance(cosine, eta_ratio) > u.w)
                        next_direction = reflect(direction, shading);
                    else
                        next_direction = refract(direction, shading, eta_ratio);
                }
            }
            if (!path_done) {
                float side = dot(next_direction, normal) > 0.0 ? 1.0 : -1.0;
                origin = p + side * ray_offset(p) * normal;
                direction = next_direction;
                bounce++;
                if (bounce > max_depth) {
                    path_done = true;
                } else if (bounce > russian_roulette_depth && integrator == 0) {
                    // Unbiased: survivors carry the weight of the paths that ended.
                    float survival = clamp(max(throughput.r, max(throughput.g, throughput.b)), 0.05, 1.0);
                    if (random4(bounce, 2u).x >= survival)
                        path_done = true;
                    else
                        throughput /= survival;
                }
            }
        }
#ifndef RTSPHERES_OMIT_DIRECT_LIGHT
        if (want_direct)
            radiance += direct_weight * direct_light(direct_mode, direct_point, direct_normal, direct_shading,
                                                     -incoming, direct_albedo, direct_material, direct_phase, media,
                                                     time, segment_bounce);
#endif
        if (path_done) {
            accumulated += vec4(radiance, 1.0);
            float luminance = dot(radiance, vec3(0.2126, 0.7152, 0.0722));
            statistics.z += luminance * luminance;
            bounce = 0u;
            finished_here++;
        }
        if (overflow)
            break;
    }
    if (overflow) {
        statistics.y += 1.0;
        bounce = 0u;     // drop the broken path; the host reports the overflow as an error
    }
    if (samples_started < samples_per_pixel || bounce != 0u)
        atomicCounterIncrement(unfinished_pixels);
    for (uint i = 0u; i < finished_here; i++)
        atomicCounterIncrement(samples_finished);

    out_origin = vec4(origin, since_vertex);
    out_direction = vec4(direction, 0.0);
    out_throughput = vec4(throughput, previous_pdf);
    out_radiance = vec4(radiance, 0.0);
    out_counters = uvec4(samples_started, bounce, media, 0u);
    out_accumulated = accumulated;
    out_statistics = statistics;
}
#endif
