/* test_image_diff.c: the metrics of image_diff() on tiny hand-made images whose expected
 * values are worked out by hand in the comments. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "image_diff.h"
#include "support.h"

#define CLOSE 1e-12

static float *sample(rt_image *image, int x, int y, int c)
{
    return &image->pixels[(y * image->width + x) * image->channels + c];
}

/* Compares a with b under options (NULL: the defaults), failing the test unless image_diff()
 * succeeds; returns the result. */
static image_diff_result diff_ok(const rt_image *a, const rt_image *b, const image_diff_options *options)
{
    image_diff_result result;
    rt_error error;
    assert_int_equal(image_diff(a, b, options, &result, NULL, &error), RT_OK);
    return result;
}

/* diff_ok() that also makes the difference image into *difference (the caller frees it). */
static image_diff_result diff_ok_with_image(const rt_image *a, const rt_image *b,
                                            const image_diff_options *options, rt_image *difference)
{
    image_diff_result result;
    rt_error error;
    assert_int_equal(image_diff(a, b, options, &result, difference, &error), RT_OK);
    return result;
}

/* Frees both images of a comparison. */
static void free_pair(rt_image *a, rt_image *b)
{
    image_free(a);
    image_free(b);
}

/* A: 2x2 RGB, all 0. B: (1,0) = (0.5, 0.25, 0), (0,1) = (0, 0, 0.125), the rest 0.
 * 12 samples; |d| sums to 0.875, d^2 to 0.25 + 0.0625 + 0.015625 = 0.328125. */
static void make_pair(rt_image *a, rt_image *b)
{
    *a = make_image(2, 2, 3, 0.0f);
    *b = make_image(2, 2, 3, 0.0f);
    *sample(b, 1, 0, 0) = 0.5f;
    *sample(b, 1, 0, 1) = 0.25f;
    *sample(b, 0, 1, 2) = 0.125f;
}

static void test_metrics(void **state)
{
    (void)state;
    rt_image a, b;
    make_pair(&a, &b);
    image_diff_result result = diff_ok(&a, &b, NULL);
    assert_close(result.mean_error, 0.875 / 12, CLOSE);
    assert_close(result.rms_error, sqrt(0.328125 / 12), CLOSE);
    assert_close(result.psnr, 10 * log10(12 / 0.328125), CLOSE);  /* 15.6315 dB */
    assert_close(result.max_error, 0.5, 0);
    assert_int_equal(result.max_x, 1);
    assert_int_equal(result.max_y, 0);
    /* Pixel errors 0.5 and 0.125 are over 0.016: 2 of 4 pixels, 50% > 1%. */
    assert_int_equal(result.failing_pixels, 2);
    assert_close(result.failing_percent, 50.0, CLOSE);
    assert_false(result.passed);
    free_pair(&a, &b);
}

static void test_metrics_are_symmetric(void **state)
{
    (void)state;
    rt_image a, b;
    make_pair(&a, &b);
    image_diff_result forward = diff_ok(&a, &b, NULL), backward = diff_ok(&b, &a, NULL);
    assert_memory_equal(&forward, &backward, sizeof forward);
    free_pair(&a, &b);
}

static void test_identical_images(void **state)
{
    (void)state;
    rt_image a = make_image(3, 2, 4, 0.75f), b = make_image(3, 2, 4, 0.75f);
    image_diff_result result = diff_ok(&a, &b, NULL);
    assert_close(result.mean_error, 0, 0);
    assert_close(result.rms_error, 0, 0);
    assert_true(isinf(result.psnr) && result.psnr > 0);
    assert_close(result.max_error, 0, 0);
    assert_int_equal(result.max_x, 0);
    assert_int_equal(result.max_y, 0);
    assert_int_equal(result.failing_pixels, 0);
    assert_true(result.passed);
    free_pair(&a, &b);
}

/* The first pixel in row order with the largest error is reported. */
static void test_max_location_first_of_ties(void **state)
{
    (void)state;
    rt_image a = make_image(3, 3, 3, 0.0f), b = make_image(3, 3, 3, 0.0f);
    *sample(&b, 0, 2, 1) = 0.25f;
    *sample(&b, 2, 1, 2) = 0.25f;
    *sample(&b, 1, 0, 0) = 0.125f;
    image_diff_result result = diff_ok(&a, &b, NULL);
    assert_close(result.max_error, 0.25, 0);
    assert_int_equal(result.max_x, 2);
    assert_int_equal(result.max_y, 1);
    free_pair(&a, &b);
}

