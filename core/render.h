/* render.h: renders a scene: camera frame, packing, GPU tracer passes, result image.
 *
 * A render is a sequence of bounded passes (see gpu.h and glsl/work.glsl for why:
 * llvmpipe's 65,535-iteration loop cap and GPU watchdogs). Passes repeat until every
 * pixel has run all its samples, or (with a noise threshold) every pixel has stopped as
 * core/adaptive.h decides, or the next pass would end past the deadline, or until
 * *stop_requested becomes non-zero (checked between passes), in which case the samples
 * finished so far are returned with their per-pixel counts and the status is
 * RT_ERROR_INTERRUPTED. render_result.stop_reason says which ended it.
 *
 * The result image has 4 channels: R, G, B (the mean radiance of the finished samples,
 * linear) and "samples" (how many samples each pixel finished), rows top to bottom.
 *
 * Defaults of render_options (zero means default):
 *   pass_work_budget: adaptive: starts at 64 work units per pixel per pass (a unit is
 *     one loop iteration of the tracer, a path segment counts 64: glsl/work.glsl) and is
 *     scaled after each pass (by at most 4x on a GPU, 16x on a CPU rasteriser) so that
 *     a pass takes about target_pass_seconds, between 16
 *     and 16384 units and at most the device's gpu_info.max_pass_work_budget (on
 *     llvmpipe half its work cap, which keeps a SIMD vector under the 65,535-iteration
 *     loop cap: 3,128 units at 8 lanes; core/gpu.c set_work_limits). A non-zero value is
 *     used for every pass. The image does not depend on it, only the time per pass.
 *   target_pass_seconds 0.25 on a GPU (short passes keep progress, Ctrl-C and watchdogs
 *     happy), 2 on a CPU rasteriser (where each pass costs a share of its time),
 *   light sampling on (next-event estimation with MIS; the image's expectation is the
 *     same without it, only the noise differs),
 *   russian_roulette_depth 4 (paths may end at random from the 5th segment on),
 *   full_tracer false: the tracer is compiled without the features the scene cannot
 *     reach (gpu.h, GPU_OMIT_*),
 *   sample_start 0, the whole image, no progress callback, no stop flag,
 *   noise_threshold 0: no adaptive sampling (every pixel takes samples_per_pixel),
 *   min_spp ADAPTIVE_DEFAULT_MIN_SPP (16, core/adaptive.h) with a threshold,
 *   deadline 0: none, no BVH cache.
 *
 * Adaptive sampling (noise_threshold > 0): pixels stop as core/adaptive.h says, after
 * each check the passes trace only the pixels still going (compacted: gpu.h
 * gpu_tracer_set_pass_pixels), and the samples channel holds each pixel's count. With a region, the tracer renders the pixels within adaptive_reach() of
 * it too (and drops them), so a region's decisions, and so its pixels, are exactly the
 * full render's. A stopped render of the whole image leaves its adaptive state
 * (render_result.adaptive_state), from which resume continues it to the bit; resume of a
 * region is refused (its margin's state is not kept).
 *
 * The deadline (a clock_seconds() time, core/clock.h): before each pass after the first
 * the render predicts its end from the last pass; a pass that would end past the deadline
 * is shortened (an adaptive budget) or not run, so the render ends within about one pass
 * of the deadline with RT_OK and stop_reason RENDER_STOP_TIME. The first pass always runs.
 *
 * With a region, result->image covers only the region (its pixels are exactly those of
 * the full render: camera and random numbers use full-image pixel coordinates).
 */
#ifndef RT_RENDER_H
#define RT_RENDER_H

#include <signal.h>
#include <stdint.h>

#include "gpu.h"
#include "image_io.h"
#include "pack.h"
#include "scene.h"
#include "status.h"

/* How the tracer picks the light it samples at a point (docs/sampling.md, "Light
 * sampling"), for a packed scene and the render's options. */
