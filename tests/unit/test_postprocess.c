/* test_postprocess.c: blur, denoiser, tone mapping and montage on small hand-made images
 * whose right answers are known: constant and noisy flat regions, hard edges between
 * regions of different normals or depths, a checker texture, grey ramps and labelled tiles.
 * The denoiser tests print what they measured (variance ratios, side means). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "luminance.h"
#include "postprocess.h"
#include "support.h"

/* ---------------------------------------------------------------------------------- */
/* Helpers                                                                              */

static float *at(const rt_image *image, int x, int y, int c)
{
    return &image->pixels[((size_t)y * image->width + x) * image->channels + c];
}

/* A small deterministic generator (xorshift64*), so every run sees the same noise. */
typedef struct random_state {
    uint64_t state;
} random_state;

static double random_uniform(random_state *random)
{
    random->state ^= random->state >> 12;
    random->state ^= random->state << 25;
    random->state ^= random->state >> 27;
    return ((random->state * 0x2545F4914F6CDD1DULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* A standard normal sample (Box-Muller). */
static double random_normal(random_state *random)
{
    double u = random_uniform(random), v = random_uniform(random);
    return sqrt(-2.0 * log(1.0 - u)) * cos(2.0 * M_PI * v);
}

/* Mean and variance of channel c over the region x0 <= x < x1, y0 <= y < y1. */
static void region_statistics(const rt_image *image, int c, int x0, int y0, int x1, int y1, double *mean,
                              double *variance)
{
    double sum = 0, square_sum = 0;
    int n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            double v = *at(image, x, y, c);
            sum += v;
            square_sum += v * v;
            n++;
        }
    *mean = sum / n;
    if (variance != NULL)
        *variance = square_sum / n - *mean * *mean;
}

static double region_mean(const rt_image *image, int c, int x0, int y0, int x1, int y1)
{
    double mean;
    region_statistics(image, c, x0, y0, x1, y1, &mean, NULL);
    return mean;
}

/* ---------------------------------------------------------------------------------- */
/* Gaussian blur                                                                        */

static void test_blur_keeps_a_constant_image(void **state)
{
    (void)state;
    rt_image image = make_image(19, 7, 4, 0.25f);
    for (int y = 0; y < 7; y++)
        for (int x = 0; x < 19; x++)
            *at(&image, x, y, 3) = (float)(x + y);  /* alpha: must not be touched */
    rt_error error;
    assert_int_equal(postprocess_gaussian_blur(&image, 3.0f, 2, &error), RT_OK);
    for (int y = 0; y < 7; y++)
        for (int x = 0; x < 19; x++) {
            for (int c = 0; c < 3; c++)
                assert_close(*at(&image, x, y, c), 0.25, 1e-6);
            assert_close(*at(&image, x, y, 3), x + y, 0);
        }
    image_free(&image);
}

static void test_blur_keeps_the_mean_and_reduces_noise(void **state)
{
    (void)state;
    rt_image image = make_image(37, 23, 3, 0.0f);
    random_state random = {12345};
    for (size_t i = 0; i < 37 * 23 * 3; i++)
        image.pixels[i] = (float)(0.5 + 0.2 * random_normal(&random));
    double means[3], variances[3];
    for (int c = 0; c < 3; c++)
        region_statistics(&image, c, 0, 0, 37, 23, &means[c], &variances[c]);
    rt_error error;
    assert_int_equal(postprocess_gaussian_blur(&image, 2.0f, 3, &error), RT_OK);
    for (int c = 0; c < 3; c++) {
        double mean, variance;
        region_statistics(&image, c, 0, 0, 37, 23, &mean, &variance);
        assert_close(mean, means[c], 1e-5);
        /* Three passes of sigma 2 are one of sigma 3.46: white noise keeps about
         * 1 / (4 pi sigma^2) = 1/150 of its variance. */
        assert_true(variance < variances[c] / 50);
        print_message("blur: channel %d mean %.7f -> %.7f, variance %.5f -> %.6f (%.0fx lower)\n", c, means[c], mean,
                      variances[c], variance, variances[c] / variance);
    }
    image_free(&image);
}

static void test_blur_wider_than_the_image_keeps_the_mean(void **state)
{
    (void)state;
    rt_image image = make_image(5, 3, 3, 0.0f);
    *at(&image, 0, 0, 0) = 15.0f;  /* mean of channel 0: 1 */
    rt_error error;
    assert_int_equal(postprocess_gaussian_blur(&image, 40.0f, 1, &error), RT_OK);
    assert_close(region_mean(&image, 0, 0, 0, 5, 3), 1.0, 1e-5);
    /* A kernel this wide spreads the spike evenly. */
    assert_close(*at(&image, 4, 2, 0), 1.0, 0.01);
    image_free(&image);
}

static void test_blur_zero_sigma_or_passes_is_a_no_op(void **state)
{
    (void)state;
    rt_image image = make_image(4, 4, 3, 0.0f);
    *at(&image, 1, 1, 0) = 1.0f;
    rt_error error;
    assert_int_equal(postprocess_gaussian_blur(&image, 0.0f, 3, &error), RT_OK);
    assert_int_equal(postprocess_gaussian_blur(&image, 2.0f, 0, &error), RT_OK);
    assert_close(*at(&image, 1, 1, 0), 1.0, 0);
    assert_close(*at(&image, 0, 0, 0), 0.0, 0);
    image_free(&image);
}

static void test_blur_rejects_bad_arguments(void **state)
{
    (void)state;
    rt_image image = make_image(4, 4, 3, 0.5f);
    rt_error error;
    assert_int_equal(postprocess_gaussian_blur(&image, -1.0f, 1, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "sigma"));
    assert_int_equal(postprocess_gaussian_blur(&image, NAN, 1, &error), RT_ERROR_INPUT);
    assert_int_equal(postprocess_gaussian_blur(&image, 1e9f, 1, &error), RT_ERROR_INPUT);
    assert_int_equal(postprocess_gaussian_blur(&image, 1.0f, -1, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "passes"));
    rt_image empty = {0};
    assert_int_equal(postprocess_gaussian_blur(&empty, 1.0f, 1, &error), RT_ERROR_INPUT);
    image_free(&image);
}

/* ---------------------------------------------------------------------------------- */
/* Denoiser                                                                             */

#define SIZE 64
#define HALF (SIZE / 2)

/* A synthetic render: colour, albedo, normal and depth buffers of one size. */
typedef struct buffers {
    rt_image colour, albedo, normal, depth;
} buffers;

/* A flat grey world: colour value + noise of standard deviation noise_sd (3 channels
 * independent), albedo 1, normal +z, depth 2. */
static buffers make_flat(float value, float noise_sd, uint64_t seed)
{
    buffers b = {
        .colour = make_image(SIZE, SIZE, 3, value),
        .albedo = make_image(SIZE, SIZE, 3, 1.0f),
        .normal = make_image(SIZE, SIZE, 3, 0.0f),
        .depth = make_image(SIZE, SIZE, 1, 2.0f),
    };
    random_state random = {seed};
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            *at(&b.normal, x, y, 2) = 1.0f;
            for (int c = 0; c < 3; c++)
                *at(&b.colour, x, y, c) += (float)(noise_sd * random_normal(&random));
        }
    return b;
}

/* Left half (x < HALF) at value left, right half at right, each with noise of sd
 * noise_sd relative to its value; the halves differ in normal (+z against +x) when
 * normals_differ, in depth (2 against 3) when depths_differ. */
static buffers make_edge(float left, float right, float noise_sd, bool normals_differ, bool depths_differ)
{
    buffers b = make_flat(0.0f, 0.0f, 1);
    random_state random = {777};
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            bool is_right = x >= HALF;
            float value = is_right ? right : left;
            for (int c = 0; c < 3; c++)
                *at(&b.colour, x, y, c) = value * (float)(1.0 + noise_sd * random_normal(&random));
            if (is_right && normals_differ) {
                *at(&b.normal, x, y, 0) = 1.0f;
                *at(&b.normal, x, y, 2) = 0.0f;
            }
            if (is_right && depths_differ)
                *at(&b.depth, x, y, 0) = 3.0f;
        }
    return b;
}

static void free_buffers(buffers *b)
{
    image_free(&b->colour);
    image_free(&b->albedo);
    image_free(&b->normal);
    image_free(&b->depth);
}

/* The denoiser with guides given by value: GUIDES(.albedo = &albedo, ...). */
#define GUIDES(...) ((postprocess_denoise_guides){__VA_ARGS__})
static rt_status denoise_guided(rt_image *colour, postprocess_denoise_guides guides,
                                const postprocess_denoise_options *options, rt_error *error)
{
    return postprocess_denoise(colour, &guides, options, error);
}

static rt_status denoise(buffers *b, const postprocess_denoise_options *options)
{
    rt_error error = {{0}};
    postprocess_denoise_guides guides = {.albedo = &b->albedo, .normal = &b->normal, .depth = &b->depth};
    rt_status status = postprocess_denoise(&b->colour, &guides, options, &error);
    if (status != RT_OK)
        print_error("postprocess_denoise: %s\n", error.message);
    return status;
}

