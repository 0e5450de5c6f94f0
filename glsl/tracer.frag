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

layout(location = 0) out vec4 out_origin;       // ray origin of the path in flight
layout(location = 1) out vec4 out_direction;    // ray direction (unit)
layout(location = 2) out vec4 out_throughput;   // path throughput so far
layout(location = 3) out vec4 out_radiance;     // radiance gathered by the path in flight
layout(location = 4) out uvec4 out_counters;    // x: samples started, y: bounce (0: no path in flight)
layout(location = 5) out vec4 out_accumulated;  // rgb: sum over finished samples, a: finished samples
layout(location = 6) out vec4 out_statistics;   // x: path segments traced, y: traversal overflows

uniform sampler2D state_origin;
uniform sampler2D state_direction;
uniform sampler2D state_throughput;
uniform sampler2D state_radiance;
uniform usampler2D state_counters;
uniform sampler2D state_accumulated;
uniform sampler2D state_statistics;

uniform usampler2D packed_scene;
uniform int packed_width_log2;

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
uniform int sky_type;
uniform vec3 sky_bottom;
uniform vec3 sky_top;
uniform uint seed;
uniform uint sample_start;
uniform uint samples_per_pixel;
uniform uint max_depth;
uniform uint russian_roulette_depth;
uniform int pass_work_budget;

layout(binding = 0, offset = 0) uniform atomic_uint unfinished_pixels;
layout(binding = 0, offset = 4) uniform atomic_uint samples_finished;

const float INFINITY = 1.0 / 0.0;
const float PI = 3.14159265358979;
const int TRAVERSAL_HARD_CAP = 60000;
const int SKY_CONSTANT = 1;

// ---- packed scene access ---------------------------------------------------------

uvec4 packed_texel(uint index)
{
    uint column = index & ((1u << uint(packed_width_log2)) - 1u);
    uint row = index >> uint(packed_width_log2);
    return texelFetch(packed_scene, ivec2(int(column), int(row)), 0);
}

vec3 packed_xyz(uvec4 texel) { return uintBitsToFloat(texel.xyz); }

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
};