/* A pixel fails when its error is strictly over the threshold. */
static void test_threshold_boundary(void **state)
{
    (void)state;
    rt_image a, b;
    make_pair(&a, &b);
    image_diff_options options = image_diff_options_defaults();
    options.fail_percent = 100;
    image_diff_result result;

    options.fail_threshold = 0.125;  /* only the 0.5 pixel is over */
    result = diff_ok(&a, &b, &options);
    assert_int_equal(result.failing_pixels, 1);
    assert_close(result.failing_percent, 25.0, CLOSE);

    options.fail_threshold = 0.124;
    result = diff_ok(&a, &b, &options);
    assert_int_equal(result.failing_pixels, 2);

    options.fail_threshold = 0.5;
    result = diff_ok(&a, &b, &options);
    assert_int_equal(result.failing_pixels, 0);
    free_pair(&a, &b);
}

/* The comparison passes when the failing share is at most fail_percent. */
static void test_fail_percent_boundary(void **state)
{
    (void)state;
    rt_image a, b;
    make_pair(&a, &b);
    image_diff_options options = image_diff_options_defaults();
    options.fail_threshold = 0.125;  /* 1 of 4 pixels fails: 25% */
    image_diff_result result;

    options.fail_percent = 25;
    result = diff_ok(&a, &b, &options);
    assert_true(result.passed);

    options.fail_percent = 24.99;
    result = diff_ok(&a, &b, &options);
    assert_false(result.passed);
    free_pair(&a, &b);
}

/* The defaults: 0.016 and 1%. 100 pixels; 0.015625 (2^-6) is under 0.016, 0.02 over. */
static void test_default_tolerance(void **state)
{
    (void)state;
    rt_image a = make_image(10, 10, 3, 0.5f), b = make_image(10, 10, 3, 0.5f);
    for (int x = 0; x < 10; x++)
        *sample(&b, x, 4, 1) = 0.5f + 0.015625f;
    *sample(&b, 7, 7, 0) = 0.52f;
    image_diff_result result = diff_ok(&a, &b, NULL);
    assert_int_equal(result.failing_pixels, 1);
    assert_close(result.failing_percent, 1.0, CLOSE);
    assert_true(result.passed);  /* exactly 1% is allowed */

    *sample(&b, 8, 8, 2) = 0.48f;
    result = diff_ok(&a, &b, NULL);
    assert_int_equal(result.failing_pixels, 2);
    assert_false(result.passed);
    free_pair(&a, &b);
}

/* hard_fail fails the comparison when any pixel's error is strictly over it, whatever
 * fail_percent allows; 0 turns it off. */
static void test_hard_fail(void **state)
{
    (void)state;
    rt_image a, b;
    make_pair(&a, &b);
    image_diff_options options = image_diff_options_defaults();
    options.fail_percent = 100;

    image_diff_result result = diff_ok(&a, &b, &options);
    assert_true(result.passed);

    options.hard_fail = 0.5;
    result = diff_ok(&a, &b, &options);
    assert_true(result.passed);

    options.hard_fail = 0.49;
    result = diff_ok(&a, &b, &options);
    assert_false(result.passed);
    free_pair(&a, &b);
}

static void test_size_mismatch(void **state)
{
    (void)state;
    rt_image a = make_image(160, 90, 3, 0.0f), b = make_image(80, 45, 3, 0.0f);
    image_diff_result result;
    rt_error error = {{0}};
    assert_int_equal(image_diff(&a, &b, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "sizes differ: 160x90 vs 80x45"));
    free_pair(&a, &b);
}

static void test_nan_is_an_error_naming_image_and_pixel(void **state)
{
    (void)state;
    rt_image a = make_image(4, 3, 4, 0.0f), b = make_image(4, 3, 4, 0.0f);
    image_diff_result result;
    rt_image difference;
    rt_error error = {{0}};

    *sample(&b, 2, 1, 1) = NAN;
    assert_int_equal(image_diff(&a, &b, NULL, &result, &difference, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "image B"));
    assert_non_null(strstr(error.message, "(2, 1)"));
    assert_null(difference.pixels);

    /* Alpha is not compared, but a NaN there is still a broken image. */
    *sample(&b, 2, 1, 1) = 0.0f;
    *sample(&a, 3, 2, 3) = NAN;
    assert_int_equal(image_diff(&a, &b, NULL, &result, NULL, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "image A"));
    assert_non_null(strstr(error.message, "(3, 2)"));
    free_pair(&a, &b);
}

