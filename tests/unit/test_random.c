/* test_random.c: the renderer's sample values (glsl/random.glsl), drawn on the device
 * that renders (llvmpipe here), for both samplers: determinism, uniformity, independence
 * across pixels, components, samples, dimensions and seeds; for the Sobol sampler also
 * stratification: every power-of-two prefix of a pixel's samples is a (0,k,2)-net in
 * each 2D pair, and it integrates a discontinuous function with less error. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gpu.h"
#include "tracer_interface.h"
#include "support.h"

#define WIDTH 256
#define HEIGHT 128
#define COUNT ((size_t)WIDTH * HEIGHT * 4)


/* The sampler the per-pixel checks below run with (both, in turn: see main()). */
static int sampler_under_test;

/* The values of every pixel of a WIDTH x HEIGHT image for one sample; the caller frees. */
static float *draw(uint32_t sample_index, uint32_t seed, uint32_t dimension)
{
    float *numbers = malloc(COUNT * sizeof(float));
    assert_non_null(numbers);
    rt_error error;
    gpu_random_request request = {.width = WIDTH, .height = HEIGHT, .sample_index = sample_index, .seed = seed,
                                  .dimension = dimension, .sampler = sampler_under_test};
    assert_int_equal(gpu_random_numbers(gpu_fixture_context, &request, numbers, &error), RT_OK);
    return numbers;
}

/* The values of samples start .. start+count-1 (count a multiple of 64) of one pixel; the
 * caller frees. */
static float *draw_range(int sampler, uint32_t start, uint32_t count, int x, int y, uint32_t seed,
                         uint32_t dimension)
{
    float *numbers = malloc((size_t)count * 4 * sizeof(float));
    assert_non_null(numbers);
    rt_error error;
    gpu_random_request request = {.width = 64, .height = (int)(count / 64), .sample_index = start, .seed = seed,
                                  .dimension = dimension, .sampler = sampler, .over_samples = true,
                                  .fixed_pixel = {x, y}};
    assert_int_equal(gpu_random_numbers(gpu_fixture_context, &request, numbers, &error), RT_OK);
    return numbers;
}

/* The values of samples 0 .. count-1 of one pixel; the caller frees. */
static float *draw_samples(int sampler, uint32_t count, int x, int y, uint32_t seed, uint32_t dimension)
{
    return draw_range(sampler, 0, count, x, y, seed, dimension);
}

/* Pearson correlation of a[i*stride_a] and b[i*stride_b] over n pairs. */
static double correlation(const float *a, const float *b, size_t n, size_t stride)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    for (size_t i = 0; i < n; i++) {
        double x = a[i * stride], y = b[i * stride];
        sa += x, sb += y, saa += x * x, sbb += y * y, sab += x * y;
    }
    double covariance = sab / n - (sa / n) * (sb / n);
    return covariance / sqrt((saa / n - (sa / n) * (sa / n)) * (sbb / n - (sb / n) * (sb / n)));
}

static void same_inputs_same_numbers(void **state)
{
    (void)state;
    float *a = draw(5, 7, 3), *b = draw(5, 7, 3);
    assert_memory_equal(a, b, COUNT * sizeof(float));
    free(a);
    free(b);
}

static void numbers_are_in_unit_interval_and_uniform(void **state)
{
    (void)state;
    float *numbers = draw(0, 1, 0);
    enum { BINS = 64 };
    double histogram[BINS] = {0}, sum = 0, sum_squares = 0;
    for (size_t i = 0; i < COUNT; i++) {
        assert_true(numbers[i] >= 0.0f && numbers[i] < 1.0f);
        histogram[(int)(numbers[i] * BINS)]++;
        sum += numbers[i];
        sum_squares += (double)numbers[i] * numbers[i];
    }
    double mean = sum / COUNT, variance = sum_squares / COUNT - mean * mean;
    assert_float_equal(mean, 0.5, 0.003);
    assert_float_equal(variance, 1.0 / 12.0, 0.001);
    /* Chi-square with 63 degrees of freedom: 99.9% of uniform draws fall in [29, 104]. */
    double expected = (double)COUNT / BINS, chi_square = 0;
    for (int bin = 0; bin < BINS; bin++)
        chi_square += (histogram[bin] - expected) * (histogram[bin] - expected) / expected;
    assert_in_range((long)chi_square, 29, 104);
    free(numbers);
}

