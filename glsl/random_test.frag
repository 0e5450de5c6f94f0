// random_test.frag: writes the renderer's random numbers (glsl/random.glsl) for one
// (sample, seed, dimension) to an RGBA32F image, one pixel per pixel, so tests can check
// their statistics on the device that renders.
layout(location = 0) out vec4 out_numbers;
uniform uint sample_index;
uniform uint seed;
uniform uint dimension;
uniform int image_height;

void main()
{
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    uvec2 image_pixel = uvec2(uint(pixel.x), uint(image_height - 1 - pixel.y));
    out_numbers = random_numbers(image_pixel, sample_index, random_seed_hash(seed), dimension);
}
