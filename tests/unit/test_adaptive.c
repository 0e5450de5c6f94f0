/* test_adaptive.c: adaptive sampling's estimator, schedule, decisions and pass tiles
 * (adaptive.h), on sums made up here, without a GPU. */
#include "adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

/* The error of known samples, worked by hand. */
static void pixel_error(void **state)
{
    (void)state;
    /* Luminances 0, 1, 0, 1: mean 0.5, sample variance (2 - 4 * 0.25) / 3 = 1/3, standard
     * error sqrt(1/12) = 0.288675, relative to the mean 0.57735. */
    assert_close(adaptive_pixel_error(2.0f, 2.0f, 4), sqrt(1.0 / 12.0) / 0.5, 1e-6);
    /* Equal samples: no error, whatever their value (also 0: a black pixel). */
    assert_close(adaptive_pixel_error(16 * 0.3f, 16 * 0.09f, 16), 0.0, 1e-3);
    assert_close(adaptive_pixel_error(0.0f, 0.0f, 16), 0.0, 0.0);
    /* Below the floor the error is absolute: samples 0 and 0.02 (mean 0.01) over the floor. */
    float sum = 8 * 0.02f, squares = 8 * 0.02f * 0.02f;
    double variance = (squares - 16 * 0.01 * 0.01) / 15;
    assert_close(adaptive_pixel_error(sum, squares, 16), sqrt(variance / 16) / ADAPTIVE_LUMINANCE_FLOOR, 1e-5);
    /* One sample tells nothing about the noise. */
    assert_true(isinf(adaptive_pixel_error(0.5f, 0.25f, 1)));
}

static void schedule(void **state)
{
    (void)state;
    assert_int_equal(adaptive_next_check(0, 16, 1024), 16);
    assert_int_equal(adaptive_next_check(16, 16, 1024), 32);
    assert_int_equal(adaptive_next_check(64, 16, 1024), 80);
    assert_int_equal(adaptive_next_check(100, 16, 1024), 125);
    assert_int_equal(adaptive_next_check(1000, 16, 1024), 1024);
    assert_int_equal(adaptive_next_check(0, 16, 8), 8);
    /* Checks before the last: 16 32 48 64 80 100 125 156 195 243 303 378 472 590 737 921. */
    assert_int_equal(adaptive_reach(16, 1024), 16);
    assert_int_equal(adaptive_reach(16, 16), 0);
    assert_int_equal(adaptive_reach(16, 32), 1);
}

/* An 8x8 image of pixels with n samples each of luminance value (R = G = B = value), all
 * with no noise but pixel (noisy_x, noisy_y), whose samples alternate 0 and 2 * value. */
static void make_sums(float *rgba, float *squares, int n, float value, int noisy_x, int noisy_y)
{
    for (int i = 0; i < 64; i++) {
        for (int c = 0; c < 3; c++)
            rgba[4 * i + c] = n * value;
        rgba[4 * i + 3] = (float)n;
        squares[i] = n * value * value;
    }
    squares[noisy_y * 8 + noisy_x] = (n / 2) * (2 * value) * (2 * value);
}

/* A noisy pixel keeps its 3x3 neighbourhood going, the rest stop at min_spp. */
static void neighbourhood(void **state)
{
    (void)state;
    adaptive_sampler *sampler = NULL;
    assert_int_equal(adaptive_create(8, 8, 0.05f, 16, 256, &sampler, NULL), RT_OK);
    for (int i = 0; i < 64; i++)
        assert_int_equal(adaptive_limits(sampler)[i], 16);
    float rgba[64 * 4], squares[64];
    make_sums(rgba, squares, 16, 0.5f, 4, 4);
    assert_int_equal(adaptive_check(sampler, rgba, squares), 9);
    assert_true(adaptive_stopped_early(sampler));
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            bool near = abs(x - 4) <= 1 && abs(y - 4) <= 1;
            assert_int_equal(adaptive_limits(sampler)[y * 8 + x], near ? 32 : 16);
        }
    /* Next check: the noisy pixel is quiet now; all stop, the stopped ones stay at 16. */
    make_sums(rgba, squares, 32, 0.5f, 0, 0);
    squares[0] = 32 * 0.25f;  /* pixel (0, 0) stopped at 16: its sums are not looked at */
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++)
            if (!(abs(x - 4) <= 1 && abs(y - 4) <= 1))
                rgba[4 * (y * 8 + x) + 3] = 16;
    assert_int_equal(adaptive_check(sampler, rgba, squares), 0);
    assert_int_equal(adaptive_limits(sampler)[0], 16);
    assert_int_equal(adaptive_limits(sampler)[4 * 8 + 4], 32);
    adaptive_free(sampler);
}

