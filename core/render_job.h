/* render_job.h: plans and runs a render job: one image, or a list of frames, of one scene
 * file, each image possibly one part of a larger render (a sample range, a crop, a tile,
 * one shard of the frames, the samples or the tiles), resumed from a partial file,
 * checkpointed, post-processed (denoise, blur, tone mapping; AOV layers) and written
 * atomically with its metadata (render_output.h). `rtspheres render` only turns its
 * arguments into a render_job; a test or a server renders a job the same way.
 *
 * ## The job
 * A plain struct; zero means default (render_job_defaults() returns it all zero):
 *   scene_path, output      required; scene_path a scene file, or a glTF file (.gltf, .glb:
 *                           a scene by itself, scene_gltf.h); output is a name pattern (batch.h): with frames each
 *                           frame formats it, without them it is formatted once with the
 *                           value of the last define of `frame`, else with 0
 *   defines                 scene variables (scene_parse.h) for every image; none (a glTF
 *                           scene has no variables: a define is refused)
 *   camera                  NULL: the scene's camera; a glTF scene's camera (or camera
 *                           node) of that name; only for a glTF scene
 *   frames                  frame numbers to render (batch.h frame_list); none: one image
 *                           without $frame and $time. Each frame sets $frame and $time =
 *                           frame / frames_per_second (default 24) as optional variables.
 *   samples_per_pixel, width, height, max_depth   0: the scene's `render` line
 *   seed_set, seed          seed_set false: the scene's seed
 *   sample_start, sample_count   count 0: every sample of the scene (or of the shard);
 *                           else indices sample_start .. sample_start + count - 1
 *   crop                    x0, y0, x1, y1 (row 0 at the top, x1/y1 exclusive); all zero:
 *                           the whole image
 *   tile_index, tile_count  count 0: no tile; else horizontal band index of count
 *                           (batch.h shard_range over the rows)
 *   shard_index, shard_count, shard_by   count 0: no shard; else part index of count of
 *                           the work: by frames (frame list positions i with i % count ==
 *                           index), samples (shard_range over the samples per pixel) or
 *                           tiles (as tile index/count); RENDER_SHARD_AUTO: frames when
 *                           the job lists several frames, else samples
 *   resume_path             NULL: start afresh; else continue that partial file
 *   checkpoint_seconds      0: never; else write the partial file that often
 *   aovs                    add the AOV layers (render.h) to an EXR
 *   light_groups            add a layer per light group (render.h render_result.light_groups,
 *                           NAME.R/G/B) to an EXR; not with denoise or blur (the layers
 *                           would not sum to the image) nor resume (a partial file keeps
 *                           no layers); tiles, crops, sample ranges and shards merge them
 *   variance                add the variance layers variance.R/G/B (render.h) to an EXR
 *   denoise                 postprocess_denoise() guided by the AOVs, the render's per-pixel
 *                           variance and its direct emission (render.h; not when resumed);
 *                           an EXR keeps the noisy colour as noisy.R/G/B and the direct
 *                           emission as emission.R/G/B
 *   blur_sigma, blur_passes sigma 0: no blur; passes 0: 1
 *   tonemap, exposure       for 8-bit outputs: TONEMAP_CLAMP and 0 stops
 *   samples_map             NULL: none; else also write each pixel's samples / spp as a
 *                           grey image there (any format: white is spp samples; an
 *                           8-bit format's sRGB curve brightens the few): where the
 *                           time went with adaptive sampling or a time limit; one image
 *                           only (not with several frames)
 *   time_limit_seconds      0: none; else each image ends within about one pass of this
 *                           many seconds after its start (render_options.deadline), and
 *                           is written with what it has (rtspheres:stop_reason time)
 *   time_limit_start        the clock_seconds() time the first image's limit counts from
 *                           (`rtspheres render`: its process's start); 0: the job's start.
 *                           Every later frame's counts from when it begins: the limit is
 *                           per image, so a job of F frames ends within about F times it
 *   memory_budget           bytes an image's render may take on the device and the host
 *                           together (see "Tiles"); 0: render_job_default_memory_budget()
 *   tracer                  how each image is traced (render.h; zero = its defaults; its
 *                           noise_threshold and min_spp: adaptive sampling). The job sets
 *                           its sample_start, region, aovs, variance, progress,
 *                           stop_requested, deadline, resume, checkpoint and bvh_cache
 *                           fields itself (a job of several frames or rows keeps one BVH
 *                           cache, pack.h, for all of them).
 *   stop_requested          NULL: never; else a non-zero value ends the job: the pass in
 *                           flight finishes and its samples go to the partial file
 *   skip_existing           false: render every image; true: before each image, look at
 *                           what its output and partial file hold (see "Existing outputs")
 *   sweep                   NULL: none; else a sweep table (sweep.h): one image per row,
 *                           each row's values as defines after the job's, the output
 *                           pattern formatted per row (sweep_output_name); rows shard
 *                           as frames do; not with frames or resume
 *
 * ## Planning
 * render_job_check() checks the fields against each other and against the file system
 * before anything is rendered: the first output name, its format (image_io.h), its
 * directory, that it is not the scene file, and the rules between crop, tile, shards,
 * samples, AOVs, resume and frames. Each image is then planned by
 * render_job_plan_image() from the scene's render settings, which are known only once
 * the scene is loaded (an empty sample shard or tile is refused there).
 *
 * ## Tiles
 * An image (its window: the whole image, the crop or the --tile band) whose traced pixels
 * would take more than memory_budget (render_bytes_per_pixel() each, render.h), or that is
 * wider or taller than the device's gpu_info.max_tile_side, is rendered in tiles
 * (render_job_tiles.c): a grid of at most max_tile_side a side (less adaptive sampling's
 * margins) whose tiles fit the budget, each rendered by render_scene() as a region, so
 * its pixels are exactly the untiled render's. Finished tiles go to a spool file beside
 * the output (".NAME.tiles-XXXXXX": 4 bytes per channel per pixel on disk, removed at the
 * end); then the output is streamed from it band by band (render_output_stream) with the
 * final metadata, atomically as always; neither the device nor the process holds more
 * than one tile and one band. Under tiling: AOVs, variance, light groups, adaptive
 * sampling, tone mapping and the samples map work as untiled; denoise and blur too, in
 * square blocks read from the spool with the filters' reach (postprocess.h) more pixels
 * on every side, the filtered colour spooled to a second file for the output's bands, so
 * that the pixels are the untiled ones; a time limit is shared out over the tiles
 * (tile k of n ends by start + limit * (k + 1) / n: unused time passes on, and every tile
 * gets its first pass); --checkpoint, --resume and --display are refused (RT_ERROR_INPUT naming the tiling and what to do), and an
 * interrupted tiled render writes no partial file (the output stays as it was).
 *
 * ## Running
 * render_job_run() renders the images in order on one GPU context. Each image: the scene
 * is loaded with its variables (asset warnings go to the warning callback with the image
 * of the list's first frame only, so a shard by frames without it shows none), planned,
 * rendered (render_scene()), post-processed, and written; on success its partial file is
 * removed. A stop request during a render writes the samples done to the partial file
 * (never over the output) as a checkpoint does: the raw means and sample counts, not
 * post-processed, since --resume adds samples to them; then it ends the job. One between
 * frames ends it before the next frame. The first failing image ends the job.
 *
 * ## Existing outputs (skip_existing)
 * Each image, once its scene is loaded and planned, is looked at as
 * render_job_examine_existing() says: an output that is complete (rtspheres:complete 1)
 * with this image's scene hash and options hash (render_job_options_hash()) is skipped
 * (nothing written, its partial file left alone); else a partial file of this image's
 * scene and options is resumed, or an incomplete output of them (--time-limit wrote it)
 * when it is a raw EXR; anything else is rendered afresh. The callback existing_output
 * says which and why, for every image whose output or partial file exists.
 *
 * Messages name the job's fields by the render command's options (--crop, --shard, ...),
 * the words a user sets them in, and carry no module tag: the command prints them after
 * "rtspheres render: ". Scene errors are the scene parser's, starting with the file's
 * path and position. Bad fields and files are RT_ERROR_INPUT.
 */