static void test_denoise_smooths_a_flat_noisy_region(void **state)
{
    (void)state;
    buffers b = make_flat(0.5f, 0.1f, 99);
    double mean_before, variance_before, mean_after, variance_after;
    region_statistics(&b.colour, 1, 0, 0, SIZE, SIZE, &mean_before, &variance_before);
    assert_int_equal(denoise(&b, NULL), RT_OK);
    region_statistics(&b.colour, 1, 0, 0, SIZE, SIZE, &mean_after, &variance_after);
    print_message("denoise flat: variance %.6f -> %.8f (%.0fx lower), mean %.5f -> %.5f\n", variance_before,
                  variance_after, variance_before / variance_after, mean_before, mean_after);
    assert_true(variance_after * 5 <= variance_before);
    assert_relative(mean_after, 0.5, 0.02);
    free_buffers(&b);
}

static void test_denoise_without_guides_still_smooths(void **state)
{
    (void)state;
    buffers b = make_flat(0.5f, 0.1f, 5);
    double before, after, mean;
    region_statistics(&b.colour, 0, 0, 0, SIZE, SIZE, &mean, &before);
    rt_error error;
    assert_int_equal(postprocess_denoise(&b.colour, NULL, NULL, &error), RT_OK);
    region_statistics(&b.colour, 0, 0, 0, SIZE, SIZE, &mean, &after);
    print_message("denoise flat, no guides: variance %.0fx lower\n", before / after);
    assert_true(after * 5 <= before);
    free_buffers(&b);
}

/* Checks a denoised edge image: each side's mean within 2% of its noise-free value, the
 * mean of the column on either side of the edge within 5% of its side's value (bleeding
 * would pull it towards the other side), and each side's variance at least 5x lower. */
static void check_edge(const char *what, const rt_image *before, const rt_image *after, float left, float right)
{
    double left_mean, right_mean, left_before, right_before, left_after, right_after;
    region_statistics(before, 0, 0, 0, HALF, SIZE, &left_mean, &left_before);
    region_statistics(before, 0, HALF, 0, SIZE, SIZE, &right_mean, &right_before);
    region_statistics(after, 0, 0, 0, HALF, SIZE, &left_mean, &left_after);
    region_statistics(after, 0, HALF, 0, SIZE, SIZE, &right_mean, &right_after);
    double left_column = region_mean(after, 0, HALF - 1, 0, HALF, SIZE);
    double right_column = region_mean(after, 0, HALF, 0, HALF + 1, SIZE);
    print_message("denoise %s edge: side means %.4f | %.4f (true %.2f | %.2f), columns at the edge %.4f | %.4f, "
                  "variance %.0fx | %.0fx lower\n",
                  what, left_mean, right_mean, left, right, left_column, right_column, left_before / left_after,
                  right_before / right_after);
    assert_relative(left_mean, left, 0.02);
    assert_relative(right_mean, right, 0.02);
    assert_relative(left_column, left, 0.05);
    assert_relative(right_column, right, 0.05);
    assert_true(left_after * 5 <= left_before);
    assert_true(right_after * 5 <= right_before);
}

static void test_denoise_keeps_an_edge_between_normals(void **state)
{
    (void)state;
    buffers b = make_edge(0.2f, 0.8f, 0.2f, true, false);
    rt_image before = make_image(SIZE, SIZE, 3, 0.0f);
    memcpy(before.pixels, b.colour.pixels, sizeof(float) * SIZE * SIZE * 3);
    assert_int_equal(denoise(&b, NULL), RT_OK);
    check_edge("normal", &before, &b.colour, 0.2f, 0.8f);
    image_free(&before);
    free_buffers(&b);
}

static void test_denoise_keeps_an_edge_between_depths(void **state)
{
    (void)state;
    buffers b = make_edge(0.2f, 0.8f, 0.2f, false, true);
    rt_image before = make_image(SIZE, SIZE, 3, 0.0f);
    memcpy(before.pixels, b.colour.pixels, sizeof(float) * SIZE * SIZE * 3);
    assert_int_equal(denoise(&b, NULL), RT_OK);
    check_edge("depth", &before, &b.colour, 0.2f, 0.8f);
    image_free(&before);
    free_buffers(&b);
}

/* With the colour weight switched off (a huge sigma), the guides alone must hold the
 * edge: every pixel next to it stays within 5% of its side (noise-free input). */
static void test_denoise_guides_alone_hold_an_edge(void **state)
{
    (void)state;
    postprocess_denoise_options options = postprocess_denoise_options_defaults();
    options.sigma_colour = 1e9f;
    for (int guide = 0; guide < 2; guide++) {
        buffers b = make_edge(0.2f, 0.8f, 0.0f, guide == 0, guide == 1);
        assert_int_equal(denoise(&b, &options), RT_OK);
        for (int y = 0; y < SIZE; y++) {
            assert_relative(*at(&b.colour, HALF - 1, y, 0), 0.2, 0.05);
            assert_relative(*at(&b.colour, HALF, y, 0), 0.8, 0.05);
        }
        free_buffers(&b);
    }
    /* And without any guide the same filter does blur it: the test can fail. */
    buffers b = make_edge(0.2f, 0.8f, 0.0f, false, false);
    assert_int_equal(denoise(&b, &options), RT_OK);
    assert_true(*at(&b.colour, HALF - 1, 10, 0) > 0.2 * 1.05);
    free_buffers(&b);
}

/* Pixels that hit nothing (depth 0 or infinite) never mix with pixels that hit. */
static void test_denoise_keeps_sky_and_surface_apart(void **state)
{
    (void)state;
    postprocess_denoise_options options = postprocess_denoise_options_defaults();
    options.sigma_colour = 1e9f;
    buffers b = make_edge(0.2f, 0.8f, 0.1f, false, false);
    for (int y = 0; y < SIZE; y++)
        for (int x = HALF; x < SIZE; x++)
            *at(&b.depth, x, y, 0) = (y % 2) ? INFINITY : 0.0f;
    assert_int_equal(denoise(&b, &options), RT_OK);
    double left_column = region_mean(&b.colour, 0, HALF - 1, 0, HALF, SIZE);
    double right_column = region_mean(&b.colour, 0, HALF, 0, HALF + 1, SIZE);
    print_message("denoise sky edge: columns at the edge %.4f | %.4f (true 0.2 | 0.8)\n", left_column, right_column);
    assert_relative(left_column, 0.2, 0.05);
    assert_relative(right_column, 0.8, 0.05);
    free_buffers(&b);
}

/* A tilted plane (depth growing linearly across the image, normals equal) is one surface:
 * the depth weight measures the distance from the plane, so it smooths like a flat one. */
static void test_denoise_smooths_a_tilted_plane(void **state)
{
    (void)state;
    buffers b = make_flat(0.5f, 0.1f, 4242);
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            *at(&b.depth, x, y, 0) = 2.0f + 0.05f * (float)x + 0.02f * (float)y;
    double before, after, mean;
    region_statistics(&b.colour, 0, 0, 0, SIZE, SIZE, &mean, &before);
    assert_int_equal(denoise(&b, NULL), RT_OK);
    region_statistics(&b.colour, 0, 0, 0, SIZE, SIZE, &mean, &after);
    print_message("denoise tilted plane: variance %.0fx lower\n", before / after);
    assert_true(after * 5 <= before);
    free_buffers(&b);
}

/* A checker texture (albedo 0.2 and 0.8 in 4x4 cells) under uniform light with 10%
 * noise: demodulation filters the light, so the texture's contrast survives exactly. */
static void test_denoise_demodulation_keeps_a_texture(void **state)
{
    (void)state;
    postprocess_denoise_options options = postprocess_denoise_options_defaults();
    buffers b = make_flat(0.0f, 0.0f, 1);
    random_state random = {31337};
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            float albedo = ((x / 4 + y / 4) % 2) ? 0.8f : 0.2f;
            for (int c = 0; c < 3; c++) {
                *at(&b.albedo, x, y, c) = albedo;
                *at(&b.colour, x, y, c) = albedo * (float)(1.0 + 0.1 * random_normal(&random));
            }
        }
    /* Light cells against dark cells, and the noise of the light, before and after; the
     * pixels along cell borders, which a bleed would darken in light cells and brighten in
     * dark ones. */
    double light_before = 0, dark_before = 0, light_after = 0, dark_after = 0, noise_before = 0, noise_after = 0;
    double worst = 0, worst_before = 0, border_error[2] = {0, 0};
    int border_count[2] = {0, 0};
    rt_image before = make_image(SIZE, SIZE, 3, 0.0f);
    memcpy(before.pixels, b.colour.pixels, sizeof(float) * SIZE * SIZE * 3);
    assert_int_equal(denoise(&b, &options), RT_OK);
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            float albedo = *at(&b.albedo, x, y, 0);
            double v0 = *at(&before, x, y, 0), v1 = *at(&b.colour, x, y, 0);
            if (albedo > 0.5f) {
                light_before += v0;
                light_after += v1;
            } else {
                dark_before += v0;
                dark_after += v1;
            }
            noise_before += (v0 / albedo - 1) * (v0 / albedo - 1);
            noise_after += (v1 / albedo - 1) * (v1 / albedo - 1);
            worst = fmax(worst, fabs(v1 / albedo - 1));
            worst_before = fmax(worst_before, fabs(v0 / albedo - 1));
            if (x % 4 == 0 || x % 4 == 3 || y % 4 == 0 || y % 4 == 3) {
                border_error[albedo > 0.5f] += v1 / albedo - 1;
                border_count[albedo > 0.5f]++;
            }
        }
    double contrast_before = light_before / dark_before, contrast_after = light_after / dark_after;
    double dark_border = border_error[0] / border_count[0], light_border = border_error[1] / border_count[1];
    print_message("denoise checker: contrast %.4f -> %.4f (true 4), lighting variance %.0fx lower, worst pixel "
                  "%.2f%% -> %.2f%% off, cell borders %+.2f%% (dark) %+.2f%% (light)\n", contrast_before, contrast_after,
                  noise_before / noise_after, 100 * worst_before, 100 * worst, 100 * dark_border, 100 * light_border);
    assert_relative(contrast_after, 4.0, 0.02);
    assert_true(noise_after * 5 <= noise_before);
    /* No cell bleeds into its neighbours: every pixel within 5% of its cell's true value,
     * and the pixels along the borders within 1% on average (a bleed of the 4x brighter
     * cells shows as tens of %). */
    assert_true(worst < 0.05);
    assert_true(fabs(dark_border) < 0.01 && fabs(light_border) < 0.01);
    image_free(&before);

    /* Without the albedo image the same noise blurs the checker: the test can fail. */
    options.sigma_colour = 1e9f;
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.normal = &b.normal, .depth = &b.depth), &options, NULL), RT_OK);
    light_after = dark_after = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            *(((x / 4 + y / 4) % 2) ? &light_after : &dark_after) += *at(&b.colour, x, y, 0);
    assert_true(light_after / dark_after < 3.0);
    free_buffers(&b);
}