// Nearest root of |origin + t*direction - center| = radius with t in (0, t_max), or
// INFINITY. direction is unit length. The discriminant is computed from the squared
// distance of the centre to the ray's closest point, which keeps float32 precise for the
// radius-1000 ground sphere (Haines et al., Ray Tracing Gems, ch. 7).
float intersect_sphere(vec3 center, float radius, vec3 origin, vec3 direction, float t_max)
{
    vec3 to_origin = origin - center;
    float b = dot(to_origin, direction);
    vec3 closest_offset = to_origin - b * direction;
    float discriminant = radius * radius - dot(closest_offset, closest_offset);
    if (discriminant < 0.0)
        return INFINITY;
    float root = sqrt(discriminant);
    float c = dot(to_origin, to_origin) - radius * radius;
    float q = -b - (b >= 0.0 ? root : -root);
    float t_near = c / q;
    float t_far = q;
    if (t_near > t_far) { float swap = t_near; t_near = t_far; t_far = swap; }
    if (t_near > 0.0 && t_near < t_max)
        return t_near;
    if (t_far > 0.0 && t_far < t_max)
        return t_far;
    return INFINITY;
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

uint primitive_offset;
uint primitive_count;
uint node_offset;
uint node_count;
uint material_offset;

// Tests one primitive (by slot); on a nearer hit updates hit.
void intersect_primitive(uint slot, vec3 origin, vec3 direction, inout Hit hit)
{
    uint base = primitive_offset + slot * uint(PACKED_PRIMITIVE_STRIDE);
    uvec4 head = packed_texel(base);
    if (head.x == uint(PRIMITIVE_SPHERE)) {
        vec4 sphere = uintBitsToFloat(packed_texel(base + 1u));
        float t = intersect_sphere(sphere.xyz, sphere.w, origin, direction, hit.t);
        if (t < hit.t) {
            hit.t = t;
            hit.primitive = slot;
        }
    }
}

// Finds the nearest hit along the ray by walking the BVH nearer child first with a small
// stack. work counts node visits and primitive tests; overflow is set when the hard cap
// cut the traversal short.
bool trace(vec3 origin, vec3 direction, out Hit hit, inout int work, inout bool overflow)
{
    hit.t = INFINITY;
    hit.primitive = 0u;
    if (node_count == 0u)
        return false;
    vec3 inverse_direction = 1.0 / direction;
    uvec4 root_min = packed_texel(node_offset);
    uvec4 root_max = packed_texel(node_offset + 1u);
    if (intersect_box(packed_xyz(root_min), packed_xyz(root_max), origin, inverse_direction, INFINITY) == INFINITY)
        return false;

    uint stack_node[BVH_MAX_DEPTH + 1];
    float stack_entry[BVH_MAX_DEPTH + 1];
    int stack_size = 0;
    uint node = 0u;
    float node_entry = 0.0;
    for (;;) {
        work++;
        if (work > TRAVERSAL_HARD_CAP) {
            overflow = true;
            break;
        }
        if (node_entry < hit.t) {
            uint base = node_offset + node * uint(PACKED_NODE_STRIDE);
            uvec4 low = packed_texel(base);
            uvec4 high = packed_texel(base + 1u);
            uint first = low.w;
            uint count = high.w;
            if (count > 0u) {
                for (uint slot = first; slot < first + count; slot++) {
                    work++;
                    intersect_primitive(slot, origin, direction, hit);
                }
            } else {
                uint left_base = node_offset + first * uint(PACKED_NODE_STRIDE);
                float left_entry = intersect_box(packed_xyz(packed_texel(left_base)),
                                                 packed_xyz(packed_texel(left_base + 1u)),
                                                 origin, inverse_direction, hit.t);
                float right_entry = intersect_box(packed_xyz(packed_texel(left_base + 2u)),
                                                  packed_xyz(packed_texel(left_base + 3u)),
                                                  origin, inverse_direction, hit.t);
                uint near_node = first, far_node = first + 1u;
                float near_entry = left_entry, far_entry = right_entry;
                if (right_entry < left_entry) {
                    near_node = first + 1u; far_node = first;
                    near_entry = right_entry; far_entry = left_entry;
                }
                if (near_entry < INFINITY) {
                    if (far_entry < INFINITY) {
                        stack_node[stack_size] = far_node;
                        stack_entry[stack_size] = far_entry;
                        stack_size++;
                    }
                    node = near_node;
                    node_entry = near_entry;
                    continue;
                }
            }
        }
        if (stack_size == 0)
            break;
        stack_size--;
        node = stack_node[stack_size];
        node_entry = stack_entry[stack_size];
    }
    return hit.t < INFINITY;
}

// ---- shading ---------------------------------------------------------------------

vec3 sky_radiance(vec3 direction)
{
    if (sky_type == SKY_CONSTANT)
        return sky_bottom;
    return mix(sky_bottom, sky_top, 0.5 * (direction.y + 1.0));
}

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

// ---- main ------------------------------------------------------------------------

void main()
{
    ivec2 frag_pixel = ivec2(gl_FragCoord.xy);
    vec3 origin = texelFetch(state_origin, frag_pixel, 0).xyz;
    vec3 direction = texelFetch(state_direction, frag_pixel, 0).xyz;
    vec3 throughput = texelFetch(state_throughput, frag_pixel, 0).rgb;
    vec3 radiance = texelFetch(state_radiance, frag_pixel, 0).rgb;
    uvec4 counters = texelFetch(state_counters, frag_pixel, 0);
    vec4 accumulated = texelFetch(state_accumulated, frag_pixel, 0);
    vec4 statistics = texelFetch(state_statistics, frag_pixel, 0);
    uint samples_started = counters.x;
    uint bounce = counters.y;

    uvec4 header_low = packed_texel(0u);
    uvec4 header_high = packed_texel(1u);
    material_offset = header_low.z;
    primitive_offset = header_high.x;
    primitive_count = header_high.y;
    node_offset = header_high.z;
    node_count = header_high.w;

    // Full-image pixel, row 0 at the top: a crop or tile renders exactly the pixels
    // (and random numbers) of the full render.
    ivec2 image_pixel = ivec2(region_origin.x + frag_pixel.x, region_origin.y + (image_size.y - 1 - frag_pixel.y));
    vec2 film_pixel = vec2(float(image_pixel.x), float(full_size.y - 1 - image_pixel.y));
    rng_pixel = uvec2(image_pixel);
    rng_seed_hash = random_seed_hash(seed);
    rng_sample = sample_start + samples_started - 1u;

    int work = 0;
    bool overflow = false;
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
            bounce = 1u;
        }
        if (work >= pass_work_budget)
            break;

        Hit hit;
        bool hit_something = trace(origin, direction, hit, work, overflow);
        statistics.x += 1.0;
        bool path_done = false;
        if (!hit_something) {
            radiance += throughput * sky_radiance(direction);
            path_done = true;
        } else {
            uint base = primitive_offset + hit.primitive * uint(PACKED_PRIMITIVE_STRIDE);
            uvec4 head = packed_texel(base);
            vec4 sphere = uintBitsToFloat(packed_texel(base + 1u));
            vec3 p = origin + hit.t * direction;
            vec3 outward_normal = (p - sphere.xyz) / sphere.w;
            bool front_face = dot(direction, outward_normal) < 0.0;
            vec3 normal = front_face ? outward_normal : -outward_normal;

            uint material = material_offset + head.y * uint(PACKED_MATERIAL_STRIDE);
            uvec4 material0 = packed_texel(material);
            uvec4 material1 = packed_texel(material + 1u);
            uint material_type = material0.x;
            vec3 albedo = uintBitsToFloat(material0.yzw);
            vec4 u = random4(bounce, 1u);
            vec3 next_direction = direction;
            if (material_type == uint(MATERIAL_EMISSIVE)) {
                radiance += throughput * uintBitsToFloat(material1.xyz);
                path_done = true;
            } else if (material_type == uint(MATERIAL_LAMBERTIAN)) {
                // normal + a uniform unit vector is cosine-distributed about the normal.
                next_direction = normal + random_unit_vector(u.xy);
                float length_squared = dot(next_direction, next_direction);
                next_direction = length_squared > 1e-12 ? next_direction * inversesqrt(length_squared) : normal;
                throughput *= albedo;
            } else if (material_type == uint(MATERIAL_METAL)) {
                float fuzz = uintBitsToFloat(material1.w);
                vec3 reflected = reflect(direction, normal);
                next_direction = normalize(reflected + fuzz * random_in_unit_sphere(u.xyz));
                throughput *= albedo;
                if (dot(next_direction, normal) <= 0.0)
                    path_done = true;   // scattered below the surface: absorbed
            } else {
                float ior = uintBitsToFloat(packed_texel(material + 2u).x);
                float eta_ratio = front_face ? 1.0 / ior : ior;
                float cosine = min(dot(-direction, normal), 1.0);
                float sine = sqrt(max(0.0, 1.0 - cosine * cosine));
                if (eta_ratio * sine > 1.0 || schlick_reflectance(cosine, eta_ratio) > u.w)
                    next_direction = reflect(direction, normal);
                else
                    next_direction = refract(direction, normal, eta_ratio);
            }
            if (!path_done) {
                float side = dot(next_direction, normal) > 0.0 ? 1.0 : -1.0;
                origin = p + side * ray_offset(p) * normal;
                direction = next_direction;
                bounce++;
                if (bounce > max_depth) {
                    path_done = true;
                } else if (bounce > russian_roulette_depth) {
                    // Unbiased: survivors carry the weight of the paths that ended.
                    float survival = clamp(max(throughput.r, max(throughput.g, throughput.b)), 0.05, 1.0);
                    if (random4(bounce, 2u).x >= survival)
                        path_done = true;
                    else
                        throughput /= survival;
                }
            }
        }
        if (path_done) {
            accumulated += vec4(radiance, 1.0);
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

    out_origin = vec4(origin, 0.0);
    out_direction = vec4(direction, 0.0);
    out_throughput = vec4(throughput, 0.0);
    out_radiance = vec4(radiance, 0.0);
    out_counters = uvec4(samples_started, bounce, 0u, 0u);
    out_accumulated = accumulated;
    out_statistics = statistics;
}