typedef enum render_light_choice {
    RENDER_LIGHTS_NONE,       /* no light, or --light-sampling off (path tracing): none sampled */
    RENDER_LIGHTS_ONE,        /* one light: nothing to choose */
    RENDER_LIGHTS_ALL,        /* Whitted, up to LIGHT_WHITTED_ALL_MAX lights: each at every point */
    RENDER_LIGHTS_BY_POINT,   /* 2 to LIGHT_LOCAL_CHOICE_MAX: by each one's estimate at the point */
    RENDER_LIGHTS_BY_TREE,    /* more: by walking the light tree */
    RENDER_LIGHTS_BY_POWER,   /* more, with --light-tree off: by power alone */
} render_light_choice;

/* Returns "none", "one", "all", "point", "tree" or "power": the words of --stats-json's
 * scene.light_choice (docs/stats-json.md). */
const char *render_light_choice_name(render_light_choice choice);

/* The integrator: INTEGRATOR_PATH (0, the default) or INTEGRATOR_WHITTED, the ids of
 * core/tracer_interface.h. */
typedef int render_integrator;

typedef struct render_progress {
    uint64_t samples_done;
    uint64_t samples_total;
    double elapsed_seconds;
    int passes;
    /* With a noise threshold, after the first check (noise_checks > 0; core/adaptive.h):
     * of the pixel_count pixels traced, those whose error was still at or above
     * noise_threshold, those still taking samples, and the mean error of those checked. */
    int noise_checks;
    int pixel_count;
    int noisy_pixels, going_pixels;
    float noise_error, noise_threshold;
} render_progress;

/* Why the passes ended. */
typedef enum render_stop_reason {
    RENDER_STOP_SAMPLES = 0,     /* every pixel ran samples_per_pixel ("spp") */
    RENDER_STOP_NOISE,           /* adaptive sampling stopped some pixels earlier ("noise") */
    RENDER_STOP_TIME,            /* the deadline ("time") */
    RENDER_STOP_INTERRUPTED,     /* *stop_requested ("interrupted") */
} render_stop_reason;

/* Returns "spp", "noise", "time" or "interrupted": the words of rtspheres:stop_reason. */
const char *render_stop_reason_name(render_stop_reason reason);

typedef struct render_options {
    uint32_t pass_work_budget;
    double target_pass_seconds;
    bool no_light_sampling;      /* true: BSDF sampling only (to compare the estimators) */
    bool no_light_tree;          /* true: scenes of more than LIGHT_LOCAL_CHOICE_MAX lights
                                  * choose one by power, not by walking the light tree */
    bool full_tracer;            /* true: compile every feature into the tracer, even those
                                  * the scene cannot reach (gpu.h GPU_OMIT_*); for checking
                                  * that leaving them out changes no image */
    render_integrator integrator;
    int sampler;                 /* SAMPLER_* of tracer_interface.h: 0, the default, is
                                  * SAMPLER_SOBOL; SAMPLER_INDEPENDENT for comparisons */
    bool aovs;                   /* also render the AOV image (see render_result.aovs) */
    bool light_groups;           /* also collect each light group's image (see
                                  * render_result.light_groups); not with resume */
    bool variance;               /* also make the variance layers (see render_result.aovs) */
    bool direct_emission;        /* also sum what camera rays see of emitters and the sky at
                                  * once, for the denoiser (see render_result.aovs); not with
                                  * resume */
    uint32_t russian_roulette_depth;
    uint32_t sample_start;       /* first sample index: parts 0:N and N:M merge into 0:N+M */
    int region[4];               /* x0, y0, x1, y1 (row 0 at the top, x1/y1 exclusive) of the
                                  * full image to render; all zero: the whole image */
    void (*progress)(void *progress_context, const render_progress *progress);
    void *progress_context;
    const volatile sig_atomic_t *stop_requested;
    float noise_threshold;       /* > 0: adaptive sampling to this error (core/adaptive.h) */
    uint32_t min_spp;            /* samples every pixel takes before a check (0: 16) */
    double deadline;             /* clock_seconds() time to end by (0: none) */
    /* Continue a partial render: an image of the region with R, G, B means and a
     * "samples" channel (as render_scene returns and an EXR keeps). A pixel with n
     * samples goes on from sample index sample_start + n, so the result equals an
     * uninterrupted render up to float rounding of mean * n. NULL: start afresh. When it
     * also has the adaptive state layer (render_result.adaptive_state) the render goes on
     * from that state instead: an adaptive render (noise_threshold, of the whole image:
     * region all zero) then equals the uninterrupted one to the bit (without
     * direct_emission, which a resume cannot continue: the program without it rounds
     * some sums differently), and a fixed one to float rounding; an adaptive render
     * needs that layer. */
    const rt_image *resume;
    uint64_t resume_scene_hash;  /* with resume: must equal this render's scene_hash (0: unchecked) */
    /* Every checkpoint_seconds (0: never), checkpoint() receives the image so far (the
     * same layout as the result), the adaptive state layer (render_result.adaptive_state;
     * an image without pixels when there is none), the samples the image holds and the
     * render's scene_hash; a non-OK status stops the render with that status. */
    double checkpoint_seconds;
    rt_status (*checkpoint)(void *checkpoint_context, const rt_image *partial, const rt_image *adaptive_state,
                            uint64_t samples, uint64_t scene_hash, rt_error *error);
    void *checkpoint_context;
    /* Every preview_seconds (0: never), between passes, preview() receives the image so far
     * (the same layout as the result: means and samples); for a live view (--display). */
    double preview_seconds;
    void (*preview)(void *preview_context, const rt_image *partial);
    void *preview_context;
    /* NULL: every BVH is built; else the packer's BVH cache (pack.h), which the caller
     * keeps between renders (a job's frames and sweep rows): trees over the same boxes as
     * the last render's are taken from it, not built again. The image is the same. */
    pack_bvh_cache *bvh_cache;
} render_options;