/* A pixel that saw no light (0 with no noise) stops only when its neighbours agree; at
 * max_spp everything stops, and that is not an early stop. */
static void dark_pixels_and_max(void **state)
{
    (void)state;
    adaptive_sampler *sampler = NULL;
    assert_int_equal(adaptive_create(8, 8, 0.05f, 16, 32, &sampler, NULL), RT_OK);
    float rgba[64 * 4], squares[64];
    make_sums(rgba, squares, 16, 0.5f, 2, 2);
    for (int c = 0; c < 4; c++)
        rgba[4 * (2 * 8 + 3) + c] = c == 3 ? 16 : 0;   /* pixel (3, 2): black so far */
    squares[2 * 8 + 3] = 0;
    assert_int_equal(adaptive_check(sampler, rgba, squares), 9);
    assert_int_equal(adaptive_limits(sampler)[2 * 8 + 3], 32);
    make_sums(rgba, squares, 32, 0.5f, 2, 2);
    assert_int_equal(adaptive_check(sampler, rgba, squares), 0);
    adaptive_free(sampler);

    assert_int_equal(adaptive_create(8, 8, 0.05f, 16, 16, &sampler, NULL), RT_OK);
    make_sums(rgba, squares, 16, 0.5f, 2, 2);
    assert_int_equal(adaptive_check(sampler, rgba, squares), 0);
    assert_false(adaptive_stopped_early(sampler));
    adaptive_free(sampler);
}

/* The pixels the next passes trace: every pixel at first, then those a check left going
 * (the noisy one and its 3x3 neighbourhood, cut at the image's corner), rows from the top,
 * in raster order. */
static void going_pixels(void **state)
{
    (void)state;
    adaptive_sampler *sampler = NULL;
    assert_int_equal(adaptive_create(20, 10, 0.05f, 16, 256, &sampler, NULL), RT_OK);
    uint32_t pixels[200];
    assert_int_equal(adaptive_going_pixels(sampler, pixels), 200);
    for (uint32_t i = 0; i < 200; i++)
        assert_int_equal(pixels[i], i);
    float rgba[200 * 4], squares[200];
    for (int i = 0; i < 200; i++) {
        for (int c = 0; c < 3; c++)
            rgba[4 * i + c] = 16 * 0.5f;
        rgba[4 * i + 3] = 16;
        squares[i] = 16 * 0.25f;
    }
    squares[9 * 20 + 19] = 8 * 1.0f;   /* pixel (19, 9): noisy, in the bottom-right corner */
    assert_int_equal(adaptive_check(sampler, rgba, squares), 4);
    assert_int_equal(adaptive_going_pixels(sampler, pixels), 4);
    const uint32_t expected[4] = {8 * 20 + 18, 8 * 20 + 19, 9 * 20 + 18, 9 * 20 + 19};
    assert_memory_equal(pixels, expected, sizeof expected);
    adaptive_free(sampler);
}

/* The runs a pixel going on takes (gpu.h gpu_tracer_set_pass_pixels) follow the checks'
 * sample counts alone: about ADAPTIVE_RUN_SAMPLES samples a run, 1 to ADAPTIVE_MAX_RUNS,
 * the same for an image with 9 pixels going as for one with 18 (a tile and the whole
 * image must split a pixel's samples alike). */
static void runs_follow_the_checks(void **state)
{
    (void)state;
    adaptive_sampler *few = NULL, *more = NULL;
    assert_int_equal(adaptive_create(8, 8, 0.001f, 16, 1024, &few, NULL), RT_OK);
    assert_int_equal(adaptive_create(8, 8, 0.001f, 16, 1024, &more, NULL), RT_OK);
    float rgba[64 * 4], squares[64];
    int checks = 0;
    for (uint32_t n = 16; n < 1024; n = adaptive_next_check(n, 16, 1024), checks++) {
        make_sums(rgba, squares, (int)n, 0.5f, 4, 4);
        assert_int_equal(adaptive_check(few, rgba, squares), 9);
        squares[1 * 8 + 1] = squares[4 * 8 + 4];   /* a second noisy pixel, far from the first */
        assert_int_equal(adaptive_check(more, rgba, squares), 18);
        uint32_t next = adaptive_next_check(n, 16, 1024), expected = (next - n) / ADAPTIVE_RUN_SAMPLES;
        expected = expected < 1 ? 1 : expected > ADAPTIVE_MAX_RUNS ? ADAPTIVE_MAX_RUNS : expected;
        assert_int_equal(adaptive_runs(few), expected);
        assert_int_equal(adaptive_runs(more), expected);
    }
    /* 16 -> 32 takes 2 runs of 8; 800 -> 1000 would take 25 of 8, capped at 16. */
    assert_true(checks > 10);
    adaptive_free(few);
    adaptive_free(more);
}

