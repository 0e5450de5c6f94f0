/* render_internal.h: what core/render.c (set-up, read-back, regions) and
 * core/render_passes.c (the pass loop) share. Not part of the library's
 * interface. */
#ifndef RT_RENDER_INTERNAL_H
#define RT_RENDER_INTERNAL_H

#include <stdint.h>

#include "gpu.h"
#include "image_io.h"
#include "render.h"
#include "status.h"

/* The adaptive pass budget (render.h, render_options.pass_work_budget): work
 * units per pixel per pass at the first pass, and the range the pass loop keeps
 * it in. */
#define INITIAL_ADAPTIVE_BUDGET 64
#define MINIMUM_ADAPTIVE_BUDGET 16
#define MAXIMUM_ADAPTIVE_BUDGET 16384

/* Reads the tracer's accumulation into a new width x height image of means (R,
 * G, B) and per-pixel finished samples, the luminance squares into
 * luminance_squares and the counters into totals when those are not NULL;
 * *samples receives their total. The caller frees image (nothing to free on
 * failure). */
rt_status render_read_image(gpu_tracer *tracer, int width, int height,
                            rt_image *image, float *luminance_squares,
                            gpu_tracer_totals *totals, uint64_t *samples,
                            rt_error *error);

/* Returns the sum of image's samples channel (the fourth of R, G, B, samples).
 */
uint64_t render_sample_total(const rt_image *image);

/* Cuts *image (of the traced region) down to region, in place; nothing when
 * they are the same. Both are x0, y0, x1, y1 of the full image, region inside
 * traced. */
rt_status render_crop_to_region(rt_image *image, const int traced[4],
                                const int region[4], rt_error *error);

/* What a render resumed from a partial file continues from (core/render.c): the sums
 * the tracer starts with (gpu.h gpu_tracer_parameters.resume, and with the adaptive state
 * layer its luminance_squares), and for adaptive sampling each pixel's sample limit and
 * finished samples (adaptive.h adaptive_resume; NULL: start the schedule afresh). All
 * traced-region-sized, rows top to bottom; freed with render_resume_free(). */
typedef struct render_resume {
    float *sums;                 /* 4 floats a pixel: sum R, G, B, samples */
    float *luminance_squares;    /* NULL: not kept (a partial without the adaptive state) */
    uint32_t *limits, *samples;  /* NULL: no adaptive state */
    uint64_t samples_total;
} render_resume;

void render_resume_free(render_resume *resume);

/* The passes of render_scene over the traced region: runs them until every
 * pixel has its samples, adaptive sampling stops every pixel, the deadline
 * comes or a stop is requested
 * (*stop says which), adapting the budget (from initial_budget) unless the
 * options fix it, reporting progress (*progress, whose samples_done starts at
 * the resumed samples) and writing checkpoints (of region); fills the result's
 * pass timings. resume (NULL: none) gives adaptive sampling the state it
 * continues from. When an adaptive render of the whole image stops before its
 * end, result->adaptive_state receives its state (render.h). start is the
 * render's start (clock_seconds). */
rt_status render_run_passes(gpu_context *context, gpu_tracer *tracer,
                            const render_options *options,
                            uint32_t samples_per_pixel, const int traced[4],
                            const int region[4], uint32_t initial_budget,
                            const render_resume *resume,
                            double start, render_progress *progress,
                            render_stop_reason *stop, render_result *result,
                            rt_error *error);

#endif
