/* render_job.c: the running half of render_job.h: each image's scene, render, post-processing
 * and files. The planning half is render_job_plan.c, the files' format render_output.c. */
#include "render_job.h"
#include "render_job_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "adaptive.h"
#include "clock.h"
#include "image_io.h"
#include "paths.h"
#include "render_denoise.h"
#include "render_output.h"
#include "scene_assets.h"
#include "scene_gltf.h"

/* Loads the scene with the variables of frame (-1: none) and its assets into *s. On
 * failure *s is freed, and run->failure says whether the scene's own message is the error. */
static rt_status load_scene(job_run *run, int frame, scene *s, rt_error *error)
{
    const render_job *job = run->job;
    int columns = job->sweep != NULL && run->sweep_row >= 0 ? job->sweep->column_count : 0;
    scene_define *defines = malloc(((size_t)job->define_count + 2 + (size_t)columns) * sizeof *defines);
    if (defines == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory for the scene's variables");
    run->failure = RENDER_JOB_FAILURE_SCENE;
    render_job_frame_values values;
    scene_parse_options parse_options = scene_parse_options_defaults();
    parse_options.defines = defines;
    parse_options.define_count = render_job_scene_defines(job, frame, defines, &values);
    for (int c = 0; c < columns; c++)
        defines[parse_options.define_count++] = (scene_define){
            .name = job->sweep->names[c],
            .value = job->sweep->values[(size_t)run->sweep_row * columns + c],
        };
    /* A glTF file is a scene by itself (scene_gltf.h); render_job_check() refused defines
     * for it, and its frames' $frame and $time are optional. */
    rt_status status = scene_gltf_is_model_path(job->scene_path)
                           ? scene_gltf_load_file(job->scene_path, job->camera, s, error)
                           : scene_load_file(job->scene_path, &parse_options, s, error);
    free(defines);
    /* A column the scene does not use is the table's mistake: say where. */
    for (int c = 0; c < columns && status == RT_ERROR_INPUT; c++) {
        char expected[2 * SWEEP_NAME_MAX + 64];
        snprintf(expected, sizeof expected, "-D %s: the scene never sets or uses $%s", job->sweep->names[c],
                 job->sweep->names[c]);
        if (strstr(error->message, expected) != NULL) {
            status = rt_error_set(error, RT_ERROR_INPUT, "%s:%d: column '%s': the scene never sets or uses $%s",
                                  job->sweep->path, job->sweep->header_line, job->sweep->names[c],
                                  job->sweep->names[c]);
            run->failure = RENDER_JOB_FAILURE_IMAGE;
        }
    }
    if (status == RT_OK) {
        status = scene_load_assets(s, error);
        if (status != RT_OK)
            scene_free(s);
    }
    return status;
}

void job_image_metadata(const job_image *image, const char *path, uint64_t samples, bool complete,
                        bool checkpoint, const render_result *result, render_output_metadata *metadata, job_metadata_texts *texts)
{
    const render_job *job = image->run->job;
    const scene_render_settings *settings = &image->scene.render;
    snprintf(texts->hash, sizeof texts->hash, "%016llx", (unsigned long long)result->scene_hash);
    snprintf(texts->options_hash, sizeof texts->options_hash, "%016llx", (unsigned long long)image->plan.options_hash);
    /* The layers' names, with the output (also one a time limit ended; the partial file
     * keeps no layers). */
    bool layers = job->light_groups && strcmp(path, image->plan.output) == 0;
    texts->groups[0] = '\0';
    for (int g = 0; layers && g < image->scene.light_group_count; g++)
        snprintf(texts->groups + strlen(texts->groups), sizeof texts->groups - strlen(texts->groups), "%s%s",
                 g > 0 ? "," : "", image->scene.light_groups[g]);
    /* What --denoise and --blur did to the output's colour (postprocess_result below). */
    texts->postprocess[0] = '\0';
    bool output = strcmp(path, image->plan.output) == 0 && !checkpoint;
    if (output && job->denoise)
        snprintf(texts->postprocess, sizeof texts->postprocess, "denoise");
    if (output && job->blur_sigma > 0)
        snprintf(texts->postprocess + strlen(texts->postprocess), sizeof texts->postprocess - strlen(texts->postprocess),
                 "%sblur sigma=%g passes=%d", job->denoise ? "; " : "", job->blur_sigma,
                 job->blur_passes > 0 ? job->blur_passes : 1);
    *metadata = (render_output_metadata){
        .scene = job->scene_path,
        .scene_hash = texts->hash,
        .options_hash = texts->options_hash,
        .spp = settings->samples_per_pixel,
        .sample_start = image->plan.sample_start,
        .seed = settings->seed,
        .max_depth = settings->max_depth,
        .frame = image->plan.frame,
        .samples_finished = samples,
        .path_segments = result->path_segments,
        .complete = complete,
        .render_seconds = result->seconds,
        .light_groups = texts->groups[0] != '\0' ? texts->groups : NULL,
        .postprocess = texts->postprocess[0] != '\0' ? texts->postprocess : NULL,
    };
    if (!checkpoint) {
        bool adaptive = job->tracer.noise_threshold > 0;
        uint32_t min_spp = job->tracer.min_spp ? job->tracer.min_spp : ADAPTIVE_DEFAULT_MIN_SPP;
        metadata->stop_reason = render_stop_reason_name(result->stop_reason);
        metadata->noise_threshold = adaptive ? job->tracer.noise_threshold : 0.0f;
        metadata->min_spp = !adaptive ? 0 : min_spp < (uint32_t)settings->samples_per_pixel ? (int)min_spp
                                                                                          : settings->samples_per_pixel;
    }
}

float job_output_exposure(const render_job *job)
{
    /* With a tone-mapping operator the exposure was applied before it (postprocess). */
    return job->tonemap != TONEMAP_CLAMP ? 0.0f : (float)job->exposure;
}

/* Writes pixels (R, G, B means, samples, of the image's region) to path with the
 * metadata of image; complete says whether the render ended by its own rule. result gives
 * the layers (the AOVs, then the adaptive state when there is one), region, path segments,
 * scene hash, time and (but for a checkpoint, whose passes have not ended) the stop
 * reason. */
static rt_status write_image(const job_image *image, const rt_image *pixels, const char *path, uint64_t samples,
                             bool complete, bool checkpoint, const render_result *result, rt_error *error)
{
    rt_image layers = {0};
    const rt_image *written = &result->aovs;
    if (result->adaptive_state.pixels != NULL) {
        written = &result->adaptive_state;
        if (result->aovs.pixels != NULL) {
            rt_status status = image_append_channels(&result->aovs, &result->adaptive_state, &layers, error);
            if (status != RT_OK)
                return status;
            written = &layers;
        }
    }
    const scene_render_settings *settings = &image->scene.render;
    rt_image placed = *pixels;
    placed.x = result->region[0];
    placed.y = result->region[1];
    placed.full_width = settings->width;
    placed.full_height = settings->height;
    render_output_metadata metadata;
    job_metadata_texts texts;
    job_image_metadata(image, path, samples, complete, checkpoint, result, &metadata, &texts);
    rt_status status =
        render_output_write(path, &placed, written, &metadata, job_output_exposure(image->run->job), error);
    image_free(&layers);
    return status;
}

/* render_options.checkpoint: writes the image so far to the partial file. */
static rt_status write_checkpoint(void *context, const rt_image *partial, const rt_image *adaptive_state,
                                  uint64_t samples, uint64_t scene_hash, rt_error *error)
{
    const job_image *image = context;
    render_result result = {.scene_hash = scene_hash, .adaptive_state = *adaptive_state};
    memcpy(result.region, image->plan.window, sizeof result.region);
    rt_status status = write_image(image, partial, image->plan.partial, samples, false, true, &result, error);
    const render_job_callbacks *callbacks = &image->run->callbacks;
    if (status == RT_OK && callbacks->checkpoint_written != NULL)
        callbacks->checkpoint_written(callbacks->user, &image->plan, samples);
    return status;
}

/* Copies channels [first, first + count) of image into a new image (*out; the caller
 * frees it). */
static rt_status copy_channels(const rt_image *image, int first, int count, rt_image *out, rt_error *error)
{
    rt_status status = image_create(out, image->width, image->height, count, error);
    if (status != RT_OK)
        return status;
    size_t pixels = (size_t)image->width * image->height;
    for (size_t i = 0; i < pixels; i++)
        for (int c = 0; c < count; c++)
            out->pixels[i * count + c] = image->pixels[i * image->channels + first + c];
    return RT_OK;
}

/* Denoises colour guided by the result's layers (render_denoise.h) and adds the noisy
 * colour to the AOVs as noisy.R/G/B, so an EXR keeps it. */
static rt_status denoise(rt_image *colour, render_result *result, rt_error *error)
{
    rt_image noisy = {0}, joined = {0};
    rt_status status = copy_channels(&result->image, 0, 3, &noisy, error);
    if (status == RT_OK)
        status = render_denoise(colour, &result->image, &result->aovs, error);
    if (status == RT_OK) {
        static const char *const names[3] = {"noisy.R", "noisy.G", "noisy.B"};
        for (int c = 0; c < 3; c++)
            snprintf(noisy.channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
        status = image_append_channels(&result->aovs, &noisy, &joined, error);
    }
    if (status == RT_OK) {
        image_free(&result->aovs);
        result->aovs = joined;
        joined = (rt_image){0};
    }
    image_free(&noisy);
    image_free(&joined);
    return status;
}

/* Applies denoise, blur and tone mapping (8-bit outputs only) to the result's colour, in
 * that order. */
static rt_status postprocess_result(const render_job *job, const char *output, render_result *result,
                                    rt_error *error)
{
    bool tonemap = image_format_of(output) == IMAGE_FORMAT_EIGHT_BIT && job->tonemap != TONEMAP_CLAMP;
    if (!job->denoise && job->blur_sigma <= 0 && !tonemap)
        return RT_OK;
    rt_image colour;
    rt_status status = copy_channels(&result->image, 0, 3, &colour, error);
    if (status == RT_OK && job->denoise)
        status = denoise(&colour, result, error);
    if (status == RT_OK && job->blur_sigma > 0)
        status = postprocess_gaussian_blur(&colour, job->blur_sigma, job->blur_passes > 0 ? job->blur_passes : 1,
                                           error);
    /* The writer's exposure would apply a second time after tone mapping: done here. */
    if (status == RT_OK && tonemap)
        status = postprocess_tonemap(&colour, job->tonemap, (float)job->exposure, error);
    if (status == RT_OK) {
        size_t pixels = (size_t)colour.width * colour.height;
        for (size_t i = 0; i < pixels; i++)
            for (int c = 0; c < 3; c++)
                result->image.pixels[4 * i + c] = colour.pixels[3 * i + c];
    }
    image_free(&colour);
    return status;
}

rt_status job_samples_map(const rt_image *rows, int samples_per_pixel, rt_image *map, rt_error *error)
{
    rt_image scale;
    rt_status status = image_create(&scale, rows->width, rows->height, 1, error);
    if (status != RT_OK)
        return status;
    double top = log1p((double)samples_per_pixel);
    for (size_t i = 0; i < (size_t)rows->width * rows->height; i++)
        scale.pixels[i] = (float)(log1p((double)rows->pixels[i * rows->channels + 3]) / top);
    status = image_color_map(&scale, 0, "inferno", map, error);
    image_free(&scale);
    return status;
}

/* Writes the heat map of image's samples channel (job_samples_map) to path. */
static rt_status write_samples_map(const char *path, const rt_image *image, int samples_per_pixel, rt_error *error)
{
    rt_image map;
    rt_status status = job_samples_map(image, samples_per_pixel, &map, error);
    if (status == RT_OK) {
        image_write_options options = image_write_options_defaults();
        status = image_write(path, &map, &options, error);
        image_free(&map);
    }
    return status;
}

/* Moves the result's light group layers (if any) after its AOVs, where the writer takes
 * the layers of an EXR from. */
static rt_status add_light_groups(render_result *result, rt_error *error)
{
    if (result->light_groups.pixels == NULL)
        return RT_OK;
    if (result->aovs.pixels == NULL) {
        result->aovs = result->light_groups;
        result->light_groups = (rt_image){0};
        return RT_OK;
    }
    rt_image joined = {0};
    rt_status status = image_append_channels(&result->aovs, &result->light_groups, &joined, error);
    if (status != RT_OK)
        return status;
    image_free(&result->aovs);
    image_free(&result->light_groups);
    result->aovs = joined;
    return RT_OK;
}

/* After the passes: writes the result, post-processed, to the output when the render
 * finished, else (render_status RT_ERROR_INTERRUPTED) as it is to the partial file, which
 * the message then names. */
static rt_status finish_image(job_image *image, render_result *result, rt_status render_status, rt_error *error)
{
    const render_job_image *plan = &image->plan;
    if (render_status == RT_ERROR_INTERRUPTED) {
        /* The partial goes next to the output, never over it: the user's last good image
         * stays, and --resume continues from the partial. Like a checkpoint it holds the
         * raw means and sample counts (and an adaptive render's state, render.h): --resume
         * adds samples to them, so denoised, blurred or tone-mapped colour there would be
         * processed twice. */
        rt_error write_error = {{0}};
        if (write_image(image, &result->image, plan->partial, result->samples, false, false, result, &write_error)
            != RT_OK)
            return rt_error_set(error, RT_ERROR_INTERRUPTED, "interrupted, and the partial could not be written: %s",
                                write_error.message);
        return rt_error_set(error, RT_ERROR_INTERRUPTED,
                            "interrupted: wrote the %llu samples finished so far to %s; continue with --resume %s",
                            (unsigned long long)result->samples, plan->partial, plan->partial);
    }
    rt_status status = postprocess_result(image->run->job, plan->output, result, error);
    if (status == RT_OK)
        status = add_light_groups(result, error);
    if (status != RT_OK)
        return status;
    status = write_image(image, &result->image, plan->output, result->samples,
                         result->stop_reason != RENDER_STOP_TIME, false, result, error);
    if (status != RT_OK)
        return status;
    if (image->run->job->samples_map != NULL)
        status = write_samples_map(image->run->job->samples_map, &result->image, plan->samples_per_pixel, error);
    if (status != RT_OK)
        return status;
    /* The checkpoint is ours and now superseded by the complete image. */
    unlink(plan->partial);
    const render_job_callbacks *callbacks = &image->run->callbacks;
    if (callbacks->image_written != NULL)
        callbacks->image_written(callbacks->user, plan, result);
    return RT_OK;
}

/* Fills *options for the image: the job's tracer settings with the image's samples and
 * region, the progress and stop of the run, and the checkpoint writer. */
static void image_render_options(job_image *image, render_options *options)
{
    const render_job *job = image->run->job;
    const render_job_callbacks *callbacks = &image->run->callbacks;
    *options = job->tracer;
    options->sample_start = image->plan.sample_start;
    memcpy(options->region, image->plan.region, sizeof options->region);
    options->aovs = job->aovs || job->denoise;
    options->light_groups = job->light_groups;
    options->variance = job->variance;
    /* With --aovs too, so that `rtspheres denoise` of its EXR is --denoise's image;
     * render_image drops it when resuming. */
    options->direct_emission = job->denoise || job->aovs;
    options->bvh_cache = image->run->bvh_cache;
    options->progress = callbacks->progress;
    options->progress_context = callbacks->user;
    options->stop_requested = job->stop_requested;
    options->deadline = job->time_limit_seconds > 0 ? image->start + job->time_limit_seconds : 0;
    options->resume = NULL;
    options->resume_scene_hash = 0;
    options->checkpoint_seconds = 0;
    options->checkpoint = NULL;
    options->checkpoint_context = NULL;
    if (job->checkpoint_seconds > 0) {
        options->checkpoint_seconds = job->checkpoint_seconds;
        options->checkpoint = write_checkpoint;
        options->checkpoint_context = image;
    }
}

/* Renders the scene of image (loaded and planned) and finishes it, continuing resume_image
 * (with its scene hash) when it has pixels, else job->resume_path when set. Frees
 * resume_image. */
static rt_status render_image(job_image *image, rt_image resume_image, uint64_t resume_scene_hash, rt_error *error)
{
    job_run *run = image->run;
    const render_job *job = run->job;
    render_options options;
    image_render_options(image, &options);
    /* Too large for the device or the budget: tiles (render_job_tiles.c). They keep no
     * partial file, so a partial --skip-existing found is not continued: the image
     * renders afresh (and the complete image supersedes the partial). */
    job_tile_grid grid;
    rt_status tiled = job_plan_tiles(image, &options, &grid, error);
    if (tiled != RT_OK || grid.count > 1) {
        image_free(&resume_image);
        return tiled != RT_OK ? tiled : job_render_tiles(image, &options, &grid, error);
    }
    if (resume_image.pixels != NULL) {
        options.resume = &resume_image;
        options.resume_scene_hash = resume_scene_hash;
    } else if (job->resume_path != NULL) {
        render_output_resume_check check = {.seed = image->scene.render.seed,
                                            .sample_start = image->plan.sample_start,
                                            .spp = image->scene.render.samples_per_pixel};
        memcpy(check.region, image->plan.window, sizeof check.region);
        rt_status status =
            render_output_read_partial(job->resume_path, &check, &resume_image, &options.resume_scene_hash, error);
        if (status != RT_OK)
            return status;
        options.resume = &resume_image;
    }
    /* A partial file keeps no direct emission sums: a resumed render is denoised without
     * them (postprocess.h). */
    if (options.resume != NULL)
        options.direct_emission = false;
    if (run->callbacks.render_started != NULL)
        run->callbacks.render_started(run->callbacks.user, &image->plan);
    render_result result;
    rt_status status = render_scene(run->context, &image->scene, &options, &result, error);
    if (status == RT_ERROR_RUNTIME)
        job_name_memory_budget(image, error);
    if (run->callbacks.render_finished != NULL)
        run->callbacks.render_finished(run->callbacks.user, &image->plan, status);
    if (status == RT_OK || status == RT_ERROR_INTERRUPTED) {
        status = finish_image(image, &result, status, error);
        image_free(&result.image);
        image_free(&result.aovs);
        image_free(&result.light_groups);
        image_free(&result.adaptive_state);
    }
    image_free(&resume_image);
    return status;
}

/* Renders one image of the job (frame -1: the job has no frames) to output. */
static rt_status run_image(job_run *run, int frame, const char *output, rt_error *error)
{
    const render_job *job = run->job;
    run->failure = RENDER_JOB_FAILURE_IMAGE;
    job_image *image = calloc(1, sizeof *image);
    if (image == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory");
    image->run = run;
    image->start = !run->image_begun && job->time_limit_start > 0 ? job->time_limit_start : clock_seconds();
    run->image_begun = true;
    rt_status status = load_scene(run, frame, &image->scene, error);
    if (status != RT_OK) {
        free(image);
        return status;
    }
    run->failure = RENDER_JOB_FAILURE_IMAGE;
    scene *s = &image->scene;
    /* Asset warnings (a missing MTL file, ...): once, with the first frame of the list. */
    bool first_frame = frame < 0 ? run->sweep_row <= 0 : frame == job->frames[0];
    for (int i = 0; i < s->warning_count && first_frame && run->callbacks.warning != NULL; i++)
        run->callbacks.warning(run->callbacks.user, s->warnings[i].message);
    render_job_apply_overrides(job, &s->render);
    image->plan.output = output;
    render_output_partial_path(output, image->plan.partial, sizeof image->plan.partial);
    status = render_job_plan_image(job, &run->plan, &s->render, frame, &image->plan, error);
    image->plan.sweep_row = run->sweep_row;
    render_job_existing existing = {0};
    rt_image resume = {0};
    uint64_t resume_scene_hash = 0;
    if (status == RT_OK) {
        s->render.samples_per_pixel = image->plan.samples_per_pixel;
        image->plan.options_hash = render_job_options_hash(job, &image->plan, &s->render);
        if (job->skip_existing)
            status = render_job_examine_existing(job, &image->plan, s, &existing, &resume, &resume_scene_hash, error);
    }
    if (status == RT_OK && existing.kind != RENDER_JOB_EXISTING_NONE && run->callbacks.existing_output != NULL)
        run->callbacks.existing_output(run->callbacks.user, &image->plan, &existing);
    if (status == RT_OK && existing.kind == RENDER_JOB_EXISTING_SKIP)
        run->images_skipped++;
    else if (status == RT_OK)
        status = render_image(image, resume, resume_scene_hash, error);
    if (status == RT_OK)
        run->failure = RENDER_JOB_FAILURE_NONE;
    scene_free(s);
    free(image);
    return status;
}

/* True when the caller asked the job to stop. */
static bool stop_requested(const render_job *job)
{
    return job->stop_requested != NULL && *job->stop_requested;
}

/* Renders the job's frames in order, those of its shard only; stops at the first failure
 * and at a stop request between frames. */
static rt_status run_frames(job_run *run, render_job_summary *summary, rt_error *error)
{
    const render_job *job = run->job;
    rt_status status = RT_OK;
    for (int i = 0; i < job->frame_count && status == RT_OK && !stop_requested(job); i++) {
        if (!render_job_includes_frame(job, &run->plan, i))
            continue;
        int frame = job->frames[i];
        char name[RENDER_JOB_PATH_MAX];
        run->failure = RENDER_JOB_FAILURE_IMAGE;
        status = render_job_output_name(job, &run->plan, frame, name, sizeof name, error);
        if (status != RT_OK)
            break;
        if (path_same_file(name, job->scene_path)) {
            status = rt_error_set(error, RT_ERROR_INPUT,
                                  "frame %d's output '%s' is the scene file; refusing to overwrite it", frame, name);
            break;
        }
        summary->images_started++;
        status = run_image(run, frame, name, error);
    }
    if (status == RT_OK && stop_requested(job)) {
        run->failure = RENDER_JOB_FAILURE_STOPPED;
        status = rt_error_set(error, RT_ERROR_INTERRUPTED, "interrupted between frames; every frame begun is written");
    }
    return status;
}

/* Renders the job's sweep rows (those of its shard) in order. */
static rt_status run_sweep(job_run *run, render_job_summary *summary, rt_error *error)
{
    const render_job *job = run->job;
    rt_status status = RT_OK;
    for (int row = 0; row < job->sweep->row_count && status == RT_OK && !stop_requested(job); row++) {
        if (!render_job_includes_frame(job, &run->plan, row))
            continue;
        char name[RENDER_JOB_PATH_MAX];
        run->failure = RENDER_JOB_FAILURE_IMAGE;
        status = sweep_output_name(job->output, job->sweep, row, name, sizeof name, error);
        if (status != RT_OK)
            break;
        summary->images_started++;
        run->sweep_row = row;
        status = run_image(run, -1, name, error);
    }
    run->sweep_row = -1;
    if (status == RT_OK && stop_requested(job)) {
        run->failure = RENDER_JOB_FAILURE_STOPPED;
        status = rt_error_set(error, RT_ERROR_INTERRUPTED, "interrupted between sweep rows; every row begun is written");
    }
    return status;
}

rt_status render_job_run(gpu_context *context, const render_job *job, const render_job_callbacks *callbacks,
                         render_job_summary *summary, rt_error *error)
{
    render_job_summary ignored;
    if (summary == NULL)
        summary = &ignored;
    memset(summary, 0, sizeof *summary);
    job_run run = {.context = context, .job = job, .sweep_row = -1};
    if (callbacks != NULL)
        run.callbacks = *callbacks;
    rt_status status = render_job_check(job, &run.plan, error);
    if (status != RT_OK) {
        summary->failure = RENDER_JOB_FAILURE_PLAN;
        return status;
    }
    /* Frames and sweep rows that move no shape keep every BVH (pack.h, the BVH cache). */
    int images = job->sweep != NULL ? job->sweep->row_count : job->frame_count;
    if (images > 1 && pack_bvh_cache_create(&run.bvh_cache, error) != RT_OK) {
        summary->failure = RENDER_JOB_FAILURE_IMAGE;
        return RT_ERROR_RUNTIME;
    }
    double start = clock_seconds();
    if (job->sweep != NULL) {
        status = run_sweep(&run, summary, error);
    } else if (job->frame_count == 0) {
        summary->images_started = 1;
        status = run_image(&run, -1, run.plan.first_output, error);
    } else {
        status = run_frames(&run, summary, error);
    }
    pack_bvh_cache_free(run.bvh_cache);
    summary->seconds = clock_seconds() - start;
    summary->images_skipped = run.images_skipped;
    summary->failure = status == RT_OK ? RENDER_JOB_FAILURE_NONE : run.failure;
    return status;
}