#ifndef RT_RENDER_JOB_H
#define RT_RENDER_JOB_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gpu.h"
#include "postprocess.h"
#include "render.h"
#include "scene.h"
#include "scene_parse.h"
#include "status.h"
#include "sweep.h"

#define RENDER_JOB_PATH_MAX 4096
#define RENDER_JOB_DEFAULT_FRAMES_PER_SECOND 24.0

typedef enum render_job_shard_kind {
    RENDER_SHARD_AUTO = 0,       /* frames with several frames, else samples */
    RENDER_SHARD_FRAMES,
    RENDER_SHARD_SAMPLES,
    RENDER_SHARD_TILES,
} render_job_shard_kind;

/* What to render and write; see "The job" above for each field's default. */
typedef struct render_job {
    const char *scene_path;
    const char *output;
    const char *camera;
    const scene_define *defines;
    int define_count;
    const int *frames;
    int frame_count;
    double frames_per_second;
    int samples_per_pixel, width, height, max_depth;
    bool seed_set;
    uint32_t seed;
    uint32_t sample_start, sample_count;
    int crop[4];
    int tile_index, tile_count;
    int shard_index, shard_count;
    render_job_shard_kind shard_by;
    const char *resume_path;
    double checkpoint_seconds;
    bool aovs;
    bool light_groups;
    bool variance;
    bool denoise;
    float blur_sigma;
    int blur_passes;
    postprocess_tonemap_operator tonemap;
    double exposure;
    const char *samples_map;
    double time_limit_seconds;
    double time_limit_start;
    uint64_t memory_budget;
    render_options tracer;
    const volatile sig_atomic_t *stop_requested;
    const sweep_table *sweep;
    bool skip_existing;
} render_job;

