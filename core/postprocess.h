/* postprocess.h: image operations after the render: Gaussian blur, an edge-aware
 * denoiser, tone mapping for 8-bit outputs and a contact sheet (montage). Plain C on
 * rt_image (float pixels, channels interleaved, rows top to bottom, see image_io.h); no
 * GPU, never prints, never exits. Every function reports through rt_status/rt_error
 * with messages prefixed "POSTPROCESS: "; bad arguments and mismatched images are
 * RT_ERROR_INPUT, running out of memory is RT_ERROR_RUNTIME. Functions that work in place
 * leave the image unchanged when they fail.
 *
 * "Colour channels" are the first three channels; an image with one or two channels is
 * grey (plus alpha) and its first channel is the colour. Other channels (alpha, the
 * render's `samples`) are never changed.
 *
 * ## Gaussian blur
 * postprocess_gaussian_blur(): separable, kernel radius ceil(3 sigma), weights normalised
 * to sum 1, applied `passes` times (n passes of sigma equal one pass of sigma*sqrt(n)).
 * Borders are mirrored (pixel -1 reads pixel 0, -2 reads 1, ...): like clamp-to-edge the
 * first pixel outside is the edge pixel, so borders neither darken nor brighten, and
 * unlike clamp-to-edge every pixel keeps a total weight of exactly 1, so the image mean is
 * preserved (clamp-to-edge over-weights the edge pixels).
 *
 * ## Denoiser
 * postprocess_denoise() is an edge-avoiding à-trous wavelet filter (Dammertz, Sewtz,
 * Hanika, Lensch, "Edge-Avoiding À-Trous Wavelet Transform for fast Global Illumination
 * Filtering", HPG 2010), with the colour weight and variance tracking of SVGF (Schied et
 * al., HPG 2017):
 *   1. Demodulation: with an albedo image, colour / max(albedo, albedo_epsilon) per
 *      channel is filtered (the lighting, smooth across texture edges) and multiplied
 *      back afterwards, so textures stay as sharp as the albedo image. With an emission
 *      image, that part of the colour (what camera rays saw of emitters and the sky at
 *      once: no noise but the pixel's coverage) is taken out first and added back
 *      unfiltered, so a pixel that a light covers in part keeps its share of the light.
 *   2. Each iteration i = 0 .. iterations-1 convolves with the 5x5 B3-spline kernel
 *      (1/16, 1/4, 3/8, 1/4, 1/16 in each direction) whose taps are 2^i pixels apart
 *      (steps 1, 2, 4, 8, 16: a 125-pixel footprint after 5 iterations for 25 taps a
 *      pixel each), every tap q of pixel p multiplied by
 *        colour  exp(-rms(c_q - c_p) / (s_i * sd_p))
 *                rms over the three channels; sd_p the estimated noise standard
 *                deviation of p (below), so the weight measures a difference in units
 *                of the noise, and one default works at any brightness and sample
 *                count. Where the variance guide gives p's noise, s_i is sigma_colour
 *                in the first two iterations and halved in each later one (4, 4, 2, 1,
 *                0.5), as Dammertz et al. halve their fixed sigma; where the noise was
 *                measured around p (no variance guide there, or under 4 samples in a
 *                render), sigma_colour in every iteration. Chosen by the RMSE of
 *                renders against references (docs/sampling.md, "Denoising": 5 to 20%
 *                lower on four scenes at 4 to 64 spp, with no more visible grain; a
 *                schedule halved from the first iteration on was better still by
 *                RMSE but left speckles).
 *        normal  exp(-|n_q - n_p|^2 / sigma_normal^2)
 *        depth   exp(-|z_q - (z_p + grad z_p . (q - p))| / (sigma_depth * z_p))
 *                the distance from the plane through p (grad z from the one-sided
 *                difference of smaller size in x and y), relative to p's depth: planes
 *                seen at an angle pass, steps in depth do not.
 *        albedo  exp(-|a_q - a_p|^2 / sigma_albedo^2)
 *      and the weighted sum is divided by the sum of the weights. Taps outside the image
 *      are left out.
 *   3. Noise estimate: before the first iteration, from the variance guide where it has a
 *      value (>= 0: the variance of the pixel's mean luminance, divided by the squared
 *      demodulation divisor and averaged over the channels), else the variance of the
 *      pixel's colour over its 7x7 neighbourhood (weighted by the normal, depth and
 *      albedo weights, so edges do not count as noise; but a highlight only the colour
 *      shows counts as noise there, and is spread out); each iteration carries it along
 *      as the variance of the weighted mean (sum (h w)^2 var_q / (sum h w)^2), and the
 *      colour weight reads it blurred over 3x3.
 *   4. Bias check, where the variance guide covers a pixel's 3x3 neighbourhood: the mean
 *      over it of the residual (input colour less denoised) against that mean's standard
 *      error (the root of the summed variances over 9, the sum taken no lower than 9 x
 *      the mean variance over the 5x5 neighbourhood): at a z-score of its luminance
 *      under 1 nothing, over 3 all of the mean residual is added back, in between a
 *      linear share (never below 0: no render's colour is; nor below what the filter left
 *      where that already was). Noise leaves residuals that average out; a feature the
 *      guides do not show (a strip lit from close by, a reflection) leaves the same
 *      residual on every side and gets back what the filter took, where its samples say
 *      so. The 5x5 floor is for few samples, whose variance is heavy-tailed: pixels that
 *      all missed a rare bright path have a variance near 0, and without it they got
 *      their dark specks back (and their neighbours' bright ones). docs/sampling.md,
 *      "Denoising", has what it gives.
 *   5. Choice among the iterations' images, where the variance guide has values (it runs
 *      before step 4, whose input is its output): for the image after each iteration k
 *      (1 .. iterations) Stein's unbiased risk estimate of each pixel's squared error in
 *      luminance, (L(F_k) - L(y))^2 - var + 2 var dF_k/dy (y the input, var the variance
 *      guide, dF_k/dy the product of the iterations' centre weight shares: exact for the
 *      first iteration, a little low after), averaged over the pixel's neighbours out to
 *      9 pixels with a Gaussian of 4.5 pixels and the normal, depth and albedo weights
 *      (along x, then along y); each pixel takes the image of lowest averaged risk (a
 *      neighbourhood with an unknown variance takes the last). Where the guides do not show
 *      what the filter blurs (reflections, refractions, the horizon in a mirror, lighting
 *      that changes within a surface) fewer iterations win; elsewhere all of them.
 *      (Rousselle, Knaus, Zwicker, "Adaptive rendering with non-local means filtering",
 *      SIGGRAPH Asia 2012, choose among filters by SURE this way.) The input itself is not
 *      offered: on four scenes' renders it was never chosen.
 * Each stage (the noise estimate, each iteration's variance blur and filter, the choice's
 * risks and averages, the bias check) runs in bands of rows on as many threads as the
 * machine has cores (pthreads; at most 64, each with at least 16 rows), the noise
 * estimate's, the filter's and the choice's taps in vector loops over runs of 256 pixels
 * (AVX-512, AVX2 or SSE2, picked for the CPU when the program starts; core/postprocess_denoise.c);
 * every pixel is computed alone and alike in every lane and every clone, so the image
 * depends on none of this. Sums are in float and the weights' exponential is the filter's
 * own (a few ulps from libm's): the image is tests/unit/test_postprocess.c's plain double
 * reference to within 2e-5.
 * Depth is a distance; a pixel whose depth is 0, negative, infinite or NaN hit nothing
 * (sky): such pixels form their own class and never mix with pixels that hit something.
 * Between two sky pixels only the colour weight counts.
 *
 * Defaults of postprocess_denoise_options (zero means default):
 *   iterations 5           steps 1, 2, 4, 8, 16 (at most 12)
 *   sigma_colour 4         noise standard deviations (SVGF's sigma_l) of the first two
 *                          iterations: noise of 1 sd keeps weight 0.78, a 4 sd step
 *                          0.37, a 12 sd step 0.05; half that in the third, and so on
 *   sigma_normal 0.3       a 10 degree crease keeps 0.71, 30 degrees 0.05, 90 degrees 2e-10
 *   sigma_depth 0.02       2% of the distance off the plane through p keeps 0.37; a step
 *                          from depth 2 to 3 keeps 1e-11
 *   sigma_albedo 0.1       albedo (0.5,0.5,0.5) against (0.6,0.6,0.6) keeps 0.05
 *   albedo_epsilon 0.01    floor of the albedo divided by in the demodulation
 * What they give (tests/unit/test_postprocess.c, 64x64 images): noise of sd 0.1 on a flat
 * 0.5 region loses 800x its variance (a tilted plane 1000x); a step from 0.2 to 0.8 with
 * 20% noise, where the normal or the depth changes, keeps both sides' means and the
 * columns next to it within 1% (variance 1300x to 2700x lower); a 0.2/0.8 albedo checker
 * of 4x4 cells under 10% noise keeps its contrast within 0.5% and every pixel within 2.3%;
 * a noise-free 2x2 highlight of 5 on that region keeps 5.000 with the variance guide (0.80
 * without); a column that a light of 10 covers at 30% keeps its value within 1% with the
 * emission guide (20% off without). On renders: docs/sampling.md, "Denoising".
 *
 * ## Tone mapping
 * postprocess_tonemap() multiplies the colour channels by 2^exposure_stops, then:
 *   TONEMAP_CLAMP     nothing more (the 8-bit writer clamps to [0,1])
 *   TONEMAP_REINHARD  L' = L / (1 + L) on the Rec.709 luminance L, the colour scaled by
 *                     L'/L (its ratios kept); a saturated colour whose largest channel
 *                     would pass 1 is scaled down to 1, keeping the ratios
 *   TONEMAP_ACES      Narkowicz's fit of the ACES filmic curve per channel,
 *                     x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), clamped to [0,1]; his fit
 *                     is pre-exposed, so 1 maps to about 0.8
 * Both curves leave every colour value in [0,1]: negative values and NaN become 0, +inf 1.
 *
 * ## Montage
 * postprocess_montage() lays count equal-size images out in a grid, row by row, left to
 * right: image i at column i % columns, row i / columns, its top-left corner at
 * (column * (width + gap), row * (height + gap)). The sheet is
 * columns * width + (columns - 1) * gap wide and rows * height + (rows - 1) * gap high,
 * rows = ceil(count / columns); no border around the outside. columns 0 means
 * ceil(sqrt(count)); more columns than images are cut to count. The sheet has three
 * channels (R, G, B) on black: the first three of each image; a one- or two-channel image
 * (grey, grey + alpha) has its first channel copied to all three.
 */
