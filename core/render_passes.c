/* render_passes.c: the pass loop of a render (render_internal.h render_run_passes): the
 * pass budget, adaptive sampling's checks (core/adaptive.h), the deadline, checkpoints and
 * previews between passes. Plain C: the GL work is the GPU module's. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "adaptive.h"
#include "clock.h"
#include "large_pages.h"
#include "render_internal.h"

/* Passes of about two seconds on a CPU rasteriser, a quarter on a GPU (under any
 * watchdog): on llvmpipe every pass costs a share of its time whatever it does, and
 * nothing kills a long draw there; 2 s rather than 1 s took 5% off the weekend at
 * 1200x675 (docs/performance.md, the log: longer passes). */
#define DEFAULT_TARGET_PASS_SECONDS 0.25
#define SOFTWARE_TARGET_PASS_SECONDS 2.0
#define CULL_MIN_PIXELS (512 * 512)
/* How far the budget may grow from one pass to the next: 4 on a GPU (a draw a watchdog
 * could kill), 16 on a CPU rasteriser, where nothing kills a draw and the loop cap bounds
 * the budget anyway (gpu.h max_pass_work_budget): from the first pass's 64 units the
 * weekend at 1200x675 reaches the cap in its third pass instead of its fourth, 0.06-0.16 s
 * sooner in all (docs/performance.md, the log). */
#define DEFAULT_MOST_BUDGET_SCALE 4.0
#define SOFTWARE_MOST_BUDGET_SCALE 16.0

/* Moves the adaptive pass budget *budget towards a pass of target_seconds after a pass of
 * pass_seconds, by at most a factor of most_scale, within [MINIMUM_ADAPTIVE_BUDGET,
 * most_budget], and gives it to the tracer. */
static void adapt_pass_budget(gpu_tracer *tracer, double pass_seconds, double target_seconds, double most_scale,
                              double most_budget, double *budget)
{
    /* Pass time grows roughly linearly with the budget; move towards the target by a
     * bounded factor per pass so one odd pass cannot swing it far. */
    double scale = pass_seconds > 0 ? target_seconds / pass_seconds : most_scale;
    scale = scale < 0.5 ? 0.5 : scale > most_scale ? most_scale : scale;
    *budget *= scale;
    *budget = *budget < MINIMUM_ADAPTIVE_BUDGET ? MINIMUM_ADAPTIVE_BUDGET : *budget > most_budget ? most_budget : *budget;
    gpu_tracer_set_pass_work_budget(tracer, (uint32_t)*budget);
}

/* Adaptive sampling in the pass loop: the sampler (NULL: none) and what its checks read. */
typedef struct adaptive_run {
    adaptive_sampler *sampler;
    float *rgba, *luminance_squares;
    uint32_t *pixels;            /* the pixels still going (adaptive_going_pixels) */
    bool checked;                /* rgba and luminance_squares hold this run's last check */
} adaptive_run;

static void end_adaptive(adaptive_run *run)
{
    adaptive_free(run->sampler);
    free(run->rgba);
    free(run->luminance_squares);
    free(run->pixels);
    memset(run, 0, sizeof *run);
}

/* Starts adaptive sampling for a width x height tracer when the options ask for it: the
 * sampler (where resume's state left it, when it has one), its buffers and the first
 * limits on the tracer. Nothing to free on failure. */
static rt_status start_adaptive(gpu_tracer *tracer, const render_options *options, uint32_t samples_per_pixel,
                                int width, int height, const render_resume *resume, adaptive_run *run,
                                rt_error *error)
{
    memset(run, 0, sizeof *run);
    if (!(options->noise_threshold > 0))
        return RT_OK;
    rt_status status = adaptive_create(width, height, options->noise_threshold, options->min_spp, samples_per_pixel,
                                       &run->sampler, error);
    if (status == RT_OK && resume != NULL && resume->limits != NULL)
        status = adaptive_resume(run->sampler, resume->limits, resume->samples, error);
    if (status != RT_OK) {
        adaptive_free(run->sampler);
        run->sampler = NULL;
        return status;
    }
    size_t pixels = (size_t)width * height;
    run->rgba = large_pages_alloc(pixels * 4 * sizeof *run->rgba);
    run->luminance_squares = large_pages_alloc(pixels * sizeof *run->luminance_squares);
    run->pixels = large_pages_alloc(pixels * sizeof *run->pixels);
    status = run->rgba && run->luminance_squares && run->pixels
                 ? gpu_tracer_set_sample_limits(tracer, adaptive_limits(run->sampler), error)
                 : rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory for adaptive sampling");
    if (status != RT_OK)
        end_adaptive(run);
    return status;
}

