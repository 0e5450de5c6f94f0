/* adaptive.h: adaptive sampling's decisions (render_options.noise_threshold): which pixels
 * go on taking samples, how far, and which pixels a pass must trace. Plain C on the sums
 * the tracer accumulates; core/render_passes.c runs it between passes, the GPU never
 * sees it. docs/sampling.md ("Adaptive sampling") says the same for users.
 *
 * ## The estimator
 * A pixel's error after n samples is the relative standard error of its mean luminance
 * (Y with Rec. 709's weights, core/luminance.h, as glsl/path_state.glsl finish_sample squares it):
 *     s^2   = (sum Y^2 - n * mean^2) / (n - 1)          (the sample variance)
 *     error = sqrt(s^2 / n) / max(mean, ADAPTIVE_LUMINANCE_FLOOR)
 * so above the floor the threshold is relative (LuxCore's halt threshold is, and Cycles'
 * above an intensity of 1), below it absolute: a nearly black pixel need not reach a
 * relative error that no display shows. The Sobol samples of one pixel are stratified,
 * so s^2 / n overestimates the variance of their mean: pixels stop later than they
 * could, never earlier. A pixel with fewer than 2 samples has an infinite error.
 *
 * ## The schedule (checks happen at fixed sample counts, so the result is a pure function
 * of the samples: the pass budget and the machine's speed decide nothing)
 * Every pixel first takes min_spp samples; then checks happen when every pixel still
 * going has reached the next count, n -> n + max(min_spp, n / 4) (at most a quarter more
 * samples than the check before needed), and max_spp (--spp) is always the last.
 *
 * ## The decision (at a check, Cycles' filtered convergence mask)
 * A pixel going on is unconverged when its error is >= threshold. A pixel stops when no
 * pixel of its 3x3 neighbourhood (itself included) is both still going and unconverged:
 * a noisy neighbour keeps it going, so an edge is sampled on both sides, and a pixel that
 * has seen no light after min_spp samples (error 0 at mean 0) only stops when its
 * neighbours agree. A stopped pixel never restarts. At max_spp every pixel stops.
 * Since a pixel's decision at check k depends on its neighbours' at check k - 1, it
 * depends on the pixels within k of it: adaptive_reach() says how far, which is how far
 * core/render.c renders around a region so that tiles merge into the full render exactly.
 *
 * ## The passes
 * After a check, passes trace only the pixels still going (adaptive_going_pixels), packed
 * densely by the tracer (gpu.h gpu_tracer_set_pass_pixels, core/gpu_compact.c), so that
 * no SIMD lane idles on a pixel that has stopped, each pixel's samples up to the next
 * check split into adaptive_runs() runs traced side by side: a pass may give a slot only
 * so many samples (glsl/work.glsl), and the few pixels of the last checks would otherwise
 * take many short passes, each with its fixed cost (docs/performance.md).
 */
#ifndef RT_ADAPTIVE_H
#define RT_ADAPTIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "status.h"

#define ADAPTIVE_DEFAULT_MIN_SPP 16
#define ADAPTIVE_LUMINANCE_FLOOR 0.2f
/* adaptive_runs(): about this many samples a run (a Cornell box slot takes 10 to 20 in a
 * pass on llvmpipe), at most ADAPTIVE_MAX_RUNS runs a pixel. */
#define ADAPTIVE_RUN_SAMPLES 8
#define ADAPTIVE_MAX_RUNS 16

typedef struct adaptive_sampler adaptive_sampler;

/* Returns the error above of a pixel with n samples whose luminances sum to
 * luminance_sum and whose squares sum to luminance_squares. */
float adaptive_pixel_error(float luminance_sum, float luminance_squares, uint32_t n);

/* Returns the check after one at samples (0: before any): min_spp, then
 * samples + max(min_spp, samples / 4), never more than max_spp. */
uint32_t adaptive_next_check(uint32_t samples, uint32_t min_spp, uint32_t max_spp);

/* Returns how many checks a render from 0 to max_spp makes before its last one: the
 * distance in pixels over which a decision can reach. */
int adaptive_reach(uint32_t min_spp, uint32_t max_spp);

/* Creates the sampler of a width x height image (every pixel going, its first limit the
 * first check) into *out; free with adaptive_free(). min_spp 0 means
 * ADAPTIVE_DEFAULT_MIN_SPP; min_spp above max_spp is max_spp. RT_ERROR_RUNTIME when memory
 * runs out. */
rt_status adaptive_create(int width, int height, float threshold, uint32_t min_spp, uint32_t max_spp,
                          adaptive_sampler **out, rt_error *error);

void adaptive_free(adaptive_sampler *sampler);

/* Puts a new sampler (adaptive_create) where a stopped render's sampler was just before a
 * check, so that the render continues as if it had not stopped (core/render.c, --resume):
 * limits holds each pixel's limit at that point and samples its finished samples (width *
 * height each, rows top to bottom). The next check is the largest limit, c: the pixels whose
 * limit is c go on (samples at most c), the others stopped at an earlier check (their limit
 * is their samples, itself a check's count). Before the first check every limit is the
 * first check's count; at a check every pixel going has reached it, so every limit equals
 * the pixel's samples. RT_ERROR_INPUT naming the first pixel (x, y from the top left) that
 * breaks these rules, as limits of another --min-spp or --spp would; the sampler is
 * unchanged then. */
rt_status adaptive_resume(adaptive_sampler *sampler, const uint32_t *limits, const uint32_t *samples,
                          rt_error *error);

/* The per-pixel sample limits to give the tracer: width * height counts, rows top to
 * bottom (a stopped pixel's limit is the samples it has). */
const uint32_t *adaptive_limits(const adaptive_sampler *sampler);

/* Makes the check once every pixel going has reached its limit: rgba holds each pixel's
 * (sum R, G, B, samples) and luminance_squares its sum of squared luminance, rows top to
 * bottom. Stops the pixels the decision above stops and raises the others' limit to the
 * next check. Returns the pixels still going (0: the render is done). */
int adaptive_check(adaptive_sampler *sampler, const float *rgba, const float *luminance_squares);

/* The runs (gpu.h gpu_tracer_set_pass_pixels) a pixel going on takes from the last check
 * to the next: (next - last) / ADAPTIVE_RUN_SAMPLES, within [1, ADAPTIVE_MAX_RUNS]. A
 * function of the checks' sample counts alone, never of how many pixels go on, so that a
 * tile's pixels get the same runs, and so the same sums, as in the whole image. */
int adaptive_runs(const adaptive_sampler *sampler);

/* How noisy the image was at the last check (all zero before the first): for progress
 * reports. */
typedef struct adaptive_noise {
    int checks;                  /* checks made so far */
    int unconverged_pixels;      /* pixels still going whose error was >= the threshold */
    int going_pixels;            /* pixels going on after the check */
    float mean_error;            /* the mean error (above) of the pixels the check looked at */
} adaptive_noise;

void adaptive_get_noise(const adaptive_sampler *sampler, adaptive_noise *noise);

/* True when some pixel stopped below max_spp (the threshold, not --spp, ended it). */
bool adaptive_stopped_early(const adaptive_sampler *sampler);

/* Writes the pixels still going (indices y * width + x, rows from the top, in that
 * order) into pixels (room for width * height) and returns their count. */
int adaptive_going_pixels(const adaptive_sampler *sampler, uint32_t *pixels);

#endif