#ifndef RT_POSTPROCESS_H
#define RT_POSTPROCESS_H

#include "image_io.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest accepted blur sigma, in pixels: beyond it the kernel costs more than it can
 * change on any image this program writes (16384 pixels a side). */
#define POSTPROCESS_MAX_BLUR_SIGMA 4096.0f
#define POSTPROCESS_MAX_DENOISE_ITERATIONS 12
/* Largest montage sheet side, in pixels. */
#define POSTPROCESS_MAX_MONTAGE_SIDE 65536

typedef struct postprocess_denoise_options {
    int iterations;              /* à-trous iterations, step 2^i; default 5 */
    float sigma_colour;          /* in noise standard deviations, first two iterations; default 4 */
    float sigma_normal;          /* on |n_q - n_p|; default 0.3 */
    float sigma_depth;           /* relative distance off p's plane; default 0.02 */
    float sigma_albedo;          /* on |a_q - a_p|; default 0.1 */
    float albedo_epsilon;        /* demodulation floor; default 0.01 */
} postprocess_denoise_options;

typedef enum postprocess_tonemap_operator {
    TONEMAP_CLAMP = 0,
    TONEMAP_REINHARD,
    TONEMAP_ACES,
} postprocess_tonemap_operator;

/* The images that guide postprocess_denoise(), each of the colour image's size and each
 * NULL to go without it. */