typedef struct render_result {
    rt_image image;              /* R, G, B, samples; free with image_free() */
    int region[4];               /* the region image covers (x0, y0, x1, y1) */
    rt_image aovs;               /* extra layers: with options.aovs albedo.R/G/B, normal.X/Y/Z
                                  * (world, first hit), depth.Z (0: no hit), variance.Y
                                  * (per-pixel sample variance of luminance); then, with
                                  * options.variance, variance.R/G/B (per-pixel sample
                                  * variance of each colour channel, E[c^2] - E[c]^2 over the
                                  * pixel's finished samples: the variance of the pixel's
                                  * mean is it / (samples - 1)); then, with
                                  * options.direct_emission, emission.R/G/B (the mean over
                                  * the pixel's samples of the radiance their first segment
                                  * brought from an emitter or the sky: the part of the
                                  * pixel that is no scattered light); empty when none is
                                  * asked; free with image_free() */
    rt_image light_groups;       /* with options.light_groups: NAME.R, NAME.G, NAME.B for each
                                  * of the scene's light groups in order (scene.h), the mean
                                  * radiance of that group alone: the groups sum to image's
                                  * R, G, B up to float rounding (an interrupted render's
                                  * groups also hold part of the paths then in flight);
                                  * free with image_free() */
    rt_image adaptive_state;     /* with noise_threshold, of the whole image (region all
                                  * zero), when the passes stopped before the end (time,
                                  * interrupt): what resume continues from, the channels of
                                  * RENDER_ADAPTIVE_STATE_CHANNEL_NAMES (below). Empty
                                  * otherwise; free with image_free() */
    uint64_t samples;            /* samples finished over all pixels */
    uint32_t samples_min, samples_max;   /* the fewest and most samples a pixel finished */
    double seconds;              /* whole render, including set-up */
    double first_pass_seconds;   /* from the start until the first pass finished */
    double steady_seconds;       /* the passes after the first (set-up and compile done) */
    uint64_t steady_samples;     /* samples those passes finished: their ratio is the
                                  * cost of a sample, whatever the set-up cost */
    double pack_seconds;         /* pack_scene(): collecting, BVH builds (bvh_build_seconds
                                  * of it) and packing, on the CPU */
    double compile_seconds;      /* the tracer program's compile and link (0: cached) */
    double upload_seconds;       /* the packed scene to the device (0: already there) */
    double path_segments;        /* rays traced, counted by the shader */
    int passes;
    int culled_passes;           /* passes that skipped finished pixels (gpu.h gpu_tracer_cull_finished) */
    render_stop_reason stop_reason;
    int bvh_depth;
    bool threaded_walk;          /* the tracer walked the BVH as threaded lists, no stack
                                  * (packed_layout.h "threaded walk"; still spheres and
                                  * quads in one level) */
    double bvh_build_seconds;
    uint64_t packed_bytes;       /* the whole packed scene, images included */
    uint64_t image_bytes;        /* of which image pixels */
    uint32_t triangle_count;     /* triangles stored (a mesh once however often placed) */
    uint32_t primitive_count, instance_count, light_count;
    render_light_choice light_choice;   /* how a point's light to sample is picked */
    uint32_t light_tree_depth;   /* the light tree's deepest leaf (0: no tree) */
    bool reused_scene;           /* the device already held this packed scene (frames) */
    uint32_t bvh_built, bvh_reused;   /* BVHs built, and taken from options.bvh_cache */
    uint64_t uploaded_bytes;     /* of the packed scene sent to the device for this render:
                                  * all, none (reused_scene) or the blocks that changed
                                  * (gpu.h gpu_tracer_uploaded_bytes()) */
    bool compiled_program;       /* the tracer program was compiled for this render (not
                                  * found in the context's cache) */
    uint64_t scene_hash;         /* FNV-1a of what decides the image apart from the samples:
                                  * packed scene, camera, sky, full size, max depth. Parts of
                                  * one render share it; `merge` refuses mixed hashes. */
} render_result;

