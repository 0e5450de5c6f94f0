/* test_random.c: the renderer's random numbers (glsl/random.glsl), drawn on the device
 * that renders (llvmpipe here): determinism, uniformity, independence across pixels,
 * components, samples, dimensions and seeds. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gpu.h"
#include "support.h"

#define WIDTH 256
#define HEIGHT 128
#define COUNT ((size_t)WIDTH * HEIGHT * 4)


static float *draw(uint32_t sample_index, uint32_t seed, uint32_t dimension)
{
    float *numbers = malloc(COUNT * sizeof(float));
    assert_non_null(numbers);
    rt_error error;
    assert_int_equal(
        gpu_random_numbers(gpu_fixture_context, WIDTH, HEIGHT, sample_index, seed, dimension, numbers, &error), RT_OK);
    return numbers;
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
    for (int k = 0; k < 3; k++) {
        size_t equal = 0;
        for (size_t i = 0; i < COUNT; i++)
            equal += base[i] == other[k][i];
        assert_true(equal < COUNT / 1000);
        assert_true(fabs(correlation(base, other[k], COUNT, 1)) < 0.01);
        free(other[k]);
    }
    free(base);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(same_inputs_same_numbers),
        cmocka_unit_test(numbers_are_in_unit_interval_and_uniform),
        cmocka_unit_test(components_and_neighbours_uncorrelated),
        cmocka_unit_test(samples_dimensions_and_seeds_are_independent),
    };
    return cmocka_run_group_tests_name("random numbers (on the device)", tests, gpu_fixture_set_up, gpu_fixture_tear_down);
}
