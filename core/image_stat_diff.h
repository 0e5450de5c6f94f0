/* image_stat_diff.h: the statistical comparison of two Monte Carlo renders (`rtspheres diff
 * --test z`, `rtspheres check`): is the difference between A and B more than the noise of
 * their samples explains? Plain C, no GPU; docs/regression.md says when to use it and when
 * the idiff-style comparison of image_diff.h.
 *
 * ## What each image must hold (found by channel name)
 * R, G, B: each pixel's mean of its samples; "samples": how many (n); variance.R/G/B: the
 * per-sample variance s^2 of each channel, E[c^2] - E[c]^2 (what `render --variance`
 * writes, render.h). The variance of a pixel's mean is then s^2 / (n - 1) (the unbiased
 * sample variance s^2 n / (n - 1), over n). Pixels with fewer than 2 samples in either
 * image are left out of every test (skipped_pixels). Both images need the variance layers:
 * a pixel's own variance is what keeps a rare bright sample (a path that found a small
 * light) from failing it, since that sample raises its variance as much as its mean;
 * borrowing the other image's variance loses that (measured: a render without variance
 * failed 1.2% of pixel channels against its own scene). A missing one is RT_ERROR_INPUT.
 *
 * Two facts about rtspheres' samples the test relies on: pixels are independent of each
 * other (each has its own random numbers), and a pixel's samples are independent or, with
 * a stratified sampler, stratified; then s^2 / (n - 1) overestimates the variance of the
 * mean: z-scores come out smaller than N(0, 1) (fewer false failures, less power), which
 * result.z_sd shows.
 *
 * ## The tests
 * Per pixel and channel, d = mean_A - mean_B and its variance v = v_A + v_B + floor^2, where
 * floor = relative_floor * (|mean_A| + |mean_B|) / 2 + absolute_floor: a difference that
 * small counts as one standard deviation, so that pixels without noise (the sky, Whitted
 * renders) do not fail on float rounding. z = d / sqrt(v).
 *   Pixel scale (Mitsuba 3's render tests' rule): a pixel channel fails when its two-sided
 *     p-value is below alpha after Šidák's correction over the 3 * pixels channels,
 *     1 - (1 - alpha)^(1 / (3 * pixels)); the scale fails when fewer than pass_share of
 *     the pixel channels pass.
 *   Block scales: a change too small for any one pixel's noise (a material's albedo by 2%)
 *     still moves the mean of many pixels. For each block size B the image is cut into
 *     B x B blocks (the last row and column of blocks smaller), and per block and channel
 *     z = (mean of d) / sqrt(sum of v_pixel / k^2 + floor(block)^2) over its k pixels;
 *     IMAGE_STAT_WHOLE_IMAGE is one block of every pixel. block_alpha is shared by the
 *     scales by Šidák, 1 - (1 - block_alpha)^(1 / scales), and within a scale by Šidák
 *     over its blocks x 3 channels; a scale fails when any of its tests fails. The block
 *     z-scores of two renders of one scene are nearly jointly normal (sums of independent
 *     pixels), and by Šidák's inequality (any correlation between the tests) the chance
 *     that any block test fails is then at most block_alpha.
 * The images match when no scale fails: the family-wise chance that two renders of the same
 * scene fail is at most block_alpha plus the pixel scale's (which is far smaller than
 * alpha: it takes pass_share's 0.25% of channels failing at level 2e-7, not one).
 *
 * Defaults of image_stat_options (zero means default):
 *   alpha 0.01, pass_share 0.9975 (Mitsuba 3's), block_alpha 0.01,
 *   block sizes 4, 8, 16, 32, 64 and the whole image (block_count 0; pixels_only: none),
 *   relative_floor 1e-3, absolute_floor 1e-5.
 */
#ifndef RT_IMAGE_STAT_DIFF_H
#define RT_IMAGE_STAT_DIFF_H

#include <stdbool.h>

#include "image_io.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IMAGE_STAT_MAX_BLOCK_SCALES 12
#define IMAGE_STAT_WHOLE_IMAGE (-1)  /* a block size: the whole image as one block */

typedef struct image_stat_options {
    double alpha;                /* pixel scale significance (before Šidák) */
    double pass_share;           /* pixel scale: share of pixel channels that must pass */
    double block_alpha;          /* all block scales together */
    int block_sizes[IMAGE_STAT_MAX_BLOCK_SCALES];   /* sides in pixels (>= 2) or
                                                     * IMAGE_STAT_WHOLE_IMAGE */
    int block_count;             /* 0: the default sizes */
    bool pixels_only;            /* no block scales (Mitsuba 3's test alone) */
    double relative_floor;
    double absolute_floor;
} image_stat_options;

/* One scale's verdict. */
typedef struct image_stat_scale {
    int block_size;              /* 1: the pixel scale; IMAGE_STAT_WHOLE_IMAGE; else B */
    long tests;                  /* blocks x channels tested */
    double test_alpha;           /* each test's level after Šidák */
    double z_threshold;          /* a test fails when |z| is above it */
    long failing;                /* tests with |z| above the threshold */
    double max_z;                /* the z of largest magnitude (signed) */
    int max_x, max_y, max_channel;  /* its block's top-left pixel and its channel (0 R, 1 G, 2 B) */
    bool passed;
} image_stat_scale;

typedef struct image_stat_result {
    image_stat_scale scales[1 + IMAGE_STAT_MAX_BLOCK_SCALES];  /* [0] pixels, then blocks */
    int scale_count;
    double passing_share;        /* pixel scale: share of tested pixel channels that pass */
    double required_share;       /* the pass_share in force */
    double z_mean, z_sd;         /* of the pixel z-scores: near 0 and at most about 1 for
                                  * two renders of one scene */
    long tested_pixels, skipped_pixels;
    int map_scale;               /* the scale the maps' significance shows: the first that
                                  * fails, or 0 (the pixels) when none does */
    bool passed;
} image_stat_result;

/* Returns options with every field at its default (all zero). */
image_stat_options image_stat_options_defaults(void);

/* Compares a and b (see above). Different sizes, a missing R, G, B or samples channel, no
 * variance layers in either, a NaN, or bad options are RT_ERROR_INPUT. options may be
 * NULL. When maps is not NULL it receives (allocated; free with image_free) a 4-channel
 * image: z.R, z.G, z.B (the pixel z-scores, 0 where skipped) and "significance": at the
 * scale result->map_scale, the z of the test covering the pixel (its block's, or its own
 * at the pixel scale; of the channel of largest |z|) over that scale's threshold, signed
 * (positive: a brighter than b); |significance| above 1 is a failing test. For
 * image_stat_heat_map(). */
rt_status image_stat_diff(const rt_image *a, const rt_image *b, const image_stat_options *options,
                          image_stat_result *result, rt_image *maps, rt_error *error);

/* Makes *heat (allocated; free with image_free) an RGB picture of maps' significance
 * channel for people: black at 0; where a is brighter, dark red at 0.5, red at 1 (a
 * failing test), yellow at 1.5; where it is darker, dark blue, blue, cyan; white from 2
 * on. Linear values, meant to be written as PNG. */
rt_status image_stat_heat_map(const rt_image *maps, rt_image *heat, rt_error *error);

/* Returns the |z| above which a two-sided test of level test_alpha (0 < test_alpha < 1)
 * fails: the inverse of p = erfc(|z| / sqrt 2). */
double image_stat_z_threshold(double test_alpha);

#ifdef __cplusplus
}
#endif

#endif