static void test_denoise_keeps_other_channels(void **state)
{
    (void)state;
    buffers b = make_flat(0.5f, 0.1f, 8);
    rt_image rgba = make_image(SIZE, SIZE, 4, 7.0f);
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            for (int c = 0; c < 3; c++)
                *at(&rgba, x, y, c) = *at(&b.colour, x, y, c);
    rt_error error;
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth};
    assert_int_equal(postprocess_denoise(&rgba, &guides, NULL, &error), RT_OK);
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            assert_close(*at(&rgba, x, y, 3), 7.0, 0);
    image_free(&rgba);
    free_buffers(&b);
}

/* A lit flat surface (0.2, noise sd 0.05) in one plane with one albedo, and on it a light:
 * columns x >= HALF + 1 are the light (10, no noise), column HALF sees it over 30% of the
 * pixel (0.3 x 10 of emission, plus 0.7 of the surface). Only the colour tells the light
 * from the surface: the emission image is what a render's camera rays saw of it at once. */
static buffers make_light_edge(rt_image *emission)
{
    buffers b = make_flat(0.2f, 0.05f, 41);
    *emission = make_image(SIZE, SIZE, 3, 0.0f);
    for (int y = 0; y < SIZE; y++)
        for (int x = HALF; x < SIZE; x++)
            for (int c = 0; c < 3; c++) {
                float direct = x == HALF ? 3.0f : 10.0f;
                *at(emission, x, y, c) = direct;
                *at(&b.colour, x, y, c) = x == HALF ? direct + 0.7f * *at(&b.colour, x, y, c) : direct;
            }
    return b;
}

static void test_denoise_leaves_the_emission_seen_at_once(void **state)
{
    (void)state;
    rt_image emission;
    buffers b = make_light_edge(&emission);
    double truth = 3.0 + 0.7 * 0.2, before, after, variance;
    region_statistics(&b.colour, 0, HALF, 0, HALF + 1, SIZE, &before, &variance);
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth,
                                         .emission = &emission};
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    region_statistics(&b.colour, 0, HALF, 0, HALF + 1, SIZE, &after, &variance);
    double surface_before, surface_variance_before, surface, surface_variance;
    print_message("denoise with emission: the partly covered column %.4f -> %.4f (true %.4f)\n", before, after,
                  truth);
    assert_relative(after, truth, 0.01);
    /* The light keeps its radiance and the surface is still smoothed. */
    region_statistics(&b.colour, 0, HALF + 2, 0, SIZE, SIZE, &surface, &surface_variance);
    assert_relative(surface, 10.0, 1e-4);
    rt_image fresh_emission;
    buffers fresh = make_light_edge(&fresh_emission);
    image_free(&fresh_emission);
    region_statistics(&fresh.colour, 0, 0, 0, HALF - 2, SIZE, &surface_before, &surface_variance_before);
    region_statistics(&b.colour, 0, 0, 0, HALF - 2, SIZE, &surface, &surface_variance);
    assert_true(surface_variance * 5 <= surface_variance_before);
    assert_relative(surface, 0.2, 0.02);
    free_buffers(&fresh);
    free_buffers(&b);
    /* Without it the column is averaged with the surface and the light beside it as if its
     * difference were noise, and ends far from its value: what --denoise did to the edges of
     * the lights it saw before it had the emission. */
    rt_image unused;
    b = make_light_edge(&unused);
    guides.emission = NULL;
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    region_statistics(&b.colour, 0, HALF, 0, HALF + 1, SIZE, &after, &variance);
    print_message("denoise without emission: the partly covered column -> %.4f\n", after);
    assert_true(fabs(after - truth) > 0.1 * truth);
    image_free(&unused);
    image_free(&emission);
    free_buffers(&b);
}

/* A flat noisy surface (0.5, noise sd 0.1) with a 2 x 2 highlight of 5 that only the colour
 * shows (a light seen in a mirror: the guides see the mirror), noise-free; variance is the
 * variance of each pixel's mean, as a render knows it: 0.01 on the surface, 0 on the
 * highlight. */
static buffers make_highlight(rt_image *variance)
{
    buffers b = make_flat(0.5f, 0.1f, 17);
    *variance = make_image(SIZE, SIZE, 1, 0.01f);
    for (int y = HALF; y < HALF + 2; y++)
        for (int x = HALF; x < HALF + 2; x++) {
            *at(variance, x, y, 0) = 0.0f;
            for (int c = 0; c < 3; c++)
                *at(&b.colour, x, y, c) = 5.0f;
        }
    return b;
}

static void test_denoise_keeps_a_highlight_its_variance_vouches_for(void **state)
{
    (void)state;
    rt_image variance;
    buffers b = make_highlight(&variance);
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth,
                                         .variance = &variance};
    double before, surface_variance_before, highlight, surface, surface_variance, unused;
    region_statistics(&b.colour, 0, 0, 0, SIZE, HALF - 2, &before, &surface_variance_before);
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    region_statistics(&b.colour, 0, HALF, HALF, HALF + 2, HALF + 2, &highlight, &unused);
    region_statistics(&b.colour, 0, 0, 0, SIZE, HALF - 2, &surface, &surface_variance);
    print_message("denoise with the render's variance: highlight 5 -> %.4f, surface variance %.0fx lower\n",
                  highlight, surface_variance_before / surface_variance);
    assert_relative(highlight, 5.0, 0.02);
    assert_true(surface_variance * 5 <= surface_variance_before);
    assert_relative(surface, 0.5, 0.02);
    free_buffers(&b);
    /* Measured around each pixel, the noise looks as large as the highlight itself and the
     * highlight is spread into the surface. */
    rt_image unused_variance;
    b = make_highlight(&unused_variance);
    image_free(&unused_variance);
    guides.variance = NULL;
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    region_statistics(&b.colour, 0, HALF, HALF, HALF + 2, HALF + 2, &highlight, &unused);
    print_message("denoise measuring the noise around each pixel: highlight 5 -> %.4f\n", highlight);
    assert_true(highlight < 0.8 * 5.0);
    /* A variance of -1 means "unknown": the noise is then measured around the pixel, the
     * same image as without the guide. */
    rt_image unknown = make_image(SIZE, SIZE, 1, -1.0f);
    buffers again = make_highlight(&unused_variance);
    image_free(&unused_variance);
    guides.variance = &unknown;
    assert_int_equal(postprocess_denoise(&again.colour, &guides, NULL, NULL), RT_OK);
    assert_memory_equal(again.colour.pixels, b.colour.pixels, sizeof(float) * SIZE * SIZE * 3);
    image_free(&unknown);
    image_free(&variance);
    free_buffers(&again);
    free_buffers(&b);
}

/* The region x0 <= x < x1, y0 <= y < y1 of image, as an image of its own. */
static rt_image region_of(const rt_image *image, int x0, int y0, int x1, int y1)
{
    rt_image block;
    assert_int_equal(image_create(&block, x1 - x0, y1 - y0, image->channels, NULL), RT_OK);
    size_t row = (size_t)(x1 - x0) * image->channels;
    for (int y = y0; y < y1; y++)
        memcpy(block.pixels + (size_t)(y - y0) * row, at(image, x0, y, 0), row * sizeof(float));
    return block;
}

/* Denoises (blur false) or blurs the core region [x0, x1) x [y0, y1) (core[4]) of the inputs
 * taken with halo more pixels on every side (within the image), and returns how many of
 * the core's values differ from whole's (the whole image done at once). */
static int block_differences(const rt_image inputs[6], const rt_image *whole, const int core[4], int halo, bool blur)
{
    int width = inputs[0].width, height = inputs[0].height;
    int x0 = core[0] - halo > 0 ? core[0] - halo : 0, x1 = core[2] + halo < width ? core[2] + halo : width;
    int y0 = core[1] - halo > 0 ? core[1] - halo : 0, y1 = core[3] + halo < height ? core[3] + halo : height;
    rt_image block[6];
    for (int i = 0; i < 6; i++)
        block[i] = region_of(&inputs[i], x0, y0, x1, y1);
    postprocess_denoise_guides guides = {.albedo = &block[1], .normal = &block[2], .depth = &block[3],
                                         .emission = &block[4], .variance = &block[5]};
    if (blur)
        assert_int_equal(postprocess_gaussian_blur(&block[0], 2.5f, 2, NULL), RT_OK);
    else
        assert_int_equal(postprocess_denoise(&block[0], &guides, NULL, NULL), RT_OK);
    int differences = 0;
    for (int y = core[1]; y < core[3]; y++)
        for (int x = core[0]; x < core[2]; x++)
            for (int c = 0; c < 3; c++)
                differences += memcmp(at(&block[0], x - x0, y - y0, c), at(whole, x, y, c), sizeof(float)) != 0;
    for (int i = 0; i < 6; i++)
        image_free(&block[i]);
    return differences;
}

