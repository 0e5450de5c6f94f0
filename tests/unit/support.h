/* support.h: the helpers the cmocka unit tests share (header only: each test includes it
 * after its own headers; every helper is static inline, so a test pays only for what it
 * calls).
 *
 *   assert_close(actual, expected, tolerance)      doubles within an absolute tolerance
 *   assert_double_equal(actual, expected, tolerance)  the same check, cmocka's naming
 *   assert_relative(actual, expected, relative)    doubles within a fraction of expected
 *   assert_contains(haystack, needle)              a string holds a fixed substring
 *   make_image(width, height, channels, value)     an image with every sample = value
 *   assert_merge_metadata_equal(actual, expected)  every field of two merge_metadata
 *   splitmix64_next(&state)                        reproducible 64-bit test data
 *   random_source, random_float, random_below      the same, as floats and integers
 *   same_box(a, b), box_contains(outer, inner)     bvh_box comparisons
 *   gpu_fixture_set_up / gpu_fixture_tear_down   a cmocka group setup/teardown pair making
 *            gpu_fixture_context, the one GPU context of a test binary that renders
 *   scratch: make_scratch / remove_scratch (a cmocka setup/teardown pair), in_scratch,
 *            write_file, scratch_write             a fresh directory per test
 *   scratch_test(test)                             a test table entry with that pair
 *   skip_because(test, reason)                     skips the running test, with the "SKIP
 *            name: reason" line tests/run.sh lists (cmocka's skip() gives no reason)
 *
 * The assertions fail the running test at the caller's file and line, as cmocka's own
 * assert_* do; the value printed is the expression as written in the test. */
#ifndef RT_TEST_SUPPORT_H
#define RT_TEST_SUPPORT_H

/* cmocka.h needs these four before it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <errno.h>
#include <ftw.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bvh.h"
#include "image_io.h"
#include "merge.h"

/* ---- float assertions -------------------------------------------------------------------- */

/* Fails the test at file:line unless actual equals expected or lies within tolerance of it
 * (equality first, so that two equal infinities pass); what names the expression. cmocka
 * 1.1's assert_float_equal compares in single precision, which these tests cannot use. */
static inline void support_check_close(double actual, double expected, double tolerance, const char *what,
                                       const char *file, int line)
{
    if (actual == expected || fabs(actual - expected) <= tolerance)
        return;
    print_error("%s is %.17g, expected %.17g (within %g)\n", what, actual, expected, tolerance);
    _fail(file, line);
}

#define assert_close(actual, expected, tolerance) \
    support_check_close((actual), (expected), (tolerance), #actual, __FILE__, __LINE__)

/* The same check as assert_close, under the name cmocka's assert_float_equal suggests. */
#define assert_double_equal(actual, expected, tolerance) assert_close(actual, expected, tolerance)

/* Fails unless actual is within relative (a fraction, 0.01 = 1%) of expected. */
#define assert_relative(actual, expected, relative)                                                   \
    support_check_close((actual), (expected), (relative) * fabs((double)(expected)), #actual, __FILE__, \
                        __LINE__)

/* ---- string assertions ------------------------------------------------------------------- */

/* Fails the test at file:line unless haystack contains needle (a fixed string). */
static inline void support_check_contains(const char *haystack, const char *needle, const char *file, int line)
{
    if (strstr(haystack, needle) != NULL)
        return;
    print_error("'%s' does not contain '%s'\n", haystack, needle);
    _fail(file, line);
}

#define assert_contains(haystack, needle) support_check_contains((haystack), (needle), __FILE__, __LINE__)

/* ---- images ------------------------------------------------------------------------------ */

/* Returns a width x height image of channels channels with every sample set to value
 * (channel names the image_create defaults); the caller frees it with image_free. */
static inline rt_image make_image(int width, int height, int channels, float value)
{
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, width, height, channels, &error), RT_OK);
    for (size_t i = 0; i < (size_t)width * height * channels; i++)
        image.pixels[i] = value;
    return image;
}

/* ---- merge metadata ---------------------------------------------------------------------- */

/* Fails the test at file:line unless every field of *actual equals *expected's (the
 * numbers exactly: they went through a file as text or as exact floats). */
