/* test_image_stat_diff.c: the statistical comparison (image_stat_diff.h) on synthetic Monte
 * Carlo images whose noise is known: each pixel's mean is its true value plus Gaussian
 * noise of the variance its variance layer states, so the z-scores of two such images are
 * exactly N(0, 1). The power cases of the real renders are tests/render/test-stat-diff.sh. */
#include "image_compare.h"
#include "image_stat_diff.h"
#include "support.h"

#define SAMPLES 64

/* A Gaussian number from the test's generator (Box-Muller). */
static double gaussian(uint64_t *state)
{
    double u = ((double)(splitmix64_next(state) >> 11) + 0.5) / 9007199254740992.0;
    double v = (double)(splitmix64_next(state) >> 11) / 9007199254740992.0;
    return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

/* The true value of the test scene at (x, y), channel c: a bright disc on a ramp. */
typedef double (*truth_function)(int x, int y, int c, int width, int height);

static double disc_on_ramp(int x, int y, int c, int width, int height)
{
    double dx = x - width * 0.5, dy = y - height * 0.5;
    double inside = dx * dx + dy * dy < (height * 0.3) * (height * 0.3) ? 1.0 : 0.0;
    return 0.2 + 0.3 * x / width + inside * (0.5 + 0.1 * c);
}

/* An image as `render --variance` writes it: R, G, B means of SAMPLES samples whose
 * per-sample standard deviation is relative * value (at least floor), samples, and
 * variance.R/G/B of that (in the population form s^2 (n - 1) / n the renderer writes).
 * scale multiplies the true values inside the box [x0, x1) x [y0, y1). */
typedef struct synthetic {
    int width, height;
    double relative, floor;
    int box[4];
    double scale;
    int shift_x;                 /* reads the truth at x - shift_x */
    bool without_variance;
} synthetic;

static rt_image make_render(const synthetic *how, truth_function truth, uint64_t seed)
{
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, how->width, how->height, 7, &error), RT_OK);
    static const char *const names[7] = {"R", "G", "B", "samples", "variance.R", "variance.G", "variance.B"};
    for (int c = 0; c < 7; c++)
        strcpy(image.channel_names[c], names[c]);
    if (how->without_variance)
        image.channels = 4;
    uint64_t state = seed;
    for (int y = 0; y < how->height; y++)
        for (int x = 0; x < how->width; x++) {
            float *pixel = image.pixels + ((size_t)y * how->width + x) * image.channels;
            int source = x - how->shift_x < 0 ? 0 : x - how->shift_x;
            bool boxed = x >= how->box[0] && x < how->box[2] && y >= how->box[1] && y < how->box[3];
            for (int c = 0; c < 3; c++) {
                double value = truth(source, y, c, how->width, how->height) * (boxed ? how->scale : 1.0);
                double sd = fmax(how->relative * value, how->floor);
                double per_sample_variance = sd * sd;
                pixel[c] = (float)(value + gaussian(&state) * sd / sqrt(SAMPLES));
                if (!how->without_variance)
                    pixel[4 + c] = (float)(per_sample_variance * (SAMPLES - 1) / SAMPLES);
            }
            pixel[3] = SAMPLES;
        }
    return image;
}

static synthetic noisy(int width, int height)
{
    return (synthetic){.width = width, .height = height, .relative = 1.0, .floor = 0.05, .scale = 1.0};
}

static image_stat_result compare(const rt_image *a, const rt_image *b, const image_stat_options *options)
{
    image_stat_result result;
    rt_error error = {{0}};
    if (image_stat_diff(a, b, options, &result, NULL, &error) != RT_OK)
        fail_msg("%s", error.message);
    return result;
}