/* Fills the six inputs of the denoiser (colour, albedo, normal, depth, emission, variance;
 * width x height) with all it meets: noise, normal and depth edges, sky, texture,
 * emission, and the variance known in some blocks only (the rest measured around them),
 * so that step 5's choice is made in some places and not in others. */
static void make_denoiser_inputs(int width, int height, rt_image inputs[6])
{
    const int channels[6] = {3, 3, 3, 1, 3, 1};
    for (int i = 0; i < 6; i++)
        inputs[i] = make_image(width, height, channels[i], 0.0f);
    random_state random = {0x9e3779b97f4a7c15ULL};
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            bool sky = (y / 37 + x / 9) % 5 == 0;
            int patch = (y / 23 + x / 7) % 3;
            for (int c = 0; c < 3; c++) {
                *at(&inputs[0], x, y, c) = (float)(0.5 + 0.1 * patch + 0.2 * random_normal(&random));
                *at(&inputs[1], x, y, c) = (x + y) % 4 == 0 ? 0.2f : 0.8f;
                *at(&inputs[4], x, y, c) = (y % 31 == 0 && x % 5 == 0) ? 3.0f : 0.0f;
            }
            *at(&inputs[2], x, y, patch) = 1.0f;
            *at(&inputs[3], x, y, 0) = sky ? 0.0f : (float)(2.0 + 0.01 * y + (patch == 2 ? 1.0 : 0.0));
            *at(&inputs[5], x, y, 0) = (x / 29 + y / 31) % 3 == 0 ? -1.0f : (float)(0.01 * (1 + patch));
        }
}

/* A block of the image denoised (or blurred) with postprocess_*_reach() more pixels on
 * every side is the whole image's pixels bit for bit: what a render in tiles relies on to
 * post-process its output block by block (core/render_job_tiles.c). The image is wider
 * than the denoiser's runs of 256 pixels (core/postprocess_denoise.c, DENOISE_RUN), and blocks
 * start at other columns than the whole image, so a pixel is computed at another place in
 * a run, in a vector lane or not. With a halo too short the pixels differ, so the
 * comparison can see a wrong reach. */
static void test_blocks_with_the_reach_are_exact(void **state)
{
    (void)state;
    enum { WIDTH = 300, HEIGHT = 260 };
    rt_image inputs[6];
    make_denoiser_inputs(WIDTH, HEIGHT, inputs);
    rt_image denoised = region_of(&inputs[0], 0, 0, WIDTH, HEIGHT);
    rt_image blurred = region_of(&inputs[0], 0, 0, WIDTH, HEIGHT);
    postprocess_denoise_guides guides = {.albedo = &inputs[1], .normal = &inputs[2], .depth = &inputs[3],
                                         .emission = &inputs[4], .variance = &inputs[5]};
    assert_int_equal(postprocess_denoise(&denoised, &guides, NULL, NULL), RT_OK);
    assert_int_equal(postprocess_gaussian_blur(&blurred, 2.5f, 2, NULL), RT_OK);
    int reach = postprocess_denoise_reach(NULL), blur_reach = postprocess_blur_reach(2.5f, 2);
    assert_int_equal(reach, 76);
    assert_int_equal(blur_reach, 16);
    assert_int_equal(postprocess_blur_reach(0.0f, 3), 0);
    assert_int_equal(postprocess_denoise_reach(&(postprocess_denoise_options){.iterations = 2}), 20);
    /* Bands of whole rows, and blocks: one across the second run's start (x 256), one at
     * the right edge, one column in the middle. */
    const int cores[][4] = {{0, 100, WIDTH, 130}, {0, 0, WIDTH, 20}, {0, 230, WIDTH, HEIGHT}, {0, 70, WIDTH, 71},
                            {230, 40, 270, 90}, {280, 150, WIDTH, 200}, {131, 0, 132, HEIGHT}};
    for (size_t i = 0; i < sizeof cores / sizeof cores[0]; i++) {
        assert_int_equal(block_differences(inputs, &denoised, cores[i], reach, false), 0);
        assert_int_equal(block_differences(inputs, &blurred, cores[i], blur_reach, true), 0);
    }
    int short_denoise = block_differences(inputs, &denoised, cores[4], 20, false);
    int short_blur = block_differences(inputs, &blurred, cores[4], 4, true);
    print_message("blocks with a short halo: %d denoised and %d blurred values differ\n", short_denoise, short_blur);
    assert_true(short_denoise > 0 && short_blur > 0);
    for (int i = 0; i < 6; i++)
        image_free(&inputs[i]);
    image_free(&denoised);
    image_free(&blurred);
}

/* The denoiser of postprocess.h with its default options, written out pixel by pixel in
 * doubles with libm's exp, as a reference for core/postprocess_denoise.c's vector loops (planes,
 * runs of pixels, float sums, its own exponential). g's images may be NULL. */
typedef struct reference_pixel {
    double normal[3], albedo[3], depth, gradient[2];
    bool hit;
} reference_pixel;

static double reference_guide_weight(const reference_pixel *p, const reference_pixel *q, int dx, int dy,
                                     const postprocess_denoise_guides *g)
{
    if (p->hit != q->hit)
        return 0.0;
    if (!p->hit)
        return 1.0;
    double exponent = 0.0;
    for (int c = 0; c < 3; c++) {
        if (g->normal != NULL)
            exponent += (q->normal[c] - p->normal[c]) * (q->normal[c] - p->normal[c]) / (0.3 * 0.3);
        if (g->albedo != NULL)
            exponent += (q->albedo[c] - p->albedo[c]) * (q->albedo[c] - p->albedo[c]) / (0.1 * 0.1);
    }
    if (g->depth != NULL)
        exponent += fabs(q->depth - (p->depth + p->gradient[0] * dx + p->gradient[1] * dy)) / (0.02 * p->depth);
    return exp(-exponent);
}

/* Step 5 of postprocess.h for the reference, after an iteration whose demodulated image is
 * signal (self: each pixel's dF/dy): the risk, averaged along x and then y with the
 * Gaussian and the guides' weights, and where lower than best_risk, best takes the image. */
static void reference_choose(const rt_image *colour, const postprocess_denoise_guides *g,
                             const reference_pixel *pixels, const double *signal, const double *divisor,
                             const double *self, double *risk, double *along_x, double *best_risk, double *best)
{
    int width = colour->width, height = colour->height;
    for (int p = 0; p < width * height; p++) {
        float v = g->variance->pixels[p * g->variance->channels];
        double difference[3];
        for (int c = 0; c < 3; c++) {
            double direct = g->emission != NULL ? g->emission->pixels[p * g->emission->channels + c] : 0.0;
            difference[c] = signal[3 * p + c] * divisor[3 * p + c] + direct - colour->pixels[p * colour->channels + c];
        }
        double luminance = luminance_double(difference[0], difference[1], difference[2]);
        risk[p] = v >= 0.0f && isfinite(v) ? luminance * luminance - v + 2.0 * v * self[p] : NAN;
    }
    for (int pass = 0; pass < 2; pass++)
        for (int y = 0; y < height; y++)
            for (int x = 0; x < width; x++) {
                int p = y * width + x;
                double sum = 0.0, weight_sum = 0.0;
                for (int t = -9; t <= 9; t++) {
                    int qx = pass == 0 ? x + t : x, qy = pass == 0 ? y : y + t;
                    if (qx < 0 || qx >= width || qy < 0 || qy >= height)
                        continue;
                    int q = qy * width + qx;
                    double w = exp(-t * t / (2.0 * 4.5 * 4.5))
                             * reference_guide_weight(&pixels[p], &pixels[q], qx - x, qy - y, g);
                    sum += w * (pass == 0 ? risk[q] : along_x[q]);
                    weight_sum += w;
                }
                if (pass == 0) {
                    along_x[p] = sum / weight_sum;
                } else if (sum / weight_sum < best_risk[p]) {
                    best_risk[p] = sum / weight_sum;
                    for (int c = 0; c < 3; c++) {
                        double direct = g->emission != NULL ? g->emission->pixels[p * g->emission->channels + c] : 0.0;
                        best[3 * p + c] = signal[3 * p + c] * divisor[3 * p + c] + direct;
                    }
                }
            }
}

