/* test_affine.c: unit tests of the parser's double-precision maths (core/affine.c). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "affine.h"

/* True when every element of a and b differ by at most tolerance. */
static bool affine_near(const affine *a, const affine *b, double tolerance)
{
    for (int row = 0; row < 3; row++)
        for (int column = 0; column < 4; column++)
            if (!(fabs(a->m[row][column] - b->m[row][column]) <= tolerance))
                return false;
    return true;
}

/* The identity composes away exactly, on either side. */
static void test_identity_composes_away(void **state)
{
    (void)state;
    double axis[3] = {0, 0.6, 0.8};
    affine rotation = affine_rotation(axis, 33);
    affine identity = affine_identity();
    affine left = affine_compose(&identity, &rotation);
    affine right = affine_compose(&rotation, &identity);
    assert_memory_equal(&left, &rotation, sizeof rotation);
    assert_memory_equal(&right, &rotation, sizeof rotation);
}

/* compose(outer, inner) applies inner first: translating a scaled point moves it by the
 * translation unscaled. */
static void test_compose_applies_inner_first(void **state)
{
    (void)state;
    double offset[3] = {1, 2, 3}, factors[3] = {2, 2, 2};
    affine translation = affine_translation(offset), scale = affine_scale(factors);
    affine scale_then_translate = affine_compose(&translation, &scale);
    affine expected = {{{2, 0, 0, 1}, {0, 2, 0, 2}, {0, 0, 2, 3}}};
    assert_memory_equal(&scale_then_translate, &expected, sizeof expected);
    affine translate_then_scale = affine_compose(&scale, &translation);
    affine expected_too = {{{2, 0, 0, 2}, {0, 2, 0, 4}, {0, 0, 2, 6}}};
    assert_memory_equal(&translate_then_scale, &expected_too, sizeof expected_too);
}

/* A rotation is right-handed: 90 degrees about +Z takes +X to +Y; its determinant is 1. */
static void test_rotation_is_right_handed(void **state)
{
    (void)state;
    double z[3] = {0, 0, 1};
    affine quarter = affine_rotation(z, 90);
    affine expected = {{{0, -1, 0, 0}, {1, 0, 0, 0}, {0, 0, 1, 0}}};
    assert_true(affine_near(&quarter, &expected, 1e-15));
    double axis[3] = {0.48, 0.6, 0.64};
    affine turn = affine_rotation(axis, 71);
    assert_true(fabs(affine_determinant(&turn) - 1) <= 1e-14);
    /* Four quarter turns are the identity, to rounding. */
    affine full = quarter;
    for (int i = 0; i < 3; i++)
        full = affine_compose(&quarter, &full);
    affine identity = affine_identity();
    assert_true(affine_near(&full, &identity, 1e-15));
}

/* The determinant of the linear part: a scale's product, negative for a mirror, 0 for a
 * map that flattens space; the translation does not count. */
static void test_determinant(void **state)
{
    (void)state;
    double factors[3] = {2, 3, 4}, mirror[3] = {-1, 1, 1};
    affine scale = affine_scale(factors), mirrored = affine_scale(mirror);
    assert_true(affine_determinant(&scale) == 24);
    assert_true(affine_determinant(&mirrored) == -1);
    affine flat = {{{1, 2, 3, 7}, {2, 4, 6, 8}, {0, 0, 1, 9}}};
    assert_true(affine_determinant(&flat) == 0);
}

/* Normalising divides by the largest component first, so that tiny and huge vectors
 * keep their direction; a zero vector has none and leaves the output untouched. */
static void test_normalise(void **state)
{
    (void)state;
    double unit[3];
    double tiny[3] = {3e-300, 4e-300, 0};
    assert_true(vector_normalise(tiny, unit));
    assert_true(fabs(unit[0] - 0.6) <= 1e-15 && fabs(unit[1] - 0.8) <= 1e-15 && unit[2] == 0);
    double huge[3] = {0, -1e300, 1e300};
    assert_true(vector_normalise(huge, unit));
    assert_true(unit[0] == 0 && fabs(unit[1] + sqrt(0.5)) <= 1e-15 && fabs(unit[2] - sqrt(0.5)) <= 1e-15);
    double zero[3] = {0, -0.0, 0}, untouched[3] = {7, 8, 9};
    assert_false(vector_normalise(zero, untouched));
    assert_true(untouched[0] == 7 && untouched[1] == 8 && untouched[2] == 9);
    float rounded[3] = {5, 5, 5};
    double down[3] = {0, -2, 0};
    assert_true(vector_normalise_to_float(down, rounded));
    assert_true(rounded[0] == 0 && rounded[1] == -1 && rounded[2] == 0);
    assert_false(vector_normalise_to_float(zero, rounded));
    assert_true(rounded[1] == -1);
}

/* The cross product is right-handed; the length is Euclidean. */
static void test_cross_and_length(void **state)
{
    (void)state;
    double x[3] = {1, 0, 0}, y[3] = {0, 1, 0}, out[3];
    vector_cross(x, y, out);
    assert_true(out[0] == 0 && out[1] == 0 && out[2] == 1);
    vector_cross(y, x, out);
    assert_true(out[2] == -1);
    double v[3] = {2, 3, 6};
    assert_true(vector_length(v) == 7);
}

/* Parallel means a sine of the angle of at most 1e-6, whatever the lengths; a zero
 * vector counts as parallel to everything. */
static void test_parallel(void **state)
{
    (void)state;
    double x[3] = {1, 0, 0}, twice_x[3] = {2, 0, 0}, minus_x[3] = {-5, 0, 0}, y[3] = {0, 1, 0};
    double zero[3] = {0, 0, 0}, almost_x[3] = {1, 1e-7, 0}, tilted[3] = {1, 1e-5, 0};
    double tiny_x[3] = {1e-20, 0, 0}, huge_y[3] = {0, 1e20, 0};
    assert_true(vectors_parallel(x, twice_x));
    assert_true(vectors_parallel(x, minus_x));
    assert_false(vectors_parallel(x, y));
    assert_true(vectors_parallel(zero, y));
    assert_true(vectors_parallel(x, zero));
    assert_true(vectors_parallel(x, almost_x));
    assert_false(vectors_parallel(x, tilted));
    assert_false(vectors_parallel(tiny_x, huge_y));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identity_composes_away),
        cmocka_unit_test(test_compose_applies_inner_first),
        cmocka_unit_test(test_rotation_is_right_handed),
        cmocka_unit_test(test_determinant),
        cmocka_unit_test(test_normalise),
        cmocka_unit_test(test_cross_and_length),
        cmocka_unit_test(test_parallel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
