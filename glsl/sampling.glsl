// sampling.glsl: the current sample's stream of random numbers (glsl/random.glsl) and
// the warps that turn uniform numbers into directions and points.
//
// Random numbers are a pure function of (pixel, sample index, seed, bounce, stream): the
// same sample renders the same whatever the pass split or the machine. Each stream is one
// dimension of glsl/random.glsl, four numbers whose (x, y) and (z, w) are the stratified
// 2D pairs of the Sobol sampler: a 2D warp takes .xy or .zw. Streams of one
// bounce: 0 the camera ray (film, lens), 1 scattering, 2 Russian roulette, 3 the ray time
// (bounce 0), 4 the distance to a scattering event in a medium, 5 path tracing's light
// sample, 6 and 7 Whitted's light samples.

uvec2 rng_pixel;     // pixel in image coordinates (row 0 at the top)
uint rng_sample;     // absolute sample index
uint rng_seed_hash;

// The seeds of the streams every sample of the pixel draws at bounce 0 (glsl/random.glsl
// dimension_seeds), set once per pixel by begin_pixel_streams: the camera ray's (stream 0)
// and the ray time's (stream 3).
DimensionSeeds camera_stream_seeds, time_stream_seeds;

// Sets the per-pixel seeds above, once rng_pixel and rng_seed_hash are set.
void begin_pixel_streams()
{
    camera_stream_seeds = dimension_seeds(rng_pixel, rng_seed_hash, 0u);
    time_stream_seeds = dimension_seeds(rng_pixel, rng_seed_hash, 3u);
}

// Four uniform numbers in [0, 1) for one (bounce, stream) of the current sample.
vec4 random4(uint bounce, uint stream)
{
    return random_numbers(rng_pixel, rng_sample, rng_seed_hash, bounce * 8u + stream, sampler_kind());
}

// random4 of the current sample for a stream whose seeds the pixel keeps
// (begin_pixel_streams): camera_stream_seeds is random4(0u, 0u), time_stream_seeds
// random4(0u, 3u).
vec4 random4_seeded(DimensionSeeds seeds)
{
    return random_numbers_seeded(seeds, rng_pixel, rng_sample, rng_seed_hash, sampler_kind());
}

vec3 random_unit_vector(vec2 u)
{
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// The cube root of x in [0, 1]: a guess from the float's bits (its exponent divided by
// three) and two steps of Halley's method (cubic convergence: about 5e-2, 1e-4, then
// float precision). pow(x, 1.0 / 3.0) is exp2(log2(x) / 3) on llvmpipe, two polynomials
// and about 50 instructions in the tracer's loop (docs/performance.md, the log).
float cube_root(float x)
{
    float y = uintBitsToFloat(floatBitsToUint(x) / 3u + 709921077u);
    float y3 = y * y * y;
    y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
    y3 = y * y * y;
    y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
    return x > 0.0 ? y : 0.0;
}

vec3 random_in_unit_sphere(vec3 u)
{
    return random_unit_vector(u.xy) * cube_root(u.z);
}

vec2 random_in_unit_disk(vec2 u)
{
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    return vec2(r * cos(phi), r * sin(phi));
}

// A direction in the cone of half-angle acos(cos_max) about the unit axis, uniform in
// solid angle; cos_theta is its cosine to the axis.
vec3 random_in_cone(vec3 axis, float cos_max, vec2 u, out float cos_theta)
{
    cos_theta = 1.0 - u.x * (1.0 - cos_max);
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * PI * u.y;
    vec3 helper = abs(axis.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    vec3 tangent = normalize(cross(helper, axis));
    vec3 bitangent = cross(axis, tangent);
    return normalize(sin_theta * cos(phi) * tangent + sin_theta * sin(phi) * bitangent + cos_theta * axis);
}