static void reference_denoise(rt_image *colour, const postprocess_denoise_guides *g)
{
    int width = colour->width, height = colour->height, n = width * height;
    reference_pixel *pixels = calloc((size_t)n, sizeof *pixels);
    double *signal = calloc((size_t)n * 3, sizeof(double)), *next = calloc((size_t)n * 3, sizeof(double));
    double *variance = calloc((size_t)n, sizeof(double)), *next_variance = calloc((size_t)n, sizeof(double));
    double *blurred = calloc((size_t)n, sizeof(double)), *divisor = calloc((size_t)n * 3, sizeof(double));
    bool *measured = calloc((size_t)n, sizeof(bool));
    double *self = calloc((size_t)n, sizeof(double)), *risk = calloc((size_t)n, sizeof(double));
    double *along_x = calloc((size_t)n, sizeof(double)), *best_risk = calloc((size_t)n, sizeof(double));
    double *best = calloc((size_t)n * 3, sizeof(double));
    assert_true(self && risk && along_x && best_risk && best);
    for (int i = 0; i < n; i++) {
        self[i] = 1.0;
        best_risk[i] = INFINITY;
    }
    assert_non_null(pixels);
    assert_true(signal && next && variance && next_variance && blurred && divisor && measured);
#define INSIDE(x, y) ((x) >= 0 && (x) < width && (y) >= 0 && (y) < height)
    for (int i = 0; i < n; i++) {
        float z = g->depth != NULL ? g->depth->pixels[i * g->depth->channels] : 1.0f;
        pixels[i].hit = isfinite(z) && z > 0.0f;
        pixels[i].depth = pixels[i].hit ? z : 0.0;
        for (int c = 0; c < 3; c++) {
            pixels[i].normal[c] = g->normal != NULL ? g->normal->pixels[i * g->normal->channels + c] : 0.0;
            pixels[i].albedo[c] = g->albedo != NULL ? g->albedo->pixels[i * g->albedo->channels + c] : 0.0;
            divisor[3 * i + c] = g->albedo != NULL ? fmax(pixels[i].albedo[c], 0.01f) : 1.0;
            double direct = g->emission != NULL ? g->emission->pixels[i * g->emission->channels + c] : 0.0;
            signal[3 * i + c] = (colour->pixels[i * colour->channels + c] - direct) / divisor[3 * i + c];
        }
        float v = g->variance != NULL ? g->variance->pixels[i * g->variance->channels] : -1.0f;
        measured[i] = !(v >= 0.0f && isfinite(v));
        for (int c = 0; c < 3 && !measured[i]; c++)
            variance[i] += v / (divisor[3 * i + c] * divisor[3 * i + c]) / 3.0;
    }
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            reference_pixel *p = &pixels[y * width + x];
            for (int axis = 0; axis < 2 && p->hit; axis++) {
                int bx = x - (axis == 0), by = y - (axis == 1), ax = x + (axis == 0), ay = y + (axis == 1);
                bool before = INSIDE(bx, by) && pixels[by * width + bx].hit;
                bool after = INSIDE(ax, ay) && pixels[ay * width + ax].hit;
                double backward = before ? p->depth - pixels[by * width + bx].depth : 0.0;
                double forward = after ? pixels[ay * width + ax].depth - p->depth : 0.0;
                p->gradient[axis] = before && after ? (fabs(backward) < fabs(forward) ? backward : forward)
                                    : before        ? backward
                                                    : forward;
            }
        }
    for (int y = 0; y < height; y++)   /* the noise measured over 7x7 where the guide has none */
        for (int x = 0; x < width; x++) {
            int p = y * width + x;
            double w_sum = 0, sum[3] = {0}, square[3] = {0};
            for (int dy = -3; dy <= 3 && measured[p]; dy++)
                for (int dx = -3; dx <= 3; dx++) {
                    if (!INSIDE(x + dx, y + dy))
                        continue;
                    int q = p + dy * width + dx;
                    double w = reference_guide_weight(&pixels[p], &pixels[q], dx, dy, g);
                    w_sum += w;
                    for (int c = 0; c < 3; c++) {
                        sum[c] += w * signal[3 * q + c];
                        square[c] += w * signal[3 * q + c] * signal[3 * q + c];
                    }
                }
            for (int c = 0; c < 3 && measured[p]; c++)
                variance[p] += fmax(0.0, square[c] / w_sum - (sum[c] / w_sum) * (sum[c] / w_sum)) / 3.0;
        }
    static const double b3[5] = {1.0 / 16, 1.0 / 4, 3.0 / 8, 1.0 / 4, 1.0 / 16};
    for (int i = 0; i < 5; i++) {
        int step = 1 << i;
        for (int y = 0; y < height; y++)
            for (int x = 0; x < width; x++) {
                int p = y * width + x;
                double sum = 0, w_sum = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++)
                        if (INSIDE(x + dx, y + dy) && pixels[p + dy * width + dx].hit == pixels[p].hit) {
                            double w = (dx == 0 ? 0.5 : 0.25) * (dy == 0 ? 0.5 : 0.25);
                            sum += w * variance[p + dy * width + dx];
                            w_sum += w;
                        }
                blurred[p] = sum / w_sum;
            }
        for (int y = 0; y < height; y++)
            for (int x = 0; x < width; x++) {
                int p = y * width + x;
                const double *cp = &signal[3 * p];
                double sigma = measured[p] ? 4.0 : 4.0 * ldexp(1.0, i > 1 ? 1 - i : 0);
                double level = (fabs(cp[0]) + fabs(cp[1]) + fabs(cp[2])) / 3.0;
                double scale = sigma * sqrt(blurred[p]) + 1e-3 * level + 1e-8;
                double w_sum = 0, sum[3] = {0}, v_sum = 0;
                for (int j = -2; j <= 2; j++)
                    for (int k = -2; k <= 2; k++) {
                        int dx = k * step, dy = j * step;
                        if (!INSIDE(x + dx, y + dy))
                            continue;
                        int q = p + dy * width + dx;
                        double w = b3[k + 2] * b3[j + 2];
                        if (q != p) {
                            double d2 = 0;
                            for (int c = 0; c < 3; c++)
                                d2 += (signal[3 * q + c] - cp[c]) * (signal[3 * q + c] - cp[c]);
                            w *= reference_guide_weight(&pixels[p], &pixels[q], dx, dy, g) * exp(-sqrt(d2 / 3) / scale);
                        }
                        w_sum += w;
                        v_sum += w * w * variance[q];
                        for (int c = 0; c < 3; c++)
                            sum[c] += w * signal[3 * q + c];
                    }
                for (int c = 0; c < 3; c++)
                    next[3 * p + c] = sum[c] / w_sum;
                next_variance[p] = v_sum / (w_sum * w_sum);
                self[p] *= b3[2] * b3[2] / w_sum;
            }
        double *swap = signal;
        signal = next;
        next = swap;
        swap = variance;
        variance = next_variance;
        next_variance = swap;
        if (g->variance != NULL)
            reference_choose(colour, g, pixels, signal, divisor, self, risk, along_x, best_risk, best);
    }
    for (int i = 0; i < n; i++)   /* remodulated or chosen; next: the residual, input less denoised */
        for (int c = 0; c < 3; c++) {
            double direct = g->emission != NULL ? g->emission->pixels[i * g->emission->channels + c] : 0.0;
            signal[3 * i + c] = best_risk[i] < INFINITY ? best[3 * i + c]
                                                        : signal[3 * i + c] * divisor[3 * i + c] + direct;
            next[3 * i + c] = colour->pixels[i * colour->channels + c] - signal[3 * i + c];
        }
    for (int y = 0; y < height; y++)   /* the bias check over 3x3 */
        for (int x = 0; x < width; x++) {
            int p = y * width + x, count = 0;
            double residual[3] = {0}, v_sum = 0;
            bool known = g->variance != NULL;
            for (int dy = -1; dy <= 1 && known; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    if (INSIDE(x + dx, y + dy)) {
                        int q = p + dy * width + dx;
                        float v = g->variance->pixels[q * g->variance->channels];
                        known = known && v >= 0.0f && isfinite(v);
                        v_sum += v;
                        for (int c = 0; c < 3; c++)
                            residual[c] += next[3 * q + c] / 9.0;
                        count++;
                    }
            double share = 0.0;
            if (known) {
                for (int c = 0; c < 3; c++)
                    residual[c] *= 9.0 / count;
                double pool_sum = 0;   /* the 5x5 mean variance, a floor under the 3x3's */
                int pool_count = 0;
                for (int dy = -2; dy <= 2; dy++)
                    for (int dx = -2; dx <= 2; dx++)
                        if (INSIDE(x + dx, y + dy)) {
                            float v = g->variance->pixels[(p + dy * width + dx) * g->variance->channels];
                            if (v >= 0.0f && isfinite(v)) {
                                pool_sum += v;
                                pool_count++;
                            }
                        }
                v_sum = fmax(v_sum, count * pool_sum / pool_count);
                double luminance = fabs(luminance_double(residual[0], residual[1], residual[2]));
                double z = luminance / (sqrt(v_sum) / count + 1e-20);
                share = z <= 1.0 ? 0.0 : z >= 3.0 ? 1.0 : (z - 1.0) / 2.0;
            }
            for (int c = 0; c < 3; c++)
                colour->pixels[p * colour->channels + c] =
                    (float)fmax(fmin(signal[3 * p + c], 0.0), signal[3 * p + c] + share * residual[c]);
        }
#undef INSIDE
    free(pixels);
    free(signal);
    free(next);
    free(variance);
    free(next_variance);
    free(blurred);
    free(divisor);
    free(measured);
    free(self);
    free(risk);
    free(along_x);
    free(best_risk);
    free(best);
}

/* postprocess_denoise() gives the reference's image (above) to float rounding, with every
 * guide and with none, on an image wider than its runs of 256 pixels. */