static inline void support_check_merge_metadata(const merge_metadata *actual, const merge_metadata *expected,
                                                const char *file, int line)
{
    _assert_string_equal(actual->scene, expected->scene, file, line);
    _assert_string_equal(actual->scene_hash, expected->scene_hash, file, line);
    _assert_true(actual->seed == expected->seed, "seed", file, line);
    _assert_int_equal(actual->max_depth, expected->max_depth, file, line);
    _assert_int_equal(actual->frame, expected->frame, file, line);
    _assert_true(actual->sample_start == expected->sample_start, "sample_start", file, line);
    _assert_int_equal(actual->spp, expected->spp, file, line);
    _assert_int_equal(actual->complete, expected->complete, file, line);
    _assert_true(actual->render_seconds == expected->render_seconds, "render_seconds", file, line);
    _assert_true(actual->path_segments == expected->path_segments, "path_segments", file, line);
    _assert_string_equal(actual->postprocess, expected->postprocess, file, line);
}

#define assert_merge_metadata_equal(actual, expected) \
    support_check_merge_metadata((actual), (expected), __FILE__, __LINE__)

/* ---- random test data -------------------------------------------------------------------- */

/* Advances *state and returns the next number of the splitmix64 sequence: the same
 * numbers on every machine and run, so a test's random scene is always the same scene. */
static inline uint64_t splitmix64_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* A splitmix64 stream for the helpers below. */
typedef struct random_source {
    uint64_t state;
} random_source;

/* Returns a float in [low, high). */
static inline float random_float(random_source *source, float low, float high)
{
    float unit = (float)(splitmix64_next(&source->state) >> 40) * 0x1.0p-24f;
    /* Not low + (high - low) * unit: high - low overflows for ranges near FLT_MAX. */
    return low * (1 - unit) + high * unit;
}

/* Returns an integer in [0, bound). */
static inline uint32_t random_below(random_source *source, uint32_t bound)
{
    return (uint32_t)(splitmix64_next(&source->state) % bound);
}

/* ---- statistics -------------------------------------------------------------------------- */

/* The regularised lower incomplete gamma function P(a, x): its series below a + 1, its
 * continued fraction (modified Lentz) above. A chi-square statistic of k degrees of
 * freedom has the p-value 1 - P(k / 2, statistic / 2). */
static inline double lower_gamma_regularised(double a, double x)
{
    if (x <= 0)
        return 0;
    double log_prefactor = a * log(x) - x - lgamma(a);
    if (x < a + 1) {
        double term = 1 / a, sum = term;
        for (int n = 1; n < 100000 && fabs(term) > fabs(sum) * 1e-15; n++) {
            term *= x / (a + n);
            sum += term;
        }
        return sum * exp(log_prefactor);
    }
    double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
    for (int n = 1; n < 100000; n++) {
        double an = -n * (n - a);
        b += 2;
        d = an * d + b;
        d = fabs(d) < 1e-300 ? 1e-300 : d;
        c = b + an / c;
        c = fabs(c) < 1e-300 ? 1e-300 : c;
        d = 1 / d;
        double delta = d * c;
        h *= delta;
        if (fabs(delta - 1) < 1e-15)
            break;
    }
    return 1 - exp(log_prefactor) * h;
}

/* ---- boxes ------------------------------------------------------------------------------- */

/* Whether two boxes are equal, bound for bound. */
static inline bool same_box(const bvh_box *a, const bvh_box *b)
{
    for (int axis = 0; axis < 3; axis++)
        if (a->min[axis] != b->min[axis] || a->max[axis] != b->max[axis])
            return false;
    return true;
}

/* Whether inner lies inside outer (an empty inner, min > max, lies inside anything). */
static inline bool box_contains(const bvh_box *outer, const bvh_box *inner)
{
    for (int axis = 0; axis < 3; axis++)
        if (inner->min[axis] < outer->min[axis] || inner->max[axis] > outer->max[axis])
            return false;
    return true;
}

/* ---- scratch directories ----------------------------------------------------------------- */

