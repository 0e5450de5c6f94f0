/* render_denoise.h: denoising a render from the layers it wrote (render --denoise, and
 * `rtspheres denoise` on an EXR rendered with --aovs): finds the denoiser's guides among
 * the channels by name and runs postprocess_denoise() (postprocess.h) with them.
 *
 * The layers (render.h render_result.aovs):
 *   albedo.R/G/B, normal.X/Y/Z, depth.Z   required: the first-hit guides
 *   variance.Y and samples                optional: each pixel's sample variance of
 *                                         luminance and sample count; from
 *                                         RENDER_DENOISE_VARIANCE_MIN_SAMPLES samples a
 *                                         pixel, the variance of its mean (variance.Y /
 *                                         (samples - 1)) is the noise the colour weight
 *                                         measures differences by; below, the denoiser
 *                                         measures it around the pixel
 *   emission.R/G/B                        optional: what camera rays saw of emitters and
 *                                         the sky at once; from
 *                                         RENDER_DENOISE_EMISSION_MIN_SAMPLES samples a
 *                                         pixel it is left out of the filtering and added
 *                                         back (below, the light's coverage is too noisy
 *                                         for that to pay: docs/sampling.md, "Denoising")
 * Without a samples channel the emission is used at every pixel and the variance at none.
 */
#ifndef RT_RENDER_DENOISE_H
#define RT_RENDER_DENOISE_H

#include "image_io.h"
#include "status.h"

#define RENDER_DENOISE_VARIANCE_MIN_SAMPLES 4
#define RENDER_DENOISE_EMISSION_MIN_SAMPLES 8

/* Denoises colour (three channels, the beauty's R, G, B; of the layers' size) in place,
 * guided by the channels named above, looked up in beauty (where "samples" is; it may be
 * NULL) and then in layers. A missing guide is RT_ERROR_INPUT naming it and what renders
 * it (--aovs); other errors as postprocess_denoise()'s. Nothing is allocated for the
 * caller. */
rt_status render_denoise(rt_image *colour, const rt_image *beauty, const rt_image *layers, rt_error *error);

/* Checks that image, read from path, is a render's raw colour to denoise: not
 * post-processed (no rtspheres:postprocess key, metadata_keys.h; nor the noisy.R layer
 * of a --denoise render written before that key). RT_ERROR_INPUT naming path and what
 * was done to it otherwise. */
rt_status render_denoise_check_raw(const char *path, const rt_image *image, rt_error *error);

/* How many rows away render_denoise() reads (postprocess.h postprocess_denoise_reach()). */
int render_denoise_reach(void);

#endif