static void test_denoise_matches_the_reference(void **state)
{
    (void)state;
    rt_image inputs[6];
    make_denoiser_inputs(290, 70, inputs);
    const postprocess_denoise_guides cases[2] = {
        {.albedo = &inputs[1], .normal = &inputs[2], .depth = &inputs[3], .emission = &inputs[4],
         .variance = &inputs[5]},
        {0},
    };
    for (int i = 0; i < 2; i++) {
        rt_image denoised = region_of(&inputs[0], 0, 0, inputs[0].width, inputs[0].height);
        rt_image reference = region_of(&inputs[0], 0, 0, inputs[0].width, inputs[0].height);
        assert_int_equal(postprocess_denoise(&denoised, &cases[i], NULL, NULL), RT_OK);
        reference_denoise(&reference, &cases[i]);
        double largest = 0.0, change = 0.0;
        for (size_t k = 0; k < (size_t)denoised.width * denoised.height * 3; k++) {
            largest = fmax(largest, fabs(denoised.pixels[k] - reference.pixels[k]) / (1.0 + fabs(reference.pixels[k])));
            change = fmax(change, fabs(inputs[0].pixels[k] - reference.pixels[k]));
        }
        print_message("denoise against the reference, %s guides: largest difference %.3g (the filter moved "
                      "values by up to %.3g)\n", i == 0 ? "all" : "no", largest, change);
        assert_true(largest < 2e-5);
        assert_true(change > 0.1);
        image_free(&denoised);
        image_free(&reference);
    }
    for (int i = 0; i < 6; i++)
        image_free(&inputs[i]);
}

/* Fine detail that no guide shows (a texture seen in a mirror: the same normal, depth and
 * albedo all over) under noise of the same size, with the render's variance: a checker of
 * cell px cells, +-amplitude around 0.5, on the left half of a noisy flat surface. Returns
 * the checker's contrast after denoising (the light cells' mean less the dark ones'; 2
 * amplitude before) and how many times lower the variance of the right half is. */
static void denoise_hidden_checker(int cell, float amplitude, double *contrast, double *flat_variance_ratio)
{
    buffers b = make_flat(0.5f, 0.05f, 77);
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < HALF; x++)
            for (int c = 0; c < 3; c++)
                *at(&b.colour, x, y, c) += ((x / cell + y / cell) % 2 == 0 ? amplitude : -amplitude);
    rt_image variance = make_image(SIZE, SIZE, 1, 0.0025f);
    double flat_before, flat_variance_before;
    region_statistics(&b.colour, 1, HALF + 8, 0, SIZE, SIZE, &flat_before, &flat_variance_before);
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth,
                                         .variance = &variance};
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    double light = 0.0, dark = 0.0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < HALF - 8; x++)
            *((x / cell + y / cell) % 2 == 0 ? &light : &dark) += *at(&b.colour, x, y, 1);
    *contrast = (light - dark) / (SIZE * (HALF - 8) / 2);
    double flat, flat_variance;
    region_statistics(&b.colour, 1, HALF + 8, 0, SIZE, SIZE, &flat, &flat_variance);
    *flat_variance_ratio = flat_variance_before / flat_variance;
    image_free(&variance);
    free_buffers(&b);
}

/* Step 5 (postprocess.h): where the later iterations' longer steps wash out detail no guide
 * shows, the risk keeps an earlier iteration's image, and the flat half keeps nearly all
 * of its smoothing. Measured: a checker of 2-pixel cells +-0.1 (two noise standard
 * deviations) keeps a contrast of 0.092 of 0.2 (0.051 without the choice), 4-pixel cells
 * +-0.05 keep 0.055 of 0.1 (0.034); the flat half's variance 174-176x lower (178-179x). */
static void test_denoise_keeps_detail_the_guides_do_not_show(void **state)
{
    (void)state;
    double contrast, ratio;
    denoise_hidden_checker(2, 0.1f, &contrast, &ratio);
    print_message("a checker no guide shows, 2-pixel cells +-0.1: contrast %.4f of 0.2, the flat half's variance "
                  "%.0fx lower\n", contrast, ratio);
    assert_true(contrast > 0.08 && contrast < 0.2);
    assert_true(ratio > 150);
    denoise_hidden_checker(4, 0.05f, &contrast, &ratio);
    print_message("4-pixel cells +-0.05: contrast %.4f of 0.1, the flat half's variance %.0fx lower\n", contrast,
                  ratio);
    assert_true(contrast > 0.045 && contrast < 0.1);
    assert_true(ratio > 150);
}

/* A dim surface as 4 samples a pixel see it: most pixels 0 (no sample found light), some
 * lit, with the render's variance. The bias check gives back a mean residual where it
 * stands out, which beside a lit pixel is negative; it must not take a pixel below 0 (it
 * took some to -0.044 before it was bounded). The mean comes out 14% low (0.086 of 0.100):
 * a pixel all of whose samples were 0 has a variance of 0, so its colour weight lets little
 * light in, while the lit pixels give theirs away; a known limit at so few samples
 * (docs/sampling.md, "Denoising", has what was tried), bounded here at 20%. */
static void test_denoise_never_makes_a_colour_negative(void **state)
{
    (void)state;
    buffers b = make_flat(0.0f, 0.0f, 5);
    rt_image variance = make_image(SIZE, SIZE, 1, 0.0f);
    random_state random = {99};
    double input_sum = 0.0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            int lit = 0;
            for (int sample = 0; sample < 4; sample++)
                lit += random_uniform(&random) < 0.1;
            float value = 0.25f * lit;   /* each lit sample 1, the mean of 4 */
            for (int c = 0; c < 3; c++)
                *at(&b.colour, x, y, c) = value;
            *at(&variance, x, y, 0) = (float)((lit / 4.0 - (lit / 4.0) * (lit / 4.0)) / 3.0);
            input_sum += value;
        }
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth,
                                         .variance = &variance};
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    float lowest = INFINITY;
    for (size_t i = 0; i < (size_t)SIZE * SIZE * 3; i++)
        lowest = fminf(lowest, b.colour.pixels[i]);
    double mean = region_mean(&b.colour, 0, 0, 0, SIZE, SIZE);
    print_message("a dim surface at 4 spp: lowest denoised value %g, mean %.4f (input %.4f)\n", lowest, mean,
                  input_sum / (SIZE * SIZE));
    assert_true(lowest >= 0.0f);
    assert_relative(mean, input_sum / (SIZE * SIZE), 0.2);
    image_free(&variance);
    free_buffers(&b);
}

/* A surface at 4 samples a pixel whose noise is heavy-tailed, as a path tracer's is: each
 * sample 0.5 with a little noise, and one in ten catching a bright path (+2), so that
 * most pixels caught none and their variance says they are nearly certain. The bias check
 * (postprocess.h, step 4) must not take that certainty at its word: before its standard
 * error had the 5x5 floor it gave pixels that missed their low values back, and pixels
 * that caught a path part of theirs, as dark and bright specks on a smoothed surface (the
 * Cornell box's ceiling at 4 and 16 spp): 176 pixels here more than 0.2 from the true
 * 0.7; with the floor 85. Most of those left are step 5's: on such noise its risk
 * estimate picks early iterations around clusters of bright pixels (4 specks without the
 * choice; on renders the choice still lowers the RMSE, docs/sampling.md). */
static void test_denoise_bias_check_distrusts_a_few_samples_variance(void **state)
{
    (void)state;
    buffers b = make_flat(0.0f, 0.0f, 5);
    rt_image variance = make_image(SIZE, SIZE, 1, 0.0f);
    random_state random = {2024};
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            double samples[4], mean = 0.0, squares = 0.0;
            for (int i = 0; i < 4; i++) {
                samples[i] = 0.5 + 0.05 * random_normal(&random) + (random_uniform(&random) < 0.1 ? 2.0 : 0.0);
                mean += samples[i] / 4.0;
            }
            for (int i = 0; i < 4; i++)
                squares += (samples[i] - mean) * (samples[i] - mean);
            for (int c = 0; c < 3; c++)
                *at(&b.colour, x, y, c) = (float)mean;
            *at(&variance, x, y, 0) = (float)(squares / 3.0 / 4.0);
        }
    double mean_before, variance_before;
    region_statistics(&b.colour, 0, 0, 0, SIZE, SIZE, &mean_before, &variance_before);
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth,
                                         .variance = &variance};
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    int specks = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            specks += fabsf(*at(&b.colour, x, y, 0) - 0.7f) > 0.2f;
    double mean, variance_after;
    region_statistics(&b.colour, 0, 0, 0, SIZE, SIZE, &mean, &variance_after);
    print_message("heavy-tailed noise at 4 spp: %d pixels more than 0.2 from 0.7, variance %.0fx lower, mean "
                  "%.4f -> %.4f\n", specks, variance_before / variance_after, mean_before, mean);
    assert_true(specks <= 120);
    assert_true(variance_after * 10 <= variance_before);
    assert_relative(mean, 0.7, 0.05);
    image_free(&variance);
    free_buffers(&b);
}

/* A bright line one pixel wide whose own samples are noisy (the strip of ceiling beside
 * the Cornell box's light, which a few samples of each pixel find) on a noisy surface of
 * the same guides: the filter spreads it into the surface, and its residual, the same
 * along the line, is many standard errors from zero over each 3x3 neighbourhood, so the
 * bias check (postprocess.h, step 4) gives part of it back: 1.14 of 1.5 (1.12 before step
 * 5's choice), where without the check the line came out at 0.97 (0.91 before the colour
 * weight's schedule). Only part, since the light the filter took went to the rows beside
 * the line, whose residuals the 3x3 mean counts with the opposite sign. A surface two rows
 * away keeps its value, and the surface its smoothing: less of it within the choice's
 * reach of the line, where earlier iterations' images win (the half's variance 46x lower,
 * 235x before the choice). */