/* The check once every pixel going has reached its limit: new limits on the tracer, and
 * the pixels still going as the pixels its passes trace (compacted: gpu.h); the noise in
 * *progress; *done when no pixel goes on, and then *stop RENDER_STOP_NOISE when the
 * threshold stopped some pixel before the most samples. */
static rt_status check_adaptive(gpu_tracer *tracer, adaptive_run *run, render_progress *progress,
                                render_stop_reason *stop, bool *done, rt_error *error)
{
    rt_status status = gpu_tracer_read(tracer, run->rgba, run->luminance_squares, NULL, error);
    if (status != RT_OK)
        return status;
    run->checked = true;
    *done = adaptive_check(run->sampler, run->rgba, run->luminance_squares) == 0;
    adaptive_noise noise;
    adaptive_get_noise(run->sampler, &noise);
    progress->noise_checks = noise.checks;
    progress->noisy_pixels = noise.unconverged_pixels;
    progress->going_pixels = noise.going_pixels;
    progress->noise_error = noise.mean_error;
    if (*done && adaptive_stopped_early(run->sampler))
        *stop = RENDER_STOP_NOISE;
    if (*done)
        return RT_OK;
    status = gpu_tracer_set_sample_limits(tracer, adaptive_limits(run->sampler), error);
    if (status != RT_OK)
        return status;
    /* RTSPHERES_TEST_FULL_PASSES=1: every pass over the whole image, as before compacted
     * passes, so that a test can show both give the same image (tests/render/test-adaptive.sh). */
    const char *full = getenv("RTSPHERES_TEST_FULL_PASSES");
    if (full != NULL && strcmp(full, "1") == 0)
        return RT_OK;
    return gpu_tracer_set_pass_pixels(tracer, run->pixels, adaptive_going_pixels(run->sampler, run->pixels),
                                      adaptive_runs(run->sampler), error);
}

/* Before a pass: whether it may run under options->deadline, predicting its time from
 * the last pass (last_pass_seconds 0: the first pass, which always runs). With an adaptive
 * budget a pass that would end late is shortened to fit (*budget, on the tracer), if it
 * can be, within the smallest budget. */
static bool pass_fits_deadline(gpu_tracer *tracer, const render_options *options, double last_pass_seconds,
                               bool adaptive_budget, double *budget)
{
    if (options->deadline <= 0 || last_pass_seconds <= 0)
        return true;
    double remaining = options->deadline - clock_seconds();
    if (remaining >= last_pass_seconds)
        return true;
    double shortened = *budget * remaining / last_pass_seconds;
    if (!adaptive_budget || !(shortened >= MINIMUM_ADAPTIVE_BUDGET))
        return false;
    *budget = shortened;
    gpu_tracer_set_pass_work_budget(tracer, (uint32_t)shortened);
    return true;
}

/* Makes the adaptive state layer (render.h) of a width x height render stopped between
 * passes into *layer (the caller frees it): the sums of the last check this run made,
 * whose limits were the samples; before any, the sums as they stand, every pixel's
 * samples its first ones, with the sampler's limits (the first check's, or a resumed
 * state's). */