/* The thresholds: erfc's inverse, and Šidák's levels for the default scales. */
static void thresholds(void **state)
{
    (void)state;
    assert_close(image_stat_z_threshold(0.05), 1.959963984540054, 1e-9);
    assert_close(image_stat_z_threshold(0.01), 2.5758293035489, 1e-9);
    assert_close(image_stat_z_threshold(1e-7), 5.326723886, 1e-6);
    rt_image a = make_render(&(synthetic){.width = 100, .height = 50, .relative = 1, .floor = 0.05, .scale = 1},
                             disc_on_ramp, 1);
    image_stat_result result = compare(&a, &a, NULL);
    /* Pixels: 1 - 0.99^(1 / 15000). Blocks: six scales share 0.01, each 1 - 0.99^(1/6),
     * then over its blocks: 4x4 has 25 x 13 blocks x 3 channels = 975 tests. */
    assert_int_equal(result.scale_count, 7);
    assert_close(result.scales[0].test_alpha, 1 - pow(0.99, 1.0 / 15000), 1e-15);
    assert_int_equal(result.scales[1].block_size, 4);
    assert_int_equal(result.scales[1].tests, 975);
    assert_close(result.scales[1].test_alpha, 1 - pow(pow(0.99, 1.0 / 6), 1.0 / 975), 1e-15);
    assert_int_equal(result.scales[6].block_size, IMAGE_STAT_WHOLE_IMAGE);
    assert_int_equal(result.scales[6].tests, 3);
    /* An image against itself: every z is 0. */
    assert_true(result.passed);
    assert_close(result.passing_share, 1.0, 0);
    assert_close(result.z_sd, 0.0, 0);
    assert_close(result.required_share, 0.9975, 0);
    image_free(&a);
}

/* Two renders of one scene (independent noise): calibrated z-scores, and over 200 pairs
 * about as many false failures as the levels allow (0.01 for the blocks, about 0 for the
 * pixel rule). */
static void same_scene_passes(void **state)
{
    (void)state;
    synthetic how = noisy(64, 48);
    int failures = 0;
    double sd_sum = 0;
    for (uint64_t pair = 0; pair < 200; pair++) {
        rt_image a = make_render(&how, disc_on_ramp, 1000 + 2 * pair);
        rt_image b = make_render(&how, disc_on_ramp, 1001 + 2 * pair);
        image_stat_result result = compare(&a, &b, NULL);
        failures += !result.passed;
        sd_sum += result.z_sd;
        assert_true(result.scales[0].passed);
        image_free(&a);
        image_free(&b);
    }
    print_message("200 pairs of one scene: %d failed, mean z sd %.4f\n", failures, sd_sum / 200);
    assert_close(sd_sum / 200, 1.0, 0.01);
    assert_true(failures <= 6);   /* Binomial(200, 0.01): 6 or more has chance 1.6% */
}

/* A 2% change of a 48 x 48 region (a pixel's z of 0.02 / (sqrt 2 * 0.125) = 0.11): no pixel
 * test sees it, Mitsuba's rule alone passes; the block tests fail. */
static void a_small_change_fails_the_blocks(void **state)
{
    (void)state;
    synthetic how = noisy(96, 64);
    how.relative = 1.0;
    how.floor = 0.0;
    rt_image a = make_render(&how, disc_on_ramp, 7);
    how.box[0] = 10, how.box[1] = 10, how.box[2] = 58, how.box[3] = 58;
    how.scale = 1.02;
    rt_image b = make_render(&how, disc_on_ramp, 8);
    image_stat_options pixels_only = image_stat_options_defaults();
    pixels_only.pixels_only = true;
    image_stat_result alone = compare(&a, &b, &pixels_only);
    assert_true(alone.passed);
    assert_int_equal(alone.scale_count, 1);
    image_stat_result result = compare(&a, &b, NULL);
    assert_true(result.scales[0].passed);
    assert_false(result.passed);
    bool some_block_failed = false;
    for (int i = 1; i < result.scale_count; i++)
        some_block_failed = some_block_failed || !result.scales[i].passed;
    assert_true(some_block_failed);
    /* The largest block z is negative: a is darker than b there. */
    image_free(&a);
    image_free(&b);
}