static void test_denoise_gives_back_a_noisy_bright_line(void **state)
{
    (void)state;
    buffers b = make_flat(0.5f, 0.05f, 23);
    rt_image variance = make_image(SIZE, SIZE, 1, 0.0025f);
    random_state random = {4242};
    for (int x = 0; x < SIZE; x++) {
        *at(&variance, x, HALF, 0) = 0.09f;
        float value = (float)(1.5 + 0.3 * random_normal(&random));
        for (int c = 0; c < 3; c++)
            *at(&b.colour, x, HALF, c) = value;
    }
    double line_before = region_mean(&b.colour, 0, 0, HALF, SIZE, HALF + 1);
    double surface_before, surface_variance_before;
    region_statistics(&b.colour, 0, 0, 0, SIZE, HALF - 2, &surface_before, &surface_variance_before);
    postprocess_denoise_guides guides = {.albedo = &b.albedo, .normal = &b.normal, .depth = &b.depth,
                                         .variance = &variance};
    assert_int_equal(postprocess_denoise(&b.colour, &guides, NULL, NULL), RT_OK);
    double line = region_mean(&b.colour, 0, 0, HALF, SIZE, HALF + 1);
    double beside = region_mean(&b.colour, 0, 0, HALF + 2, SIZE, HALF + 3);
    double surface, surface_variance;
    region_statistics(&b.colour, 0, 0, 0, SIZE, HALF - 2, &surface, &surface_variance);
    print_message("denoise of a noisy bright line: %.4f -> %.4f (true 1.5), the surface 2 rows away %.4f, "
                  "elsewhere its variance %.0fx lower\n", line_before, line, beside,
                  surface_variance_before / surface_variance);
    assert_true(line > 1.08 && line < 1.5);
    assert_relative(beside, 0.5, 0.02);
    assert_relative(surface, 0.5, 0.01);
    assert_true(surface_variance * 20 <= surface_variance_before);
    image_free(&variance);
    free_buffers(&b);
}

static void test_denoise_rejects_bad_input(void **state)
{
    (void)state;
    buffers b = make_flat(0.5f, 0.1f, 3);
    rt_image small = make_image(SIZE, SIZE - 1, 3, 1.0f);
    rt_image grey = make_image(SIZE, SIZE, 1, 1.0f);
    rt_error error;
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.albedo = &small), NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "albedo"));
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.normal = &small), NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "normal"));
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.depth = &small), NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "depth"));
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.normal = &grey), NULL, &error), RT_ERROR_INPUT);
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.emission = &small), NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "emission"));
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.emission = &grey), NULL, &error), RT_ERROR_INPUT);
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.variance = &small), NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "variance"));
    rt_image bad_emission = make_image(SIZE, SIZE, 3, 0.0f);
    *at(&bad_emission, 7, 2, 0) = INFINITY;
    assert_int_equal(denoise_guided(&b.colour, GUIDES(.emission = &bad_emission), NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "emission image has an infinity at pixel (7, 2)"));
    image_free(&bad_emission);
    assert_int_equal(postprocess_denoise(&grey, NULL, NULL, &error), RT_ERROR_INPUT);
    postprocess_denoise_options options = postprocess_denoise_options_defaults();
    options.sigma_normal = -1;
    assert_int_equal(postprocess_denoise(&b.colour, NULL, &options, &error), RT_ERROR_INPUT);
    options = postprocess_denoise_options_defaults();
    options.iterations = POSTPROCESS_MAX_DENOISE_ITERATIONS + 1;
    assert_int_equal(postprocess_denoise(&b.colour, NULL, &options, &error), RT_ERROR_INPUT);
    *at(&b.colour, 3, 5, 1) = NAN;
    rt_image copy = make_image(SIZE, SIZE, 3, 0.0f);
    memcpy(copy.pixels, b.colour.pixels, sizeof(float) * SIZE * SIZE * 3);
    assert_int_equal(postprocess_denoise(&b.colour, NULL, NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "NaN at pixel (3, 5)"));
    /* Nothing changed on failure. */
    assert_memory_equal(copy.pixels, b.colour.pixels, sizeof(float) * SIZE * SIZE * 3);
    image_free(&copy);
    image_free(&small);
    image_free(&grey);
    free_buffers(&b);
}

/* ---------------------------------------------------------------------------------- */
/* Tone mapping                                                                         */

static void test_tonemap_reinhard_of_one_is_a_half(void **state)
{
    (void)state;
    rt_image image = make_image(1, 1, 3, 1.0f);
    rt_error error;
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_REINHARD, 0.0f, &error), RT_OK);
    for (int c = 0; c < 3; c++)
        assert_close(image.pixels[c], 0.5, 1e-6);
    /* Exposure first: 0.5 at +1 stop is 1, then 0.5. */
    image.pixels[0] = image.pixels[1] = image.pixels[2] = 0.5f;
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_REINHARD, 1.0f, &error), RT_OK);
    assert_close(image.pixels[1], 0.5, 1e-6);
    image_free(&image);
}

static void test_tonemap_curves_are_monotonic_and_bounded(void **state)
{
    (void)state;
    enum { STEPS = 2001 };
    postprocess_tonemap_operator operators[] = {TONEMAP_REINHARD, TONEMAP_ACES};
    for (int o = 0; o < 2; o++) {
        rt_image ramp = make_image(STEPS, 1, 3, 0.0f);
        for (int i = 0; i < STEPS; i++)
            for (int c = 0; c < 3; c++)
                *at(&ramp, i, 0, c) = 1e-3f * (float)i * (float)i / 40.0f;  /* 0 .. 100, denser near 0 */
        rt_error error;
        assert_int_equal(postprocess_tonemap(&ramp, operators[o], 0.0f, &error), RT_OK);
        for (int i = 0; i < STEPS; i++) {
            float v = *at(&ramp, i, 0, 0);
            assert_true(v >= 0.0f && v <= 1.0f);
            if (i > 0)
                assert_true(v >= *at(&ramp, i - 1, 0, 0));
        }
        /* Strictly rising over the highlights too (x 1.56 against 6.25), not flat from 1 on. */
        assert_true(*at(&ramp, STEPS / 4, 0, 0) > *at(&ramp, STEPS / 8, 0, 0));
        image_free(&ramp);
    }
}

static void test_tonemap_aces_values(void **state)
{
    (void)state;
    rt_image image = make_image(5, 1, 3, 0.0f);
    float inputs[5] = {0.0f, 1.0f, 1e6f, -2.0f, INFINITY};
    for (int x = 0; x < 5; x++)
        for (int c = 0; c < 3; c++)
            *at(&image, x, 0, c) = inputs[x];
    *at(&image, 3, 0, 1) = NAN;
    rt_error error;
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_ACES, 0.0f, &error), RT_OK);
    assert_close(*at(&image, 0, 0, 0), 0.0, 1e-6);
    assert_close(*at(&image, 1, 0, 0), 2.54 / 3.16, 1e-6);  /* 0.8038: the fit is pre-exposed */
    assert_close(*at(&image, 2, 0, 0), 1.0, 1e-6);
    assert_close(*at(&image, 3, 0, 0), 0.0, 0);
    assert_close(*at(&image, 3, 0, 1), 0.0, 0);
    assert_close(*at(&image, 4, 0, 2), 1.0, 0);
    image_free(&image);
}

static void test_tonemap_reinhard_keeps_colour_ratios(void **state)
{
    (void)state;
    rt_image image = make_image(2, 1, 4, 0.5f);
    float *dim = at(&image, 0, 0, 0), *bright = at(&image, 1, 0, 0);
    dim[0] = 0.4f, dim[1] = 0.2f, dim[2] = 0.1f;
    bright[0] = 0.0f, bright[1] = 0.0f, bright[2] = 100.0f;  /* luminance 7.2: B would pass 1 */
    rt_error error;
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_REINHARD, 0.0f, &error), RT_OK);
    assert_close(dim[0] / dim[1], 2.0, 1e-5);
    assert_close(dim[1] / dim[2], 2.0, 1e-5);
    double luminance = 0.2126 * 0.4 + 0.7152 * 0.2 + 0.0722 * 0.1;
    assert_close(0.2126 * dim[0] + 0.7152 * dim[1] + 0.0722 * dim[2], luminance / (1 + luminance), 1e-6);
    assert_close(bright[2], 1.0, 1e-6);
    assert_close(bright[0], 0.0, 0);
    assert_close(*at(&image, 0, 0, 3), 0.5, 0);  /* alpha untouched */
    image_free(&image);
}

static void test_tonemap_clamp_only_exposes(void **state)
{
    (void)state;
    rt_image image = make_image(1, 1, 3, 3.0f);
    rt_error error;
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_CLAMP, -1.0f, &error), RT_OK);
    assert_close(image.pixels[0], 1.5, 1e-6);
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_CLAMP, 2.0f, &error), RT_OK);
    assert_close(image.pixels[2], 6.0, 1e-6);  /* the 8-bit writer clamps, not this */
    assert_int_equal(postprocess_tonemap(&image, (postprocess_tonemap_operator)7, 0.0f, &error), RT_ERROR_INPUT);
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_ACES, NAN, &error), RT_ERROR_INPUT);
    image_free(&image);
}

