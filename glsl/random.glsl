// random.glsl: the renderer's random numbers, shared by the tracer and the RNG test
// shader (prepended to both when they are compiled).
//
// Every number is a pure function of (pixel, sample index, seed, dimension): no state
// is carried between passes, so the image does not depend on how work is split into
// passes, tiles or machines.

// A 4-in/4-out integer hash in the style of pcg4d (Jarzynski and Olano, "Hash Functions
// for GPU Rendering", JCGT 2020): two rounds of multiply-add mixing across components.
uvec4 hash4(uvec4 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    v ^= v >> 16u;
    return v;
}

// Spreads a user seed over all bits, so seeds 1 and 2 give unrelated streams.
uint random_seed_hash(uint seed)
{
    return hash4(uvec4(seed, 0x9e3779b9u, 0x85ebca6bu, 0xc2b2ae35u)).x;
}

// Four uniform numbers in [0, 1) (24-bit resolution) for one dimension of one sample.
vec4 random_numbers(uvec2 pixel, uint sample_index, uint seed_hash, uint dimension)
{
    uvec4 h = hash4(uvec4(pixel.x, pixel.y, sample_index, seed_hash ^ dimension));
    return vec4(h >> 8u) * (1.0 / 16777216.0);
}