/* What render_job_check() found: the first output name and the shard resolved. */
typedef struct render_job_plan {
    char first_output[RENDER_JOB_PATH_MAX];  /* the first image's output name (the only
                                              * one without frames) */
    const char *frame_define;                /* the value of the last define of `frame`, or
                                              * NULL */
    render_job_shard_kind shard_by;          /* with a shard: never RENDER_SHARD_AUTO */
    int tile_index, tile_count;              /* the band to render (tile_count 0: none):
                                              * the job's tile, or its shard by tiles */
} render_job_plan;

/* One image of the job as planned: what the callbacks are told. */
typedef struct render_job_image {
    int frame;                   /* -1: the job has no frames */
    const char *output;          /* the file it is written to */
    char partial[RENDER_JOB_PATH_MAX];  /* its partial file (render_output_partial_path()) */
    uint32_t sample_start;       /* its samples: sample_start .. + samples_per_pixel - 1 */
    int samples_per_pixel;
    int region[4];               /* render_options.region: all zero for the whole image */
    int window[4];               /* the pixels it covers: region, or the whole image */
    uint64_t options_hash;       /* render_job_options_hash() of the image */
    int sweep_row;               /* -1: the job has no sweep */
} render_job_image;

/* What skip_existing decided for an image (render_job_examine_existing()). */
typedef enum render_job_existing_kind {
    RENDER_JOB_EXISTING_NONE = 0,    /* neither output nor partial file is there: render */
    RENDER_JOB_EXISTING_SKIP,        /* the output is complete, of this scene and options */
    RENDER_JOB_EXISTING_RESUME,      /* continue the file named in the decision */
    RENDER_JOB_EXISTING_RENDER,      /* something is there but will not do: render afresh */
} render_job_existing_kind;

typedef struct render_job_existing {
    render_job_existing_kind kind;
    char resume_path[RENDER_JOB_PATH_MAX];   /* RESUME: the partial file or the output */
    char reason[1024];                       /* one sentence: what is there and why this */
} render_job_existing;

