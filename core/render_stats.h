/* render_stats.h: the figures of a render job, machine-readable: what the summary line and
 * --verbose say, for every image, as one JSON document (`rtspheres render --stats-json`).
 * The schema is docs/stats-json.md, versioned by RENDER_STATS_SCHEMA_VERSION (raised when
 * a field changes meaning or goes away; new fields may appear within a version).
 *
 * Use: render_stats_init() with the device, then one render_stats_add_*() per image as
 * the job's callbacks tell of it (render_job.h), render_stats_write() whenever the file
 * should reflect what is known (the render command writes it after every image, so a job
 * killed half way leaves the images it finished), render_stats_free() at the end.
 * Nothing here prints; the file is written to a temporary file beside it and renamed.
 */
#ifndef RT_RENDER_STATS_H
#define RT_RENDER_STATS_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu.h"
#include "render.h"
#include "render_job.h"
#include "status.h"

#define RENDER_STATS_SCHEMA_VERSION 1

/* What happened to one image. */
typedef enum render_stats_outcome {
    RENDER_STATS_RENDERED = 0,   /* written to its output */
    RENDER_STATS_SKIPPED,        /* --skip-existing: its output was complete */
    RENDER_STATS_FAILED,         /* its render or its writing failed */
    RENDER_STATS_INTERRUPTED,    /* stopped; its samples went to the partial file */
} render_stats_outcome;

/* One image's entry (copied out of the job's callbacks; owns nothing). */
typedef struct render_stats_image {
    render_stats_outcome outcome;
    render_job_image plan;       /* output and partial names copied into the strings below */
    char output[RENDER_JOB_PATH_MAX];
    char note[1024];             /* skip or resume reason, or the failure's message */
    bool resumed;
    bool has_result;             /* the figures below are filled (rendered) */
    render_result result;        /* its images are not kept (pixels NULL) */
    uint32_t spp_min, spp_max;   /* per-pixel samples over the image */
    double spp_mean;
    long long peak_rss_bytes;    /* of the process, when the image ended */
    double first_pass_after_start;   /* seconds from the command's start to its first
                                      * pass's end (context, parse, BVH, upload, compile);
                                      * < 0: unknown */
} render_stats_image;

typedef struct render_stats {
    gpu_info device;
    int threads_requested;       /* --threads, 0: none */
    double context_seconds;      /* creating the GPU context */
    double before_command_seconds;   /* from the process's start to the command's (the
                                      * libraries' loading before main, core/clock.h) */
    const char *scene;           /* the scene file, as given */
    const char *output;          /* the output name or pattern, as given */
    render_stats_image *images;
    int image_count, image_capacity;
    double job_seconds;          /* render_job_summary.seconds, once the job ended (0 before) */
    bool job_finished;
    const char *job_error;       /* NULL, or the job's failure message */
} render_stats;

/* Starts *stats for a job of scene and output on device (copied). Allocates nothing. */
void render_stats_init(render_stats *stats, const gpu_info *device, int threads_requested, double context_seconds,
                       double before_command_seconds, const char *scene, const char *output);

/* Adds a rendered image with its result (render_job_callbacks.image_written): sizes, the
 * per-pixel samples (the result's samples channel), timings, figures, peak memory.
 * first_pass_after_start as in render_stats_image. RT_ERROR_RUNTIME when out of memory. */
rt_status render_stats_add_rendered(render_stats *stats, const render_job_image *image, const render_result *result,
                                    bool resumed, double first_pass_after_start, rt_error *error);

/* Adds an image that was not rendered: skipped (note: why), failed or interrupted (note:
 * the message). */
rt_status render_stats_add_other(render_stats *stats, const render_job_image *image, render_stats_outcome outcome,
                                 const char *note, rt_error *error);

/* Writes stats as JSON to path atomically. Errors: RT_ERROR_RUNTIME "STATS: cannot
 * write 'path': reason". */
rt_status render_stats_write(const render_stats *stats, const char *path, rt_error *error);

/* Frees the image list and zeroes *stats. */
void render_stats_free(render_stats *stats);

/* Returns "rendered", "skipped", "failed" or "interrupted". */
const char *render_stats_outcome_name(render_stats_outcome outcome);

#endif