/* The adaptive state layer (render_result.adaptive_state, render_options.resume): where
 * an adaptive render stood at its last check, or before its first, whose samples are each
 * pixel's first ones, so that a render resumed from it continues the same samples to the
 * same decisions. Per pixel, float32: the sums (not means) of R, G, B over the pixel's
 * finished samples, their count, the sum of their squared luminance (core/luminance.h),
 * and the pixel's sample limit (adaptive.h adaptive_resume). A pixel's samples after that
 * check (in R, G, B and samples, which the layer leaves as they are) are traced again. */
#define RENDER_ADAPTIVE_STATE_CHANNELS 6
#define RENDER_ADAPTIVE_STATE_CHANNEL_NAMES \
    {"adaptive.sum.R", "adaptive.sum.G", "adaptive.sum.B", "adaptive.samples", "adaptive.sum.Y2", "adaptive.limit"}

/* True when partial (a partial render read back, render_options.resume) has the adaptive
 * state layer, which an adaptive render needs to resume it. */
bool render_partial_has_adaptive_state(const rt_image *partial);

/* Returns options with every field at its default (all zero). */
render_options render_options_defaults(void);

/* Returns an estimate of the memory a render with these options takes per traced pixel at
 * its peak, on the device and the host together (the state textures, gpu.h
 * GPU_TRACER_STATE_BYTES_PER_PIXEL; the read-back copies; the result and its layers;
 * adaptive sampling's buffers), light_group_count the scene's groups (counted only with
 * options->light_groups). What render jobs tile an image by (render_job.h). */
uint64_t render_bytes_per_pixel(const render_options *options, int light_group_count);

/* Computes the scene hash render_scene() would give s with options (render_result.
 * scene_hash) into *hash without a GPU: frames the camera and packs the scene on the CPU
 * (BVH builds included), then frees the packing. For telling whether an existing file was
 * rendered from this scene (--skip-existing). Errors: those of camera framing and
 * pack_scene(). */
rt_status render_scene_hash(const scene *s, const render_options *options, uint64_t *hash, rt_error *error);

/* Renders s with the scene's render settings on context. options may be NULL. On RT_OK
 * and on RT_ERROR_INTERRUPTED, result->image holds the image (the caller frees it with
 * image_free()); on other errors it is empty. */
rt_status render_scene(gpu_context *context, const scene *s, const render_options *options,
                       render_result *result, rt_error *error);

#endif