static void components_and_neighbours_uncorrelated(void **state)
{
    (void)state;
    float *numbers = draw(3, 1, 2);
    size_t pixels = (size_t)WIDTH * HEIGHT;
    /* The four numbers of a pixel against each other (|r| < 0.015 is ~5 sigma here). */
    for (int a = 0; a < 4; a++)
        for (int b = a + 1; b < 4; b++)
            assert_true(fabs(correlation(numbers + a, numbers + b, pixels, 4)) < 0.015);
    /* A pixel against its right and lower neighbours. */
    assert_true(fabs(correlation(numbers, numbers + 4, pixels - 1, 4)) < 0.015);
    assert_true(fabs(correlation(numbers, numbers + 4 * WIDTH, pixels - WIDTH, 4)) < 0.015);
    free(numbers);
}

static void samples_dimensions_and_seeds_are_independent(void **state)
{
    (void)state;
    float *base = draw(10, 1, 0);
    float *other[3] = {draw(11, 1, 0), draw(10, 1, 1), draw(10, 2, 0)};
    /* Samples of one pixel are independent only for the independent sampler: Sobol
     * samples 10 and 11 are an aligned pair, stratified on purpose (checked below). */
    for (int k = sampler_under_test == SAMPLER_SOBOL ? 1 : 0; k < 3; k++) {
        size_t equal = 0;
        for (size_t i = 0; i < COUNT; i++)
            equal += base[i] == other[k][i];
        assert_true(equal < COUNT / 1000);
        assert_true(fabs(correlation(base, other[k], COUNT, 1)) < 0.01);
        free(other[k]);
    }
    if (sampler_under_test == SAMPLER_SOBOL)
        free(other[0]);
    free(base);
}

/* True when the first n points (x = numbers[4 i + c], y = numbers[4 i + c + 1]), n = 2^k,
 * put exactly one point in every cell of every 2^a x 2^(k-a) grid of [0,1)^2: the
 * definition of a (0,k,2)-net in base 2. */
static bool is_net(const float *numbers, int component, int k)
{
    uint32_t n = 1u << k;
    bool ok = true;
    unsigned char *seen = calloc(n, 1);
    assert_non_null(seen);
    for (int a = 0; a <= k && ok; a++) {
        memset(seen, 0, n);
        for (uint32_t i = 0; i < n && ok; i++) {
            uint32_t column = (uint32_t)(numbers[4 * i + component] * (float)(1u << a));
            uint32_t row = (uint32_t)(numbers[4 * i + component + 1] * (float)(1u << (k - a)));
            uint32_t cell = (row << a) | column;
            ok = !seen[cell];
            seen[cell] = 1;
        }
    }
    free(seen);
    return ok;
}

static void sobol_prefixes_are_nets_in_every_pair(void **state)
{
    (void)state;
    enum { K = 12 };
    const int pixels[3][2] = {{0, 0}, {17, 3}, {1023, 700}};
    const uint32_t dimensions[4] = {0, 1, 13, 401};
    for (int p = 0; p < 3; p++)
        for (int d = 0; d < 4; d++) {
            float *numbers = draw_samples(SAMPLER_SOBOL, 1u << K, pixels[p][0], pixels[p][1], 3 + p, dimensions[d]);
            for (int k = 0; k <= K; k++) {
                if (!is_net(numbers, 0, k) || !is_net(numbers, 2, k))
                    fail_msg("pixel (%d, %d) dimension %u: the first 2^%d samples are not a (0,%d,2)-net",
                             pixels[p][0], pixels[p][1], dimensions[d], k, k);
            }
            free(numbers);
        }
}

static void sobol_aligned_blocks_are_nets(void **state)
{
    /* Sample ranges (--samples START:COUNT) and resumed renders start mid-sequence: a
     * block of 2^k samples starting at a multiple of 2^k is a net too (the shuffle maps
     * aligned blocks to aligned blocks), e.g. the samples 10 and 11 of one pixel. */
    (void)state;
    float *pair = draw_range(SAMPLER_SOBOL, 0, 64, 3, 3, 1, 0);
    for (uint32_t i = 0; i < 64; i += 2)
        assert_true(is_net(pair + 4 * i, 0, 1) && is_net(pair + 4 * i, 2, 1));
    free(pair);
    float *block = draw_range(SAMPLER_SOBOL, 3u << 10, 1u << 10, 3, 3, 1, 0);
    assert_true(is_net(block, 0, 10) && is_net(block, 2, 10));
    free(block);
}

static void independent_samples_are_not_nets(void **state)
{
    (void)state;
    /* The check above has power: independent numbers fail it (at 2^8 points a random set
     * is a net with a vanishing probability). */
    float *numbers = draw_samples(SAMPLER_INDEPENDENT, 256, 5, 5, 1, 0);
    assert_false(is_net(numbers, 0, 8));
    free(numbers);
}