/* A fresh directory for one test (cmocka's state), removed with what the test left in it. */
typedef struct scratch {
    char directory[128]; /* short, so that tests may put it in fixed-size buffers */
    char path[512];      /* the last path made by in_scratch() */
} scratch;

/* cmocka setup: makes $TMPDIR/PROGRAM.XXXXXX (/tmp without TMPDIR) and stores a malloc'ed
 * scratch in *state; returns 0, or -1 (the test then fails) when it cannot. */
static inline int make_scratch(void **state)
{
    scratch *s = calloc(1, sizeof *s);
    if (s == NULL)
        return -1;
    const char *tmp = getenv("TMPDIR");
    snprintf(s->directory, sizeof s->directory, "%s/%s.XXXXXX", tmp && *tmp ? tmp : "/tmp",
             program_invocation_short_name);
    if (mkdtemp(s->directory) == NULL) {
        free(s);
        return -1;
    }
    *state = s;
    return 0;
}

/* nftw callback of remove_scratch: removes one file, link or (already emptied) directory. */
static inline int support_remove_entry(const char *path, const struct stat *info, int type, struct FTW *walk)
{
    (void)info, (void)type, (void)walk;
    return remove(path);
}

/* cmocka teardown: removes the scratch directory and everything in it (without following
 * links), and frees the scratch; returns 0 when all of it was removed. */
static inline int remove_scratch(void **state)
{
    scratch *s = *state;
    int result = nftw(s->directory, support_remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    free(s);
    return result == 0 ? 0 : -1;
}

/* An entry of a cmocka test table: test, run in a scratch directory of its own. */
#define scratch_test(test) cmocka_unit_test_setup_teardown(test, make_scratch, remove_scratch)

/* Returns directory/name in the scratch's path buffer (overwritten by the next call). */
static inline const char *in_scratch(scratch *s, const char *name)
{
    snprintf(s->path, sizeof s->path, "%s/%s", s->directory, name);
    return s->path;
}

/* Writes length bytes to directory/name, making the directories name passes through when
 * missing, and fails the test unless every byte is written; returns the path (in the
 * scratch's buffer). */
static inline const char *scratch_write(scratch *s, const char *name, const void *bytes, size_t length)
{
    for (const char *slash = strchr(name, '/'); slash != NULL; slash = strchr(slash + 1, '/')) {
        char directory[sizeof s->path];
        snprintf(directory, sizeof directory, "%s/%.*s", s->directory, (int)(slash - name), name);
        if (mkdir(directory, 0700) != 0 && errno != EEXIST)
            fail_msg("cannot make %s: %s", directory, strerror(errno));
    }
    const char *path = in_scratch(s, name);
    FILE *file = fopen(path, "wb");
    assert_non_null(file);
    assert_int_equal(fwrite(bytes, 1, length, file), length);
    assert_int_equal(fclose(file), 0);
    return path;
}

/* Writes the string text to directory/name as scratch_write does; returns the path. */
static inline const char *write_file(scratch *s, const char *name, const char *text)
{
    return scratch_write(s, name, text, strlen(text));
}

/* ---- a GPU context for the group -------------------------------------------------------- */

#include "gpu.h"

static gpu_context *gpu_fixture_context;

/* Group setup: creates gpu_fixture_context (a failure fails the group with the message). */
static inline int gpu_fixture_set_up(void **state)
{
    (void)state;
    rt_error error;
    if (gpu_create(NULL, &gpu_fixture_context, &error) != RT_OK) {
        print_error("%s\n", error.message);
        return -1;
    }
    return 0;
}

/* Group teardown: destroys gpu_fixture_context. */
static inline int gpu_fixture_tear_down(void **state)
{
    (void)state;
    gpu_destroy(gpu_fixture_context);
    gpu_fixture_context = NULL;
    return 0;
}

/* ---- skips ---------------------------------------------------------------------------------- */

/* Skips the running test (a check this machine cannot run) and prints the "SKIP name: reason"
 * line that tests/run.sh counts and lists; test is the test function's name. */
#define skip_because(test, reason)                 \
    do {                                           \
        printf("SKIP %s: %s\n", #test, (reason)); \
        fflush(stdout);                            \
        skip();                                    \
    } while (0)

#endif