/* A one-pixel shift of the disc: its edge pixels fail the pixel rule. */
static void a_shift_fails_the_pixels(void **state)
{
    (void)state;
    synthetic how = noisy(96, 64);
    how.relative = 0.2;
    how.floor = 0.01;
    rt_image a = make_render(&how, disc_on_ramp, 11);
    how.shift_x = 1;
    rt_image b = make_render(&how, disc_on_ramp, 12);
    image_stat_result result = compare(&a, &b, NULL);
    assert_false(result.scales[0].passed);
    assert_true(result.passing_share < 0.9975);
    assert_false(result.passed);
    image_free(&a);
    image_free(&b);
}

/* The pixel rule: 0.25% of pixel channels may fail. 100 x 40 x 3 = 12000 channels: 30 may
 * fail, 31 may not (each made to fail by a difference of 100 standard deviations). */
static void the_pass_share(void **state)
{
    (void)state;
    synthetic how = noisy(100, 40);
    rt_image a = make_render(&how, disc_on_ramp, 3);
    rt_image b = make_render(&how, disc_on_ramp, 3);
    image_stat_options options = image_stat_options_defaults();
    options.pixels_only = true;
    for (int i = 0; i < 31; i++) {
        float *pixel = b.pixels + (size_t)(i * 97 % 4000) * 7;
        pixel[i % 3] += 100.0f * sqrtf(2 * pixel[4 + i % 3] / (SAMPLES - 1));
        image_stat_result result = compare(&a, &b, &options);
        assert_int_equal(result.scales[0].failing, i + 1);
        assert_true(result.passed == (i + 1 <= 30));
    }
    options.pass_share = 0.99;
    assert_true(compare(&a, &b, &options).passed);
    image_free(&a);
    image_free(&b);
}

/* Pixels without noise: float rounding passes, a 1% difference fails (the noise floor,
 * 0.1% of the value, counts as one standard deviation). */
static void the_noise_floor(void **state)
{
    (void)state;
    synthetic how = {.width = 32, .height = 32, .relative = 0, .floor = 0, .scale = 1};
    rt_image a = make_render(&how, disc_on_ramp, 1), b = make_render(&how, disc_on_ramp, 1);
    for (size_t p = 0; p < 32 * 32; p++)
        for (int c = 0; c < 3; c++)
            b.pixels[p * 7 + c] = nextafterf(b.pixels[p * 7 + c], 2.0f);
    assert_true(compare(&a, &b, NULL).passed);
    for (size_t p = 0; p < 32 * 32; p++)
        b.pixels[p * 7] *= 1.01f;
    image_stat_result result = compare(&a, &b, NULL);
    assert_false(result.passed);
    assert_true(fabs(result.scales[0].max_z) > 9.0);
    image_free(&a);
    image_free(&b);
}

/* Bad inputs are errors with a message; different sizes too (image_compare() makes that a
 * failed comparison instead). Pixels with fewer than 2 samples are skipped. */