/* Equal infinities do not differ; an infinity against a number is an infinite error. */
static void test_infinities(void **state)
{
    (void)state;
    rt_image a = make_image(2, 1, 3, 0.0f), b = make_image(2, 1, 3, 0.0f);
    *sample(&a, 0, 0, 0) = *sample(&b, 0, 0, 0) = INFINITY;
    image_diff_result result = diff_ok(&a, &b, NULL);
    assert_true(result.passed);
    assert_close(result.max_error, 0, 0);
    assert_close(result.mean_error, 0, 0);  /* not inf - inf = NaN */
    assert_close(result.rms_error, 0, 0);

    *sample(&b, 1, 0, 2) = INFINITY;
    result = diff_ok(&a, &b, NULL);
    assert_false(result.passed);
    assert_true(isinf(result.max_error));
    assert_int_equal(result.max_x, 1);
    free_pair(&a, &b);
}

/* +inf against -inf is an infinite error like any other, each counted once per pixel
 * however many; in the difference image equal infinities are 0 and others infinite. */
static void test_infinities_of_both_signs(void **state)
{
    (void)state;
    rt_image a = make_image(3, 1, 3, 0.0f), b = make_image(3, 1, 3, 0.0f);
    *sample(&a, 0, 0, 1) = *sample(&b, 0, 0, 1) = -INFINITY;
    *sample(&a, 1, 0, 0) = INFINITY;
    *sample(&b, 1, 0, 0) = -INFINITY;
    *sample(&b, 2, 0, 2) = INFINITY;
    image_diff_options options = image_diff_options_defaults();
    options.fail_percent = 100;
    rt_image difference;
    image_diff_result result = diff_ok_with_image(&a, &b, &options, &difference);
    assert_true(isinf(result.max_error) && isinf(result.mean_error) && isinf(result.rms_error));
    assert_int_equal(result.max_x, 1);
    assert_int_equal(result.failing_pixels, 2);
    assert_true(result.passed);
    assert_close(*sample(&difference, 0, 0, 1), 0, 0);
    assert_true(isinf(*sample(&difference, 1, 0, 0)));
    assert_true(isinf(*sample(&difference, 2, 0, 2)));
    assert_close(*sample(&difference, 2, 0, 0), 0, 0);
    image_free(&difference);
    free_pair(&a, &b);
}

/* Large images: the sums stay exact enough (OIIO sums in batches of pixels); 640x360,
 * every green sample off by 2^-8 and one red by 0.75. */
static void test_large_image(void **state)
{
    (void)state;
    rt_image a = make_image(640, 360, 3, 0.25f), b = make_image(640, 360, 3, 0.25f);
    for (int y = 0; y < 360; y++)
        for (int x = 0; x < 640; x++)
            *sample(&b, x, y, 1) = 0.25f + 1.0f / 256;
    *sample(&b, 600, 300, 0) = 1.0f;
    image_diff_result result = diff_ok(&a, &b, NULL);
    double samples = 640.0 * 360 * 3;
    assert_close(result.mean_error, (640.0 * 360 / 256 + 0.75) / samples, 1e-15);
    assert_close(result.rms_error, sqrt((640.0 * 360 / 65536 + 0.5625) / samples), 1e-15);
    assert_close(result.max_error, 0.75, 0);
    assert_int_equal(result.max_x, 600);
    assert_int_equal(result.max_y, 300);
    assert_int_equal(result.failing_pixels, 1);
    free_pair(&a, &b);
}

/* Only the first three channels count: alpha and extra channels may differ freely, and
 * the channel counts may differ. */
static void test_compares_at_most_three_channels(void **state)
{
    (void)state;
    rt_image a = make_image(2, 2, 5, 0.25f), b = make_image(2, 2, 3, 0.25f);
    *sample(&a, 1, 1, 3) = 1.0f;
    *sample(&a, 0, 1, 4) = -7.0f;
    image_diff_result result = diff_ok(&a, &b, NULL);
    assert_close(result.max_error, 0, 0);
    assert_true(result.passed);
    free_pair(&a, &b);

    /* Both RGBA, alpha wholly different. */
    a = make_image(2, 2, 4, 0.25f);
    b = make_image(2, 2, 4, 0.25f);
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 2; x++)
            *sample(&b, x, y, 3) = 1.0f;
    result = diff_ok(&a, &b, NULL);
    assert_close(result.max_error, 0, 0);
    assert_close(result.mean_error, 0, 0);
    assert_true(result.passed);
    free_pair(&a, &b);
}

/* A grey image against RGB compares just the one channel: the 0.5 in B's green is not
 * seen; mean = 0.25 / 4 samples. */