typedef struct postprocess_denoise_guides {
    const rt_image *albedo;      /* three channels or more; the demodulation's divisor */
    const rt_image *normal;      /* three channels or more, unit length */
    const rt_image *depth;       /* the first channel: distance to the first hit */
    const rt_image *emission;    /* three channels or more: the part of colour with no noise to
                                  * remove (emitters and sky seen at once); not filtered */
    const rt_image *variance;    /* the first channel: the variance of each pixel's mean
                                  * luminance (its samples' variance over their count) */
} postprocess_denoise_guides;

/* Returns options with every field at its default (all zero). */
postprocess_denoise_options postprocess_denoise_options_defaults(void);

/* Blurs the colour channels of image in place with a Gaussian of sigma_pixels, passes
 * times (see above). sigma 0 or passes 0 changes nothing. A negative, NaN or too large
 * (> POSTPROCESS_MAX_BLUR_SIGMA) sigma, negative passes or an empty image are
 * RT_ERROR_INPUT; out of memory RT_ERROR_RUNTIME. */
rt_status postprocess_gaussian_blur(rt_image *image, float sigma_pixels, int passes, rt_error *error);

/* Denoises the colour channels of colour in place (see above), guided by the images of
 * guides (NULL: none; without albedo there is no demodulation, without variance the noise
 * is measured around each pixel). options may be NULL for the defaults. Guides of another
 * size, too few channels, a non-finite colour or emission value, a negative or NaN option
 * or more than POSTPROCESS_MAX_DENOISE_ITERATIONS iterations are RT_ERROR_INPUT; out of
 * memory RT_ERROR_RUNTIME. Nothing is allocated for the caller. */