/* Pearson correlation of two components over the first n samples of one pixel. */
static double sample_correlation(const float *numbers, int a, int b, size_t n)
{
    return correlation(numbers + a, numbers + b, n, 4);
}

static void sobol_pairs_dimensions_and_pixels_are_independent(void **state)
{
    (void)state;
    enum { N = 4096 };
    float *base = draw_samples(SAMPLER_SOBOL, N, 9, 4, 1, 2);
    float *other_dimension = draw_samples(SAMPLER_SOBOL, N, 9, 4, 1, 3);
    float *other_pixel = draw_samples(SAMPLER_SOBOL, N, 10, 4, 1, 2);
    float *other_seed = draw_samples(SAMPLER_SOBOL, N, 9, 4, 2, 2);
    /* |r| < 0.06 is ~4 sigma for 4096 independent pairs. Within a pair the Sobol points
     * are stratified, not independent, but still uncorrelated. */
    for (int a = 0; a < 4; a++)
        for (int b = a + 1; b < 4; b++)
            assert_true(fabs(sample_correlation(base, a, b, N)) < 0.06);
    float *others[3] = {other_dimension, other_pixel, other_seed};
    for (int k = 0; k < 3; k++) {
        for (int c = 0; c < 4; c++)
            assert_true(fabs(correlation(base + c, others[k] + c, N, 4)) < 0.06);
        free(others[k]);
    }
    free(base);
}

/* Mean squared error, over 64 pixels, of the share of n samples inside the disc of radius
 * 0.4 about (0.5, 0.5) (pair (x, y) of dimension 0), against its area. */
static double disc_estimate_error(int sampler, uint32_t n)
{
    double error = 0;
    const double area = 3.14159265358979 * 0.16;
    for (int pixel = 0; pixel < 64; pixel++) {
        float *numbers = draw_samples(sampler, n, pixel, 2 * pixel, 1, 0);
        uint32_t inside = 0;
        for (uint32_t i = 0; i < n; i++) {
            double dx = numbers[4 * i] - 0.5, dy = numbers[4 * i + 1] - 0.5;
            inside += dx * dx + dy * dy < 0.16;
        }
        double estimate = (double)inside / n;
        error += (estimate - area) * (estimate - area);
        free(numbers);
    }
    return error / 64;
}

static void sobol_integrates_a_disc_better(void **state)
{
    (void)state;
    /* A disc's edge is the kind of discontinuity pixel edges, shadows and light borders
     * make. Independent samples: mean squared error area (1 - area) / n; a (0,2)-sequence
     * converges about as n^-1.5 for such a function, so at 1024 samples it is many times
     * smaller (seen: ~30x). */
    double independent = disc_estimate_error(SAMPLER_INDEPENDENT, 1024);
    double sobol = disc_estimate_error(SAMPLER_SOBOL, 1024);
    print_message("disc, 1024 samples, mean squared error: independent %.3g, sobol %.3g\n", independent, sobol);
    assert_true(sobol * 8 < independent);
}

/* Runs the per-pixel checks with the Sobol sampler, then with the independent one. */
static int with_sobol(void **state)
{
    (void)state;
    sampler_under_test = SAMPLER_SOBOL;
    return 0;
}

static int with_independent(void **state)
{
    (void)state;
    sampler_under_test = SAMPLER_INDEPENDENT;
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(same_inputs_same_numbers, with_sobol),
        cmocka_unit_test_setup(numbers_are_in_unit_interval_and_uniform, with_sobol),
        cmocka_unit_test_setup(components_and_neighbours_uncorrelated, with_sobol),
        cmocka_unit_test_setup(samples_dimensions_and_seeds_are_independent, with_sobol),
        cmocka_unit_test_setup(same_inputs_same_numbers, with_independent),
        cmocka_unit_test_setup(numbers_are_in_unit_interval_and_uniform, with_independent),
        cmocka_unit_test_setup(components_and_neighbours_uncorrelated, with_independent),
        cmocka_unit_test_setup(samples_dimensions_and_seeds_are_independent, with_independent),
        cmocka_unit_test(sobol_prefixes_are_nets_in_every_pair),
        cmocka_unit_test(sobol_aligned_blocks_are_nets),
        cmocka_unit_test(independent_samples_are_not_nets),
        cmocka_unit_test(sobol_pairs_dimensions_and_pixels_are_independent),
        cmocka_unit_test(sobol_integrates_a_disc_better),
    };
    return cmocka_run_group_tests_name("sample values (on the device)", tests, gpu_fixture_set_up, gpu_fixture_tear_down);
}