static void test_single_channel_against_rgb(void **state)
{
    (void)state;
    rt_image a = make_image(2, 2, 1, 0.0f), b = make_image(2, 2, 3, 0.0f);
    *sample(&b, 1, 1, 0) = 0.25f;
    *sample(&b, 0, 0, 1) = 0.5f;
    rt_image difference;
    image_diff_result result = diff_ok_with_image(&a, &b, NULL, &difference);
    assert_close(result.mean_error, 0.25 / 4, CLOSE);
    assert_close(result.max_error, 0.25, 0);
    assert_int_equal(result.max_x, 1);
    assert_int_equal(result.max_y, 1);
    /* The one compared channel is shown as grey: 0.25 * 16 = 4 in R, G and B. */
    assert_int_equal(difference.channels, 3);
    for (int c = 0; c < 3; c++) {
        assert_close(*sample(&difference, 1, 1, c), 4.0, 0);
        assert_close(*sample(&difference, 0, 0, c), 0.0, 0);
    }
    image_free(&difference);
    free_pair(&a, &b);
}

static void test_difference_image(void **state)
{
    (void)state;
    rt_image a, b;
    make_pair(&a, &b);
    *sample(&a, 0, 0, 1) = 0.75f;
    *sample(&b, 0, 0, 1) = 0.625f;  /* |d| = 0.125, sign must not matter */
    rt_image difference;

    /* Default scale 16. */
    diff_ok_with_image(&a, &b, NULL, &difference);
    assert_int_equal(difference.width, 2);
    assert_int_equal(difference.height, 2);
    assert_int_equal(difference.channels, 3);
    const float expected_16[2][2][3] = {
        {{0, 2, 0}, {8, 4, 0}},
        {{0, 0, 2}, {0, 0, 0}},
    };
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 2; x++)
            for (int c = 0; c < 3; c++)
                assert_close(*sample(&difference, x, y, c), expected_16[y][x][c], 0);
    image_free(&difference);

    image_diff_options options = image_diff_options_defaults();
    options.diff_scale = 2;
    diff_ok_with_image(&a, &b, &options, &difference);
    assert_close(*sample(&difference, 1, 0, 0), 1.0, 0);
    assert_close(*sample(&difference, 0, 1, 2), 0.25, 0);
    image_free(&difference);
    free_pair(&a, &b);
}

/* The difference image is the size of the inputs and RGB even when they have alpha. */
static void test_difference_image_from_rgba(void **state)
{
    (void)state;
    rt_image a = make_image(3, 1, 4, 0.5f), b = make_image(3, 1, 4, 0.5f);
    *sample(&b, 2, 0, 3) = 0.0f;
    *sample(&b, 2, 0, 2) = 0.25f;
    rt_image difference;
    diff_ok_with_image(&a, &b, NULL, &difference);
    assert_int_equal(difference.channels, 3);
    assert_close(*sample(&difference, 2, 0, 2), 4.0, 0);
    assert_close(*sample(&difference, 2, 0, 0), 0.0, 0);
    image_free(&difference);
    free_pair(&a, &b);
}

static void test_defaults_are_zero(void **state)
{
    (void)state;
    image_diff_options options = image_diff_options_defaults();
    assert_close(options.fail_threshold, 0, 0);
    assert_close(options.fail_percent, 0, 0);
    assert_close(options.hard_fail, 0, 0);
    assert_close(options.diff_scale, 0, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_metrics),
        cmocka_unit_test(test_metrics_are_symmetric),
        cmocka_unit_test(test_identical_images),
        cmocka_unit_test(test_max_location_first_of_ties),
        cmocka_unit_test(test_threshold_boundary),
        cmocka_unit_test(test_fail_percent_boundary),
        cmocka_unit_test(test_default_tolerance),
        cmocka_unit_test(test_hard_fail),
        cmocka_unit_test(test_size_mismatch),
        cmocka_unit_test(test_nan_is_an_error_naming_image_and_pixel),
        cmocka_unit_test(test_infinities),
        cmocka_unit_test(test_infinities_of_both_signs),
        cmocka_unit_test(test_large_image),
        cmocka_unit_test(test_compares_at_most_three_channels),
        cmocka_unit_test(test_single_channel_against_rgb),
        cmocka_unit_test(test_difference_image),
        cmocka_unit_test(test_difference_image_from_rgba),
        cmocka_unit_test(test_defaults_are_zero),
    };
    return cmocka_run_group_tests_name("image_diff", tests, NULL, NULL);
}