rt_status postprocess_denoise(rt_image *colour, const postprocess_denoise_guides *guides,
                              const postprocess_denoise_options *options, rt_error *error);

/* The reach of the blur and the denoiser: how many pixels away from a pixel they read to
 * compute it (rows or columns). A band of rows taken with this many more rows on each side
 * (or up to the image's edge) and filtered alone gives its own rows exactly, bit for bit,
 * as the whole image does (and so does a block of columns and rows taken with it on every
 * side): how a render in tiles is post-processed block by block
 * (core/render_job_tiles.c; tests/unit/test_postprocess.c checks bands and blocks,
 * tests/render/test-postprocess.sh blocks of a render). Chained filters add
 * their reaches. The blur's: passes x ceil(3 sigma) (0 when it changes nothing); the
 * denoiser's, with options (NULL: defaults): 2 (2^iterations - 1) for the iterations'
 * taps (the 3x3 variance blur stays within them), + 3 for the 7x7 noise estimate, + 1
 * for the depth gradient, + 9 for the choice's average, + 1 for the bias check's 3x3
 * (its 5x5 pool reads only the variance guide, well within): 76 with the defaults. */
int postprocess_blur_reach(float sigma_pixels, int passes);
int postprocess_denoise_reach(const postprocess_denoise_options *options);

/* Exposes and tone-maps the colour channels of image in place for an 8-bit output (see
 * above). An unknown operator, a non-finite exposure or an empty image are
 * RT_ERROR_INPUT. */
rt_status postprocess_tonemap(rt_image *image, postprocess_tonemap_operator op, float exposure_stops,
                              rt_error *error);

/* Makes a contact sheet of images[0 .. count-1] into *out (allocated; the caller frees it
 * with image_free()), laid out as above. count < 1, columns < 0, gap_pixels < 0, an empty
 * image, images of different sizes (the message names the first that differs and both
 * sizes) or a sheet side over POSTPROCESS_MAX_MONTAGE_SIDE are RT_ERROR_INPUT; out of
 * memory RT_ERROR_RUNTIME. *out is zeroed on failure. */
rt_status postprocess_montage(const rt_image *images, int count, int columns, int gap_pixels, rt_image *out,
                              rt_error *error);

#ifdef __cplusplus
}
#endif

#endif