/* How far each frame's scene variables need room: $frame's and $time's values. */
typedef struct render_job_frame_values {
    char frame[32];
    char time[64];
} render_job_frame_values;

/* Events of a running job; every callback may be NULL. user goes to each. */
typedef struct render_job_callbacks {
    void *user;
    /* A warning of the scene's assets (a missing MTL file, ...), with the first frame only. */
    void (*warning)(void *user, const char *message);
    /* The image is rendered in columns x rows tiles of at most tile_width x tile_height
     * (render_job.h "Tiles"); reason says why ("it is larger than the device's ..."). Told
     * before render_started; never for an untiled image. */
    void (*tiles_planned)(void *user, const render_job_image *image, int columns, int rows, int tile_width,
                          int tile_height, const char *reason);
    /* The image's passes are about to start (the scene is loaded and the image planned). */
    void (*render_started)(void *user, const render_job_image *image);
    /* render_options.progress of each pass. */
    void (*progress)(void *user, const render_progress *progress);
    /* The passes have ended with status (RT_OK, RT_ERROR_INTERRUPTED or an error). */
    void (*render_finished)(void *user, const render_job_image *image, rt_status status);
    /* A checkpoint wrote samples (over all pixels) to image->partial. */
    void (*checkpoint_written)(void *user, const render_job_image *image, uint64_t samples);
    /* skip_existing looked at the image's files (decision->kind is not NONE): a skip (no
     * other callback follows for the image), a resume or a render afresh, and why. */
    void (*existing_output)(void *user, const render_job_image *image, const render_job_existing *decision);
    /* The complete image is written to image->output; result is render_scene()'s. */
    void (*image_written)(void *user, const render_job_image *image, const render_result *result);
} render_job_callbacks;

/* Where a job stopped short, for the caller to word it. */
typedef enum render_job_failure {
    RENDER_JOB_FAILURE_NONE = 0, /* every image is written */
    RENDER_JOB_FAILURE_PLAN,     /* render_job_check() refused the job; nothing rendered */
    RENDER_JOB_FAILURE_SCENE,    /* loading the scene or its assets; the message is the
                                  * parser's, starting with the file's position */
    RENDER_JOB_FAILURE_IMAGE,    /* an image's name, planning, render, post-processing or
                                  * writing; or it was interrupted (RT_ERROR_INTERRUPTED,
                                  * the message says where the partial file went) */
    RENDER_JOB_FAILURE_STOPPED,  /* a stop request between frames: RT_ERROR_INTERRUPTED,
                                  * nothing half done, an empty message */
} render_job_failure;

typedef struct render_job_summary {
    int images_started;          /* images the job went on to (loading their scene), the
                                  * last of which may have failed */
    int images_skipped;          /* of those, skipped as complete (skip_existing) */
    double seconds;              /* from the first image's start to the last one's end */
    render_job_failure failure;
} render_job_summary;

/* Returns a job with every field at its default (all zero). */
render_job render_job_defaults(void);

/* Returns the memory budget of a job that sets none: a quarter of the machine's physical
 * memory, at most RENDER_JOB_DEFAULT_MEMORY_BUDGET_MAX (512 MiB; why: docs/performance.md,
 * "Memory"). */
#define RENDER_JOB_DEFAULT_MEMORY_BUDGET_MAX (512ull << 20)
uint64_t render_job_default_memory_budget(void);

/* Returns "frames", "samples" or "tiles" ("auto" for RENDER_SHARD_AUTO): the words of
 * --shard-by. */
const char *render_job_shard_kind_name(render_job_shard_kind kind);