/* A sampler resumed from a stopped render's limits and samples (adaptive_resume) makes
 * the check it was waiting for as the sampler that never stopped does: the same pixels
 * go on, with the same limits and runs. Before the first check every pixel goes on,
 * whatever it has finished; limits of another schedule are refused. */
static void resume_where_it_stopped(void **state)
{
    (void)state;
    adaptive_sampler *original = NULL, *resumed = NULL;
    assert_int_equal(adaptive_create(8, 8, 0.05f, 16, 256, &original, NULL), RT_OK);
    float rgba[64 * 4], squares[64];
    make_sums(rgba, squares, 16, 0.5f, 2, 2);
    assert_int_equal(adaptive_check(original, rgba, squares), 9);
    /* Waiting for the check at 32: the pixels going have 32 samples, the rest their 16. */
    uint32_t limits[64], samples[64];
    make_sums(rgba, squares, 32, 0.5f, 2, 2);
    for (int i = 0; i < 64; i++) {
        if (adaptive_limits(original)[i] == 16) {
            for (int c = 0; c < 4; c++)
                rgba[4 * i + c] /= 2;
            squares[i] /= 2;
        }
        samples[i] = limits[i] = (uint32_t)rgba[4 * i + 3];
    }
    assert_int_equal(adaptive_create(8, 8, 0.05f, 16, 256, &resumed, NULL), RT_OK);
    assert_int_equal(adaptive_resume(resumed, limits, samples, NULL), RT_OK);
    assert_memory_equal(adaptive_limits(resumed), limits, sizeof limits);
    assert_true(adaptive_stopped_early(resumed));
    /* (2, 2) is still noisy: it and its neighbours go on. */
    assert_int_equal(adaptive_check(original, rgba, squares), 9);
    assert_int_equal(adaptive_check(resumed, rgba, squares), 9);
    assert_memory_equal(adaptive_limits(resumed), adaptive_limits(original), sizeof limits);
    assert_int_equal(adaptive_limits(resumed)[2 * 8 + 2], 48);
    assert_int_equal(adaptive_runs(resumed), adaptive_runs(original));
    adaptive_noise noise_original, noise_resumed;
    adaptive_get_noise(original, &noise_original);
    adaptive_get_noise(resumed, &noise_resumed);
    assert_int_equal(noise_resumed.checks, noise_original.checks);
    adaptive_free(resumed);

    /* Before the first check: every pixel goes on to 16, whatever it has. */
    for (int i = 0; i < 64; i++) {
        limits[i] = 16;
        samples[i] = (uint32_t)(i % 17);
    }
    assert_int_equal(adaptive_create(8, 8, 0.05f, 16, 256, &resumed, NULL), RT_OK);
    assert_int_equal(adaptive_resume(resumed, limits, samples, NULL), RT_OK);
    uint32_t pixels[64];
    assert_int_equal(adaptive_going_pixels(resumed, pixels), 64);
    assert_false(adaptive_stopped_early(resumed));

    /* Not this schedule: a next check at 24 (min-spp 16 checks at 16, 32, 48, ...); a
     * stopped pixel whose samples are not its limit; a pixel going past the check. */
    rt_error error = {{0}};
    for (int i = 0; i < 64; i++)
        samples[i] = limits[i] = 24;
    assert_int_equal(adaptive_resume(resumed, limits, samples, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "check at 24 samples"));
    for (int i = 0; i < 64; i++)
        samples[i] = limits[i] = 32;
    samples[9] = limits[9] = 16;
    samples[9] = 15;
    assert_int_equal(adaptive_resume(resumed, limits, samples, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "pixel 1,1 (15 samples, limit 16)"));
    samples[9] = 16;
    samples[10] = 33;
    assert_int_equal(adaptive_resume(resumed, limits, samples, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "pixel 2,1 (33 samples, limit 32)"));
    samples[10] = 32;
    assert_int_equal(adaptive_resume(resumed, limits, samples, &error), RT_OK);
    adaptive_free(resumed);
    adaptive_free(original);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pixel_error),
        cmocka_unit_test(schedule),
        cmocka_unit_test(neighbourhood),
        cmocka_unit_test(dark_pixels_and_max),
        cmocka_unit_test(going_pixels),
        cmocka_unit_test(runs_follow_the_checks),
        cmocka_unit_test(resume_where_it_stopped),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
