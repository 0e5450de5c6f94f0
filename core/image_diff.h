/* image_diff.h: per-pixel comparison of two images, in the spirit of OpenImageIO's idiff,
 * through OpenImageIO's ImageBufAlgo::compare (a thin C shim over C++, like image_io.cpp).
 *
 * Compares the first min(3, channels) channels (colour; alpha and extra layers are not
 * compared). The error of a pixel is the largest absolute difference over its compared
 * channels. A pixel "fails" when its error exceeds fail_threshold (taken in single
 * precision, as compare takes it); the comparison passes when the share of failing pixels
 * is at most fail_percent and no pixel's error exceeds hard_fail (when hard_fail > 0).
 * Equal infinities do not differ; an infinity against anything else is an infinite error.
 *
 * Defaults of image_diff_options (zero means default):
 *   fail_threshold 0.016, fail_percent 1.0 (percent of pixels), hard_fail off,
 *   diff_scale 16 (amplification of the difference image)
 */
#ifndef RT_IMAGE_DIFF_H
#define RT_IMAGE_DIFF_H

#include <stdbool.h>

#include "image_io.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The defaults, for callers that show them. */
#define IMAGE_DIFF_DEFAULT_FAIL_THRESHOLD 0.016
#define IMAGE_DIFF_DEFAULT_FAIL_PERCENT 1.0
#define IMAGE_DIFF_DEFAULT_SCALE 16.0

typedef struct image_diff_options {
    double fail_threshold;
    double fail_percent;
    double hard_fail;
    double diff_scale;
} image_diff_options;

typedef struct image_diff_result {
    double mean_error;           /* mean absolute difference over compared channels */
    double rms_error;            /* root mean square difference over compared channels */
    double psnr;                 /* dB, with peak 1.0; INFINITY when identical */
    double max_error;            /* largest per-channel absolute difference */
    int max_x, max_y;            /* where max_error is */
    long failing_pixels;         /* pixels whose error exceeds fail_threshold */
    double failing_percent;      /* 100 * failing_pixels / pixel count */
    bool passed;
} image_diff_result;

/* Returns options with every field at its default (all zero). */
image_diff_options image_diff_options_defaults(void);

/* Compares a and b. Different sizes, or a NaN anywhere, are RT_ERROR_INPUT with a message.
 * options may be NULL. When difference_image is not NULL it receives (allocated; free with
 * image_free) an RGB image of |a - b| * diff_scale per compared channel. */
rt_status image_diff(const rt_image *a, const rt_image *b, const image_diff_options *options,
                     image_diff_result *result, rt_image *difference_image, rt_error *error);

#ifdef __cplusplus
}
#endif

#endif