/* Checks job (see "Planning" above) and fills *plan. Returns RT_OK, or RT_ERROR_INPUT
 * with the first rule broken, in this order: a define of frame or time with frames; the
 * first output name (batch.h's errors; several frames and no frame number in the
 * pattern); its format; its directory; the scene file as output; crop with tile; aovs
 * without EXR; variance without EXR; variance with resume; skip_existing with resume;
 * resume with several frames; shard_by without shard; a shard by frames without frames,
 * or with no frame; light groups
 * (see the job); a shard by samples with a sample range; a shard by tiles with crop or
 * tile; a samples map with several frames or of an unknown
 * format; a minimum spp without a noise threshold; a noise threshold with a shard by samples,
 * a sample range, or resume of part of the image (crop, tile, shard by tiles); a sweep with frames, resume or a define
 * of one of its columns, two of its rows writing one file (the table's file:line). */
rt_status render_job_check(const render_job *job, render_job_plan *plan, rt_error *error);

/* True when the frame at position index of job->frames is this job's to render (always,
 * but for a shard by frames). */
bool render_job_includes_frame(const render_job *job, const render_job_plan *plan, int index);

/* Writes the output name of frame (-1: the job has no frames) into name (size bytes).
 * Errors: batch.h's output_pattern_format() and output_name_without_frames(). */
rt_status render_job_output_name(const render_job *job, const render_job_plan *plan, int frame, char *name,
                                 size_t size, rt_error *error);

/* Fills defines (room for job->define_count + 2) with the job's defines and, when frame
 * >= 0, the optional $frame and $time, whose text goes into *values. Returns the count. */
int render_job_scene_defines(const render_job *job, int frame, scene_define *defines,
                             render_job_frame_values *values);

/* Applies the job's overrides (samples per pixel, size, max depth, seed) to settings. */
void render_job_apply_overrides(const render_job *job, scene_render_settings *settings);

/* Plans the samples and region of one image from settings (the scene's, after
 * render_job_apply_overrides()): the job's sample range, or its shard of the samples,
 * else all; its crop, or its tile's band, else the whole image. Fills every field of
 * *image but output and partial. An empty shard of the samples or an empty tile is
 * RT_ERROR_INPUT ("... is empty; use fewer shards/tiles"). */
rt_status render_job_plan_image(const render_job *job, const render_job_plan *plan,
                                const scene_render_settings *settings, int frame, render_job_image *image,
                                rt_error *error);

/* Returns the options hash of image (planned from settings, the scene's after
 * render_job_apply_overrides()): FNV-1a over what changes its pixels or layers beyond the
 * scene hash (render.h scene_hash: packed scene, camera, sky, size, depth, integrator,
 * sampler, light sampling): size, depth, seed, the image's samples (first index and
 * count), its region (crop, tile, shard by tiles), Russian roulette depth, noise threshold
 * and min spp, AOVs, light groups, variance, denoise, blur, tone mapping and exposure.
 * Not: frames/sweep/shard lists, time limit, checkpoints, the pass budget, --full-tracer,
 * the device, threads, progress, statistics or the display, which change no pixel. */
uint64_t render_job_options_hash(const render_job *job, const render_job_image *image,
                                 const scene_render_settings *settings);

/* Looks at what image's output and partial file hold (see "Existing outputs" above) for a
 * render from s (loaded, planned; the hashes are computed from it as render_scene() would,
 * packing it on the CPU only when a file is there to compare), and fills *decision. With
 * RENDER_JOB_EXISTING_RESUME, *resume (else empty) holds the file's pixels and
 * *resume_scene_hash its hash, as render_options.resume takes them; free it with
 * image_free(). Errors: only those of packing the scene (a file that cannot be read is a
 * reason to render afresh, not an error). In render_job_existing.c. */
rt_status render_job_examine_existing(const render_job *job, const render_job_image *image, const scene *s,
                                      render_job_existing *decision, rt_image *resume, uint64_t *resume_scene_hash,
                                      rt_error *error);

/* Plans job (render_job_check(), so the caller need not) and renders its images on
 * context (see "Running" above), telling callbacks (may be NULL) what happens. Returns
 * RT_OK when every image is written, else the first failure's status and message with
 * summary->failure saying where; summary may be NULL. */
rt_status render_job_run(gpu_context *context, const render_job *job, const render_job_callbacks *callbacks,
                         render_job_summary *summary, rt_error *error);

#endif
