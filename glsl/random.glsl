// random.glsl: the renderer's sample values, shared by the tracer and the sampler test
// shader (prepended to both when they are compiled).
//
// Every value is a pure function of (pixel, sample index, seed, dimension): no state is
// carried between passes, so the image does not depend on how work is split into passes,
// tiles, sample ranges or machines, and resumed or merged renders are exact.
//
// Two samplers (docs/sampling.md says when to use which):
//   SAMPLER_SOBOL (default): padded, shuffled, Owen-scrambled Sobol points. Each
//     dimension gives four numbers made of two 2D pairs; each pair holds the first two
//     dimensions of the Sobol sequence (a (0,2)-sequence), with the sample index shuffled
//     and the two coordinates scrambled by hashes of (pixel, seed, pair). Any 2^k
//     consecutive samples from 0 are stratified in every 2^a x 2^(k-a) grid of each pair
//     (tests/unit/test_random.c checks it), pairs are independent of one another (the
//     padding of pbrt-v4's PaddedSobolSampler), and pixels are independent of one another.
//   SAMPLER_INDEPENDENT: independent uniform numbers from one hash (the samples rtspheres
//     drew before the Sobol sampler); the same expectation, more noise.
// The sampler is chosen by the `sampler` value the including shader defines (a uniform
// or a compiled-in constant).

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

// A random permutation of 32-bit words in which bit k of the result depends only on bits
// 0..k of x: applied to a bit-reversed number (whose bit 0 is its leading binary digit)
// it is a nested uniform (Owen) scramble, which keeps a digital net a net. The form of
// the Laine-Karras hash, with the constants of N. Vegdahl's improved variant (2021).
uint owen_permute_reversed(uint x, uint seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

// The second Sobol dimension in bit-reversed form: its generator matrix is Pascal's
// triangle mod 2, so bit j of the result is the XOR of index bits k with j a bit-subset
// of k (Lucas' theorem); five shift-and-mask steps compute all 32 at once.
uint sobol_second_reversed(uint index)
{
    index ^= (index >> 1u) & 0x55555555u;
    index ^= (index >> 2u) & 0x33333333u;
    index ^= (index >> 4u) & 0x0f0f0f0fu;
    index ^= (index >> 8u) & 0x00ff00ffu;
    index ^= (index >> 16u) & 0x0000ffffu;
    return index;
}

// One scrambled 2D Sobol point of sample sample_index, for the pair whose hashes are
// seeds (shuffle, first and second coordinate's scramble), as 24-bit numbers in [0, 1).
// The index is shuffled by a nested uniform scramble, which maps the first 2^k indices to
// one aligned block of 2^k Sobol indices, so every power-of-two prefix stays a net.
vec2 sobol_pair(uint sample_index, uvec3 seeds)
{
    uint index = bitfieldReverse(owen_permute_reversed(bitfieldReverse(sample_index), seeds.x));
    uint first = bitfieldReverse(owen_permute_reversed(index, seeds.y));
    uint second = bitfieldReverse(owen_permute_reversed(sobol_second_reversed(index), seeds.z));
    return vec2(uvec2(first, second) >> 8u) * (1.0 / 16777216.0);
}

// What random_numbers hashes from (pixel, seed, dimension) alone, apart from the sample:
// the Sobol sampler's seeds of the dimension's two pairs (shuffle, first and second
// coordinate's scramble). A dimension that every sample of a pixel draws (the camera's)
// takes them once per pixel (glsl/sampling.glsl): LLVM does not hoist them out of the
// tracer's loop, where they cost 70 instructions a segment (docs/performance.md, the log).
struct DimensionSeeds {
    uint dimension;
    uvec3 first_pair;
    uvec3 second_pair;
};

DimensionSeeds dimension_seeds(uvec2 pixel, uint seed_hash, uint dimension)
{
    DimensionSeeds seeds;
    seeds.dimension = dimension;
    seeds.first_pair = hash4(uvec4(pixel.x, pixel.y, seed_hash, 2u * dimension)).xyz;
    seeds.second_pair = hash4(uvec4(pixel.x, pixel.y, seed_hash, 2u * dimension + 1u)).xyz;
    return seeds;
}

// random_numbers for the dimension whose seeds are given (dimension_seeds of the same
// pixel and seed_hash): the same four numbers.
vec4 random_numbers_seeded(DimensionSeeds seeds, uvec2 pixel, uint sample_index, uint seed_hash, int sampler_kind)
{
    if (sampler_kind == SAMPLER_INDEPENDENT) {
        uvec4 h = hash4(uvec4(pixel.x, pixel.y, sample_index, seed_hash ^ seeds.dimension));
        return vec4(h >> 8u) * (1.0 / 16777216.0);
    }
    return vec4(sobol_pair(sample_index, seeds.first_pair), sobol_pair(sample_index, seeds.second_pair));
}

// Four numbers in [0, 1) (24-bit resolution) for one dimension of one sample: with the
// Sobol sampler, (x, y) and (z, w) are two independent stratified 2D pairs, so a 2D
// sampling routine should take one pair, never (y, z).
vec4 random_numbers(uvec2 pixel, uint sample_index, uint seed_hash, uint dimension, int sampler_kind)
{
    return random_numbers_seeded(dimension_seeds(pixel, seed_hash, dimension), pixel, sample_index, seed_hash,
                                 sampler_kind);
}
