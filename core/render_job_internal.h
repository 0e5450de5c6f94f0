/* render_job_internal.h: what the running half of render jobs (render_job.c) shares with
 * its tiled renders (render_job_tiles.c); no other file includes it. */
#ifndef RT_RENDER_JOB_INTERNAL_H
#define RT_RENDER_JOB_INTERNAL_H

#include "pack.h"
#include "render_job.h"
#include "render_output.h"

/* One run of a job: what every image needs. */
typedef struct job_run {
    gpu_context *context;
    const render_job *job;
    render_job_plan plan;
    render_job_callbacks callbacks;      /* the caller's, or all NULL */
    render_job_failure failure;          /* where the run stopped short */
    bool image_begun;                    /* an image has begun (its limit counted from then) */
    int images_skipped;                  /* skip_existing found them complete */
    int sweep_row;                       /* the sweep row being rendered, -1: none */
    pack_bvh_cache *bvh_cache;           /* with several images: their BVHs carried over */
} job_run;

/* One image being rendered: its scene (render settings after the job's overrides and
 * plan) and its plan. */
typedef struct job_image {
    job_run *run;
    scene scene;
    render_job_image plan;
    double start;                        /* clock_seconds() its time limit counts from */
} job_image;

/* The texts a render_output_metadata points into. */
typedef struct job_metadata_texts {
    char hash[24];
    char options_hash[24];
    char groups[SCENE_LIGHT_GROUP_MAX * (SCENE_LIGHT_GROUP_NAME_MAX + 1) + 1];
    char postprocess[64];
} job_metadata_texts;

/* Fills *metadata (pointing into *texts) for image's file at path (the output lists its
 * light groups and the post-processing of its colour; the partial file keeps no layers and
 * raw colour): samples finished, complete (the render
 * ended by its own rule), checkpoint (a checkpoint's file: no stop reason); result gives
 * the scene hash, path segments, time and stop reason. */
void job_image_metadata(const job_image *image, const char *path, uint64_t samples, bool complete,
                        bool checkpoint, const render_result *result, render_output_metadata *metadata, job_metadata_texts *texts);

/* Returns the exposure the writer applies (image_write_options.exposure): the job's, but
 * 0 after a tone-mapping operator, which applied it already. */
float job_output_exposure(const render_job *job);

/* Makes the heat map of the samples channel (the fourth) of rows, an image of R, G, B,
 * samples and any more channels, into *map (new, RGB, rows' size; the caller frees it):
 * OpenImageIO's "inferno" colour map (black, purple, red, orange, yellow) over
 * log(1 + n) / log(1 + samples_per_pixel), so that both the pixels of --min-spp and the
 * few that took hundreds show (each doubling of the count is the same step along the map:
 * at 1024 spp, 16 samples are 0.41 of the way, 64 0.60, 256 0.80), in linear values as
 * image_write() takes them. Errors: image_create()'s, image_color_map()'s. */
rt_status job_samples_map(const rt_image *rows, int samples_per_pixel, rt_image *map, rt_error *error);

/* The tiles of one image (render_job.h, "Tiles"): columns x rows over its window. */
typedef struct job_tile_grid {
    int count;                           /* columns * rows; 1: the image is not tiled */
    int columns, rows;
    int tile_width, tile_height;         /* the largest tile (the last ones may be smaller) */
    uint64_t budget;                     /* the memory budget it was planned for */
    const char *reason;                  /* why it is tiled, for messages */
} job_tile_grid;

/* Plans the tiles of image rendered with options (render_job.h, "Tiles") into *grid.
 * Returns RT_ERROR_INPUT when a tile of one row would not fit the budget (naming the
 * least budget that works), or when the image tiles and the job asks for something
 * tiles cannot do (the refusals of "Tiles"). */
rt_status job_plan_tiles(const job_image *image, const render_options *options, job_tile_grid *grid,
                         rt_error *error);

/* Renders image tile by tile as grid says, with options (the image's), writes its
 * output (and samples map), removes its partial file and tells the callbacks, as an
 * untiled image is finished. */
rt_status job_render_tiles(job_image *image, const render_options *options, const job_tile_grid *grid,
                           rt_error *error);

/* After a failed render of image: a message that suggests a smaller --memory-budget
 * (render.h, gpu.h) gets the budget in force appended, so the user knows where from. */
void job_name_memory_budget(const job_image *image, rt_error *error);

#endif