static rt_status adaptive_state_layer(gpu_tracer *tracer, adaptive_run *run, int width, int height,
                                      rt_image *layer, rt_error *error)
{
    if (!run->checked) {
        rt_status status = gpu_tracer_read(tracer, run->rgba, run->luminance_squares, NULL, error);
        if (status != RT_OK)
            return status;
    }
    rt_status status = image_create(layer, width, height, RENDER_ADAPTIVE_STATE_CHANNELS, error);
    if (status != RT_OK)
        return status;
    static const char *const names[RENDER_ADAPTIVE_STATE_CHANNELS] = RENDER_ADAPTIVE_STATE_CHANNEL_NAMES;
    for (int c = 0; c < RENDER_ADAPTIVE_STATE_CHANNELS; c++)
        snprintf(layer->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
    const uint32_t *limits = adaptive_limits(run->sampler);
    for (size_t i = 0; i < (size_t)width * height; i++) {
        float *pixel = layer->pixels + i * RENDER_ADAPTIVE_STATE_CHANNELS;
        memcpy(pixel, run->rgba + 4 * i, 4 * sizeof *pixel);
        pixel[4] = run->luminance_squares[i];
        pixel[5] = run->checked ? run->rgba[4 * i + 3] : (float)limits[i];
    }
    return RT_OK;
}

/* Reads the image so far once (cut to region) and hands it to options->checkpoint when
 * checkpoint_due, with the adaptive state layer when adaptive sampling runs over the
 * whole image, and to options->preview (--display) when preview_due. */
static rt_status write_partial(gpu_tracer *tracer, const render_options *options, adaptive_run *adaptive,
                               const int traced[4], const int region[4], uint64_t scene_hash, bool checkpoint_due,
                               bool preview_due, rt_error *error)
{
    rt_image partial;
    uint64_t partial_samples;
    rt_status status = render_read_image(tracer, traced[2] - traced[0], traced[3] - traced[1], &partial, NULL,
                                         NULL, &partial_samples, error);
    if (status != RT_OK)
        return status;
    if (memcmp(traced, region, 4 * sizeof *traced) != 0) {
        status = render_crop_to_region(&partial, traced, region, error);
        partial_samples = status == RT_OK ? render_sample_total(&partial) : 0;
    }
    rt_image state = {0};
    if (status == RT_OK && checkpoint_due && adaptive->sampler != NULL && memcmp(traced, region, 4 * sizeof *traced) == 0)
        status = adaptive_state_layer(tracer, adaptive, partial.width, partial.height, &state, error);
    if (status == RT_OK && checkpoint_due)
        status = options->checkpoint(options->checkpoint_context, &partial, &state, partial_samples, scene_hash,
                                     error);
    image_free(&state);
    if (status == RT_OK && preview_due)
        options->preview(options->preview_context, &partial);
    image_free(&partial);
    return status;
}

rt_status render_run_passes(gpu_context *context, gpu_tracer *tracer, const render_options *options,
                            uint32_t samples_per_pixel, const int traced[4], const int region[4],
                            uint32_t initial_budget, const render_resume *resume, double start,
                            render_progress *progress, render_stop_reason *stop, render_result *result,
                            rt_error *error)
{
    double last_checkpoint = clock_seconds(), last_preview = clock_seconds();
    double first_pass_end = 0, last_pass_seconds = 0;
    bool adaptive_budget = options->pass_work_budget == 0;
    gpu_info device;
    gpu_get_info(context, &device);
    double target_seconds = options->target_pass_seconds > 0 ? options->target_pass_seconds
                            : device.software                ? SOFTWARE_TARGET_PASS_SECONDS
                                                             : DEFAULT_TARGET_PASS_SECONDS;
    double budget = initial_budget;
    double most_budget = device.max_pass_work_budget < MAXIMUM_ADAPTIVE_BUDGET ? device.max_pass_work_budget
                                                                               : MAXIMUM_ADAPTIVE_BUDGET;
    adaptive_run adaptive;
    rt_status status = start_adaptive(tracer, options, samples_per_pixel, traced[2] - traced[0],
                                      traced[3] - traced[1], resume, &adaptive, error);
    /* RTSPHERES_TEST_STOP_AFTER_PASSES=N: stop after N passes as a time limit would, so
     * that a test can make partial files at chosen points (tests/render/test-adaptive.sh). */
    const char *test_stop = getenv("RTSPHERES_TEST_STOP_AFTER_PASSES");
    int stop_after_passes = test_stop != NULL ? atoi(test_stop) : 0;
    *stop = RENDER_STOP_SAMPLES;
    /* Finished pixels are marked for full passes to skip (gpu.h gpu_tracer_cull_finished)
     * once at most half the pixels go on, and again each time those fall to a quarter: at
     * the end of a render a few slow pixels (long paths through glass) take several passes
     * that would otherwise read and write the whole image's state. Adaptive renders end in
     * compacted passes instead. Only for images of CULL_MIN_PIXELS or more: the marking
     * program costs a compile (0.25 s on llvmpipe when Mesa's cache lacks it) and a pass of
     * a smaller image costs little anyway. RTSPHERES_TEST_CULL=always|never overrides that,
     * for tests. */
    uint64_t traced_pixels = (uint64_t)(traced[2] - traced[0]) * (uint64_t)(traced[3] - traced[1]);
    const char *test_cull = getenv("RTSPHERES_TEST_CULL");
    bool may_cull = adaptive.sampler == NULL
                    && (test_cull != NULL ? strcmp(test_cull, "always") == 0 : traced_pixels >= CULL_MIN_PIXELS);
    uint64_t cull_at_most = traced_pixels / 2;
    bool marked = false;
    for (bool done = false; status == RT_OK && !done;) {
        if (!pass_fits_deadline(tracer, options, last_pass_seconds, adaptive_budget, &budget)
            || (stop_after_passes > 0 && progress->passes >= stop_after_passes)) {
            *stop = RENDER_STOP_TIME;
            break;
        }
        gpu_pass_report report;
        double pass_start = clock_seconds();
        status = gpu_tracer_run_pass(tracer, &report, error);
        if (status != RT_OK)
            break;
        last_pass_seconds = clock_seconds() - pass_start;
        if (adaptive_budget)
            adapt_pass_budget(tracer, last_pass_seconds, target_seconds,
                              device.software ? SOFTWARE_MOST_BUDGET_SCALE : DEFAULT_MOST_BUDGET_SCALE, most_budget,
                              &budget);
        progress->passes++;
        progress->samples_done += report.samples_finished;
        progress->elapsed_seconds = clock_seconds() - start;
        if (progress->passes == 1) {
            result->first_pass_seconds = progress->elapsed_seconds;
            first_pass_end = clock_seconds();
        } else {
            result->steady_samples += report.samples_finished;
            result->steady_seconds = clock_seconds() - first_pass_end;
        }
        if (options->progress != NULL)
            options->progress(options->progress_context, progress);
        if (marked)
            result->culled_passes++;
        if (may_cull && report.unfinished_pixels > 0 && report.unfinished_pixels <= cull_at_most) {
            status = gpu_tracer_cull_finished(tracer, error);
            marked = true;
            cull_at_most = report.unfinished_pixels / 4;
            if (status != RT_OK)
                break;
        }
        if (status == RT_OK && report.unfinished_pixels == 0) {
            done = true;
            if (adaptive.sampler != NULL)
                status = check_adaptive(tracer, &adaptive, progress, stop, &done, error);
            continue;
        }
        if (options->stop_requested != NULL && *options->stop_requested) {
            *stop = RENDER_STOP_INTERRUPTED;
            break;
        }
        /* Checkpoints and previews (--display) share one read-back when both are due. */
        bool checkpoint_due = options->checkpoint != NULL && options->checkpoint_seconds > 0
                              && clock_seconds() - last_checkpoint >= options->checkpoint_seconds;
        bool preview_due = options->preview != NULL && options->preview_seconds > 0
                           && clock_seconds() - last_preview >= options->preview_seconds;
        if (status == RT_OK && (checkpoint_due || preview_due)) {
            status = write_partial(tracer, options, &adaptive, traced, region, result->scene_hash, checkpoint_due,
                                   preview_due, error);
            if (checkpoint_due)
                last_checkpoint = clock_seconds();
            if (preview_due)
                last_preview = clock_seconds();
        }
    }
    /* Stopped before the end: what a resume continues from. */
    if (status == RT_OK && adaptive.sampler != NULL && (*stop == RENDER_STOP_TIME || *stop == RENDER_STOP_INTERRUPTED)
        && memcmp(traced, region, 4 * sizeof *traced) == 0)
        status = adaptive_state_layer(tracer, &adaptive, traced[2] - traced[0], traced[3] - traced[1],
                                      &result->adaptive_state, error);
    end_adaptive(&adaptive);
    return status;
}
