// random_test.frag: writes the renderer's sample values (glsl/random.glsl) for one
// (seed, dimension) to an RGBA32F image, so tests can check them on the device that
// renders. Two layouts:
//   fixed_pixel.x < 0: pixel (x, y) gets the values of its own pixel for sample_index
//   fixed_pixel.x >= 0: every output pixel shows fixed_pixel, output pixel (x, y) (row 0 at
//     the top) holding sample sample_index + y * width + x, for checks over samples
layout(location = 0) out vec4 out_numbers;
uniform uint sample_index;
uniform uint seed;
uniform uint dimension;
uniform int image_height;
uniform int image_width;
uniform ivec2 fixed_pixel;
uniform int sampler;

void main()
{
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    uvec2 image_pixel = uvec2(uint(pixel.x), uint(image_height - 1 - pixel.y));
    uint index = sample_index;
    if (fixed_pixel.x >= 0) {
        index = sample_index + image_pixel.y * uint(image_width) + image_pixel.x;
        image_pixel = uvec2(fixed_pixel);
    }
    out_numbers = random_numbers(image_pixel, index, random_seed_hash(seed), dimension, sampler);
}