/* A two-channel image is grey + alpha: only the grey channel is blurred or tone-mapped. */
static void test_grey_alpha_keeps_alpha(void **state)
{
    (void)state;
    rt_image image = make_image(6, 5, 2, 0.0f);
    for (int y = 0; y < 5; y++)
        for (int x = 0; x < 6; x++) {
            *at(&image, x, y, 0) = (x + y) % 2 ? 1.0f : 3.0f;
            *at(&image, x, y, 1) = 0.1f * (float)x;
        }
    rt_error error;
    assert_int_equal(postprocess_gaussian_blur(&image, 1.0f, 1, &error), RT_OK);
    assert_close(region_mean(&image, 0, 0, 0, 6, 5), 2.0, 1e-5);
    assert_true(*at(&image, 2, 2, 0) < 2.5f);
    assert_int_equal(postprocess_tonemap(&image, TONEMAP_REINHARD, 0.0f, &error), RT_OK);
    for (int y = 0; y < 5; y++)
        for (int x = 0; x < 6; x++) {
            float grey = *at(&image, x, y, 0);
            assert_true(grey > 0.5f && grey < 0.75f);  /* 1/(1+1) .. 3/(1+3) */
            assert_close(*at(&image, x, y, 1), 0.1f * (float)x, 0);
        }
    image_free(&image);
}

/* ---------------------------------------------------------------------------------- */
/* Montage                                                                              */

/* count 3x2 tiles; tile i is filled with (i + 1, 10 (i + 1), 100 (i + 1)), plus an alpha
 * channel that must not reach the sheet. */
static void make_tiles(rt_image *tiles, int count)
{
    for (int i = 0; i < count; i++) {
        tiles[i] = make_image(3, 2, 4, 0.0f);
        for (int y = 0; y < 2; y++)
            for (int x = 0; x < 3; x++) {
                *at(&tiles[i], x, y, 0) = (float)(i + 1);
                *at(&tiles[i], x, y, 1) = 10.0f * (i + 1);
                *at(&tiles[i], x, y, 2) = 100.0f * (i + 1);
                *at(&tiles[i], x, y, 3) = -1.0f;
            }
    }
}

/* The index of the tile whose colour (x, y) of sheet holds, -1 for black. */
static int tile_at(const rt_image *sheet, int x, int y)
{
    float r = *at(sheet, x, y, 0);
    if (r == 0.0f) {
        assert_close(*at(sheet, x, y, 1), 0, 0);
        assert_close(*at(sheet, x, y, 2), 0, 0);
        return -1;
    }
    assert_close(*at(sheet, x, y, 1), 10 * r, 0);
    assert_close(*at(sheet, x, y, 2), 100 * r, 0);
    return (int)r - 1;
}

static void test_montage_layout(void **state)
{
    (void)state;
    rt_image tiles[5];
    make_tiles(tiles, 5);
    rt_image sheet;
    rt_error error;
    /* 5 tiles in 2 columns with a 1-pixel gap: 3 rows; 2*3+1 = 7 wide, 3*2+2 = 8 high.
     *   row 0: tiles 0 1     x 0..2 and 4..6, y 0..1
     *   row 1: tiles 2 3     y 3..4
     *   row 2: tile 4, then black
     * Gaps: column x = 3, rows y = 2 and 5. */
    assert_int_equal(postprocess_montage(tiles, 5, 2, 1, &sheet, &error), RT_OK);
    assert_int_equal(sheet.width, 7);
    assert_int_equal(sheet.height, 8);
    assert_int_equal(sheet.channels, 3);
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 7; x++) {
            int expected = -1;
            if (x != 3 && y != 2 && y != 5)
                expected = (y / 3) * 2 + (x / 4);
            if (expected == 5)
                expected = -1;  /* the empty last cell */
            assert_int_equal(tile_at(&sheet, x, y), expected);
        }
    image_free(&sheet);

    /* Default columns: ceil(sqrt(5)) = 3, no gap: 9x4, tiles 0 1 2 / 3 4 -. */
    assert_int_equal(postprocess_montage(tiles, 5, 0, 0, &sheet, &error), RT_OK);
    assert_int_equal(sheet.width, 9);
    assert_int_equal(sheet.height, 4);
    assert_int_equal(tile_at(&sheet, 8, 1), 2);
    assert_int_equal(tile_at(&sheet, 2, 2), 3);
    assert_int_equal(tile_at(&sheet, 3, 2), 4);
    assert_int_equal(tile_at(&sheet, 6, 3), -1);
    image_free(&sheet);

    /* More columns than images: one row, no empty cells. */
    assert_int_equal(postprocess_montage(tiles, 2, 10, 2, &sheet, &error), RT_OK);
    assert_int_equal(sheet.width, 8);
    assert_int_equal(sheet.height, 2);
    assert_int_equal(tile_at(&sheet, 7, 1), 1);
    image_free(&sheet);

    /* One image: the image itself (colour channels). */
    assert_int_equal(postprocess_montage(tiles, 1, 0, 5, &sheet, &error), RT_OK);
    assert_int_equal(sheet.width, 3);
    assert_int_equal(sheet.height, 2);
    image_free(&sheet);
    for (int i = 0; i < 5; i++)
        image_free(&tiles[i]);
}

static void test_montage_grey_images(void **state)
{
    (void)state;
    rt_image grey[2] = {make_image(2, 2, 1, 0.25f), make_image(2, 2, 1, 0.75f)};
    rt_image sheet;
    rt_error error;
    assert_int_equal(postprocess_montage(grey, 2, 1, 0, &sheet, &error), RT_OK);
    assert_int_equal(sheet.width, 2);
    assert_int_equal(sheet.height, 4);
    for (int c = 0; c < 3; c++) {
        assert_close(*at(&sheet, 1, 1, c), 0.25, 0);
        assert_close(*at(&sheet, 0, 2, c), 0.75, 0);
    }
    image_free(&sheet);
    image_free(&grey[0]);
    image_free(&grey[1]);
}

static void test_montage_rejects_bad_input(void **state)
{
    (void)state;
    rt_image tiles[3];
    make_tiles(tiles, 2);
    tiles[2] = make_image(4, 2, 3, 1.0f);
    rt_image sheet;
    rt_error error;
    assert_int_equal(postprocess_montage(tiles, 3, 0, 0, &sheet, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "image 3 is 4x2, image 1 is 3x2"));
    assert_null(sheet.pixels);
    assert_int_equal(postprocess_montage(tiles, 0, 0, 0, &sheet, &error), RT_ERROR_INPUT);
    assert_int_equal(postprocess_montage(tiles, 2, -1, 0, &sheet, &error), RT_ERROR_INPUT);
    assert_int_equal(postprocess_montage(tiles, 2, 0, -1, &sheet, &error), RT_ERROR_INPUT);
    assert_int_equal(postprocess_montage(tiles, 2, 2, 1 << 30, &sheet, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "a side"));
    for (int i = 0; i < 3; i++)
        image_free(&tiles[i]);
}

static void test_defaults_are_zero(void **state)
{
    (void)state;
    postprocess_denoise_options options = postprocess_denoise_options_defaults();
    assert_int_equal(options.iterations, 0);
    assert_close(options.sigma_colour, 0, 0);
    assert_close(options.sigma_normal, 0, 0);
    assert_close(options.sigma_depth, 0, 0);
    assert_close(options.sigma_albedo, 0, 0);
    assert_close(options.albedo_epsilon, 0, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blur_keeps_a_constant_image),
        cmocka_unit_test(test_blur_keeps_the_mean_and_reduces_noise),
        cmocka_unit_test(test_blur_wider_than_the_image_keeps_the_mean),
        cmocka_unit_test(test_blur_zero_sigma_or_passes_is_a_no_op),
        cmocka_unit_test(test_blur_rejects_bad_arguments),
        cmocka_unit_test(test_denoise_smooths_a_flat_noisy_region),
        cmocka_unit_test(test_denoise_without_guides_still_smooths),
        cmocka_unit_test(test_denoise_keeps_an_edge_between_normals),
        cmocka_unit_test(test_denoise_keeps_an_edge_between_depths),
        cmocka_unit_test(test_denoise_guides_alone_hold_an_edge),
        cmocka_unit_test(test_denoise_keeps_sky_and_surface_apart),
        cmocka_unit_test(test_denoise_smooths_a_tilted_plane),
        cmocka_unit_test(test_denoise_demodulation_keeps_a_texture),
        cmocka_unit_test(test_denoise_keeps_other_channels),
        cmocka_unit_test(test_denoise_leaves_the_emission_seen_at_once),
        cmocka_unit_test(test_denoise_keeps_a_highlight_its_variance_vouches_for),
        cmocka_unit_test(test_denoise_gives_back_a_noisy_bright_line),
        cmocka_unit_test(test_blocks_with_the_reach_are_exact),
        cmocka_unit_test(test_denoise_matches_the_reference),
        cmocka_unit_test(test_denoise_keeps_detail_the_guides_do_not_show),
        cmocka_unit_test(test_denoise_never_makes_a_colour_negative),
        cmocka_unit_test(test_denoise_bias_check_distrusts_a_few_samples_variance),
        cmocka_unit_test(test_denoise_rejects_bad_input),
        cmocka_unit_test(test_tonemap_reinhard_of_one_is_a_half),
        cmocka_unit_test(test_tonemap_curves_are_monotonic_and_bounded),
        cmocka_unit_test(test_tonemap_aces_values),
        cmocka_unit_test(test_tonemap_reinhard_keeps_colour_ratios),
        cmocka_unit_test(test_tonemap_clamp_only_exposes),
        cmocka_unit_test(test_grey_alpha_keeps_alpha),
        cmocka_unit_test(test_montage_layout),
        cmocka_unit_test(test_montage_grey_images),
        cmocka_unit_test(test_montage_rejects_bad_input),
        cmocka_unit_test(test_defaults_are_zero),
    };
    return cmocka_run_group_tests_name("postprocess", tests, NULL, NULL);
}
