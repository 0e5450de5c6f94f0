/* image_compare.h: one comparison of a new image with a reference, by either test:
 * IMAGE_COMPARE_IDIFF (image_diff.h: fixed thresholds in the spirit of idiff, for cases where
 * exactness is the point and for images without variance) or IMAGE_COMPARE_Z
 * (image_stat_diff.h: is the difference more than the samples' noise explains?). What
 * `rtspheres diff` and `rtspheres check` (suite.h) run; docs/regression.md says which to
 * use when.
 *
 * Defaults of image_compare_options (zero means default): the idiff test, and each test's
 * own defaults (image_diff.h, image_stat_diff.h).
 */
#ifndef RT_IMAGE_COMPARE_H
#define RT_IMAGE_COMPARE_H

#include <stdbool.h>
#include <stddef.h>

#include "image_diff.h"
#include "image_io.h"
#include "image_stat_diff.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum image_compare_test {
    IMAGE_COMPARE_IDIFF = 0,
    IMAGE_COMPARE_Z,
} image_compare_test;

typedef struct image_compare_options {
    image_compare_test test;
    image_diff_options idiff;    /* the idiff test's; with the z test, only diff_scale
                                  * (of the difference image) is used */
    image_stat_options stat;     /* the z test's */
} image_compare_options;

typedef struct image_compare_result {
    image_compare_test test;
    bool sizes_differ;           /* then nothing else is filled and passed is false */
    int width, height;           /* a's size */
    int other_width, other_height;  /* b's */
    int channels_compared;       /* the idiff test's: min(3, channels of a, of b) */
    image_diff_result idiff;     /* the idiff metrics: with either test (its verdict counts
                                  * only with IMAGE_COMPARE_IDIFF) */
    image_stat_result stat;      /* with IMAGE_COMPARE_Z */
    bool passed;
} image_compare_result;

/* Returns options with every field at its default (all zero). */
image_compare_options image_compare_options_defaults(void);

/* Returns "idiff" or "z", the words of --test. */
const char *image_compare_test_name(image_compare_test test);

/* Compares a (the new image) with b (the reference) by options->test (options may be
 * NULL). Different sizes are a failed comparison (RT_OK, result->sizes_differ), not an
 * error; the errors are those of image_diff() and image_stat_diff(). difference (may be
 * NULL) receives image_diff()'s amplified |a - b|; maps (may be NULL; z test only, else
 * left empty) image_stat_diff()'s maps. Both are allocated; free with image_free(). */
rt_status image_compare(const rt_image *a, const rt_image *b, const image_compare_options *options,
                        image_compare_result *result, rt_image *difference, rt_image *maps, rt_error *error);

/* Writes one line into text (size bytes) saying what decided the result: for a failure
 * the failing rule and its numbers, for a pass the margin (e.g. "z: 100.00% of pixel
 * channels pass (99.75% must); largest block |z| 2.1 of 3.9 (16x16)"). */
void image_compare_describe(const image_compare_result *result, const image_compare_options *options, char *text,
                            size_t size);

/* Writes the comparison's metrics into text (size bytes), one per line, each ending in
 * '\n' (what `rtspheres diff` prints before its result line). idiff: size and channels
 * compared, mean and RMS error, PSNR, the max error and where, the pixels over the
 * threshold. z: size and pixels tested, whose variance, mean, RMS and max error, the pixel
 * z-scores' mean and standard deviation, then one line per scale: its tests over the
 * threshold, the level of each, its largest z and where, pass or FAIL. Different sizes:
 * one line saying so. */
void image_compare_metrics(const image_compare_result *result, const image_compare_options *options, char *text,
                           size_t size);

/* Writes the name of a block scale into text: "pixels", "4x4 blocks", "the whole image". */
void image_compare_scale_name(int block_size, char *text, size_t size);

#ifdef __cplusplus
}
#endif

#endif