static void errors_and_skipped_pixels(void **state)
{
    (void)state;
    synthetic how = noisy(16, 8);
    rt_image a = make_render(&how, disc_on_ramp, 1), b = make_render(&how, disc_on_ramp, 2);
    image_stat_result result;
    rt_error error = {{0}};
    rt_image plain = make_image(16, 8, 3, 0.5f);
    assert_int_equal(image_stat_diff(&a, &plain, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "DIFF: image B has no 'samples' channel");
    how.without_variance = true;
    rt_image c = make_render(&how, disc_on_ramp, 3), d = make_render(&how, disc_on_ramp, 4);
    assert_int_equal(image_stat_diff(&a, &d, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "DIFF: image B has no variance.R/G/B layers, which the statistical test needs of "
                                   "both images; render it with --variance");
    assert_int_equal(image_stat_diff(&c, &a, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "image A has no variance.R/G/B layers");
    how.without_variance = false;
    how.width = 8;
    rt_image small = make_render(&how, disc_on_ramp, 5);
    assert_int_equal(image_stat_diff(&a, &small, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "sizes differ: 16x8 vs 8x8");
    b.pixels[7 * 5 + 1] = NAN;
    assert_int_equal(image_stat_diff(&a, &b, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "image B has NaN at pixel (5, 0) in G");
    b.pixels[7 * 5 + 1] = 0.5f;
    image_stat_options options = image_stat_options_defaults();
    options.block_sizes[0] = 1;
    options.block_count = 1;
    assert_int_equal(image_stat_diff(&a, &b, &options, &result, NULL, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "block size must be 2 pixels or more");
    /* One pixel with 1 sample and one with none: left out. */
    a.pixels[3] = 1;
    b.pixels[7 + 3] = 0;
    assert_int_equal(image_stat_diff(&a, &b, NULL, &result, NULL, &error), RT_OK);
    assert_int_equal(result.skipped_pixels, 2);
    assert_int_equal(result.tested_pixels, 16 * 8 - 2);
    image_compare_result compared;
    image_compare_options compare_options = {.test = IMAGE_COMPARE_Z};
    assert_int_equal(image_compare(&a, &small, &compare_options, &compared, NULL, NULL, &error), RT_OK);
    assert_true(compared.sizes_differ && !compared.passed);
    image_free(&a), image_free(&b), image_free(&c), image_free(&d), image_free(&plain), image_free(&small);
}

/* The maps: pixel z-scores, and the significance of the finest failing scale, signed:
 * below -1 where a is darker than b (by a failing test), within (-1, 1) elsewhere; the
 * heat map is black at 0, red at 1 and blue at -1. */
static void maps_and_heat(void **state)
{
    (void)state;
    synthetic how = noisy(64, 32);
    rt_image a = make_render(&how, disc_on_ramp, 5);
    how.box[0] = 0, how.box[1] = 0, how.box[2] = 32, how.box[3] = 32;
    how.scale = 1.3;
    rt_image b = make_render(&how, disc_on_ramp, 6);
    image_stat_result result;
    rt_image maps, heat;
    rt_error error;
    /* Blocks within one half only, so that no test covers both halves. */
    image_stat_options options = {.block_sizes = {4, 8, 16}, .block_count = 3};
    assert_int_equal(image_stat_diff(&a, &b, &options, &result, &maps, &error), RT_OK);
    assert_false(result.passed);
    assert_true(result.scales[0].passed);   /* 30% at a pixel's 18% noise: few pixels see it */
    assert_int_equal(result.map_scale, 1);  /* 4x4 blocks do */
    assert_false(result.scales[1].passed);
    assert_int_equal(maps.channels, 4);
    assert_string_equal(maps.channel_names[3], "significance");
    double left = 0, right = 0;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 64; x++) {
            double s = maps.pixels[(y * 64 + x) * 4 + 3];
            if (x < 32)
                left = fmin(left, s);
            else
                right = fmax(right, fabs(s));
        }
    assert_true(left < -1.0);    /* the changed half is covered by failing tests */
    assert_true(right < 1.0);
    maps.pixels[3] = 0.0f;
    maps.pixels[7] = 1.0f;
    maps.pixels[11] = -1.0f;
    assert_int_equal(image_stat_heat_map(&maps, &heat, &error), RT_OK);
    assert_close(heat.pixels[0] + heat.pixels[1] + heat.pixels[2], 0.0, 1e-6);
    assert_close(heat.pixels[3], 1.0, 1e-6);
    assert_true(heat.pixels[4] < 0.1f && heat.pixels[5] < 0.1f);
    assert_true(heat.pixels[6] < 0.1f && heat.pixels[7] < 0.3f);
    assert_close(heat.pixels[8], 1.0, 1e-6);
    image_free(&heat), image_free(&maps), image_free(&a), image_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(thresholds),
        cmocka_unit_test(same_scene_passes),
        cmocka_unit_test(a_small_change_fails_the_blocks),
        cmocka_unit_test(a_shift_fails_the_pixels),
        cmocka_unit_test(the_pass_share),
        cmocka_unit_test(the_noise_floor),
        cmocka_unit_test(errors_and_skipped_pixels),
        cmocka_unit_test(maps_and_heat),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
