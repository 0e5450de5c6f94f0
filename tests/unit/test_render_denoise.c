/* test_render_denoise.c: render_denoise() finds the denoiser's guides among a render's
 * layers by name, uses the per-pixel variance and the direct emission where a pixel has
 * the samples for them (render_denoise.h), and says which layer is missing. Each result is
 * checked against postprocess_denoise() called with the guides built by hand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "postprocess.h"
#include "render_denoise.h"
#include "support.h"

#define WIDTH 24
#define HEIGHT 16

/* The layer names of a render with --aovs and its direct emission, in its order. */
static const char *const layer_names[] = {"albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z",
                                          "depth.Z", "variance.Y", "emission.R", "emission.G", "emission.B"};
#define LAYERS ((int)(sizeof layer_names / sizeof layer_names[0]))

/* A beauty image (R, G, B, samples: every pixel samples) of a noisy lit plane with a light
 * on its right third, and its layers: albedo 0.5, normal +z, depth 2, a sample variance of
 * 0.04 (0 on the light), the light's emission. */
static void make_render(float samples, rt_image *beauty, rt_image *layers)
{
    *beauty = make_image(WIDTH, HEIGHT, 4, 0.0f);
    *layers = make_image(WIDTH, HEIGHT, LAYERS, 0.0f);
    static const char *const beauty_names[4] = {"R", "G", "B", "samples"};
    for (int c = 0; c < 4; c++)
        snprintf(beauty->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", beauty_names[c]);
    for (int c = 0; c < LAYERS; c++)
        snprintf(layers->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", layer_names[c]);
    uint32_t state = 12345;
    for (int i = 0; i < WIDTH * HEIGHT; i++) {
        bool light = i % WIDTH >= 2 * WIDTH / 3;
        float *b = beauty->pixels + 4 * i, *l = layers->pixels + LAYERS * i;
        for (int c = 0; c < 3; c++) {
            state = state * 1664525u + 1013904223u;
            b[c] = light ? 4.0f : 0.3f + 0.1f * ((float)(state >> 8) / 16777216.0f - 0.5f);
            l[c] = 0.5f;
            l[8 + c] = light ? 4.0f : 0.0f;
        }
        b[3] = samples;
        l[5] = 1.0f;
        l[6] = 2.0f;
        l[7] = light ? 0.0f : 0.04f;
    }
}

/* The channels [first, first + count) of image as an image of their own. */
static rt_image channels(const rt_image *image, int first, int count)
{
    rt_image out = make_image(image->width, image->height, count, 0.0f);
    for (int i = 0; i < image->width * image->height; i++)
        for (int c = 0; c < count; c++)
            out.pixels[i * count + c] = image->pixels[i * image->channels + first + c];
    return out;
}

/* Denoises the beauty of a render of samples per pixel both ways (render_denoise, and by
 * hand with the variance and emission guides when with_variance / with_emission) and
 * checks they agree to the bit. */
static void check_against_hand(float samples, bool with_variance, bool with_emission)
{
    rt_image beauty, layers;
    make_render(samples, &beauty, &layers);
    rt_image ours = channels(&beauty, 0, 3), theirs = channels(&beauty, 0, 3);
    rt_image albedo = channels(&layers, 0, 3), normal = channels(&layers, 3, 3), depth = channels(&layers, 6, 1);
    rt_image variance = channels(&layers, 7, 1), emission = channels(&layers, 8, 3);
    for (int i = 0; i < WIDTH * HEIGHT; i++)
        variance.pixels[i] /= samples - 1;
    postprocess_denoise_guides guides = {.albedo = &albedo, .normal = &normal, .depth = &depth,
                                         .variance = with_variance ? &variance : NULL,
                                         .emission = with_emission ? &emission : NULL};
    rt_error error = {{0}};
    assert_int_equal(render_denoise(&ours, &beauty, &layers, &error), RT_OK);
    assert_int_equal(postprocess_denoise(&theirs, &guides, NULL, &error), RT_OK);
    assert_memory_equal(ours.pixels, theirs.pixels, sizeof(float) * 3 * WIDTH * HEIGHT);
    rt_image *images[] = {&beauty, &layers, &ours, &theirs, &albedo, &normal, &depth, &variance, &emission};
    for (size_t k = 0; k < sizeof images / sizeof images[0]; k++)
        image_free(images[k]);
}

static void test_guides_by_the_samples_a_pixel_has(void **state)
{
    (void)state;
    /* Below 4 samples neither the variance nor the emission; from 4 the variance; from 8
     * both. */
    check_against_hand(3, false, false);
    check_against_hand(RENDER_DENOISE_VARIANCE_MIN_SAMPLES, true, false);
    check_against_hand(RENDER_DENOISE_EMISSION_MIN_SAMPLES - 1, true, false);
    check_against_hand(RENDER_DENOISE_EMISSION_MIN_SAMPLES, true, true);
    check_against_hand(64, true, true);
}

static void test_the_light_keeps_its_radiance(void **state)
{
    (void)state;
    rt_image beauty, layers;
    make_render(64, &beauty, &layers);
    rt_image colour = channels(&beauty, 0, 3);
    assert_int_equal(render_denoise(&colour, &beauty, &layers, NULL), RT_OK);
    for (int i = 0; i < WIDTH * HEIGHT; i++)
        if (i % WIDTH >= 2 * WIDTH / 3)
            assert_relative(colour.pixels[3 * i], 4.0, 1e-3);   /* only the surface beside it mixes in */
    image_free(&colour);
    image_free(&beauty);
    image_free(&layers);
}

static void test_a_missing_guide_is_named(void **state)
{
    (void)state;
    static const struct {
        const char *layer;
        const char *named;
    } cases[] = {{"albedo.G", "albedo.R/G/B"}, {"normal.Z", "normal.X/Y/Z"}, {"depth.Z", "depth.Z"}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        rt_image beauty, layers;
        make_render(16, &beauty, &layers);
        for (int c = 0; c < LAYERS; c++)
            if (strcmp(layers.channel_names[c], cases[k].layer) == 0)
                snprintf(layers.channel_names[c], IMAGE_CHANNEL_NAME_MAX, "other");
        rt_image colour = channels(&beauty, 0, 3), before = channels(&beauty, 0, 3);
        rt_error error = {{0}};
        assert_int_equal(render_denoise(&colour, &beauty, &layers, &error), RT_ERROR_INPUT);
        assert_non_null(strstr(error.message, cases[k].named));
        assert_non_null(strstr(error.message, "--aovs"));
        assert_memory_equal(colour.pixels, before.pixels, sizeof(float) * 3 * WIDTH * HEIGHT);
        image_free(&colour);
        image_free(&before);
        image_free(&beauty);
        image_free(&layers);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_guides_by_the_samples_a_pixel_has),
        cmocka_unit_test(test_the_light_keeps_its_radiance),
        cmocka_unit_test(test_a_missing_guide_is_named),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
