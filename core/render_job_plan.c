/* render_job_plan.c: the planning half of render_job.h: the rules between a job's fields,
 * its output names, and each image's samples and region. No GPU; the only file-system
 * look-ups are render_job_check()'s checks of the first output. */
#include "render_job.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch.h"
#include "image_io.h"
#include "paths.h"
#include "scene_gltf.h"

render_job render_job_defaults(void)
{
    return (render_job){0};
}

const char *render_job_shard_kind_name(render_job_shard_kind kind)
{
    switch (kind) {
    case RENDER_SHARD_AUTO: return "auto";
    case RENDER_SHARD_FRAMES: return "frames";
    case RENDER_SHARD_SAMPLES: return "samples";
    case RENDER_SHARD_TILES: return "tiles";
    }
    return "auto";
}

/* True when the job names a crop (any of its numbers non-zero, as render.h's region). */
static bool has_crop(const render_job *job)
{
    return job->crop[0] || job->crop[1] || job->crop[2] || job->crop[3];
}

/* Returns the value of the job's last define of name, or NULL. */
static const char *last_define(const render_job *job, const char *name)
{
    const char *value = NULL;
    for (int i = 0; i < job->define_count; i++)
        if (strcmp(job->defines[i].name, name) == 0)
            value = job->defines[i].value;
    return value;
}

/* Finds the first output name into plan->first_output, checking what only frames or
 * their absence decide. */
static rt_status plan_first_output(const render_job *job, render_job_plan *plan, rt_error *error)
{
    const char *time_define = last_define(job, "time");
    if (job->frame_count > 0 && (plan->frame_define != NULL || time_define != NULL)) {
        const char *name = plan->frame_define != NULL ? "frame" : "time";
        return rt_error_set(error, RT_ERROR_INPUT,
                            "-D %s and --frames both set $%s (--frames sets $frame and $time); give one", name, name);
    }
    int first_frame = job->frame_count > 0 ? job->frames[0] : -1;
    rt_status status =
        job->sweep != NULL
            ? sweep_output_name(job->output, job->sweep, 0, plan->first_output, sizeof plan->first_output, error)
            : render_job_output_name(job, plan, first_frame, plan->first_output, sizeof plan->first_output, error);
    if (status != RT_OK)
        return status;
    if (job->frame_count > 1 && !output_pattern_has_frame(job->output))
        return rt_error_set(error, RT_ERROR_INPUT,
                            "%d frames would all write '%s'; put a frame number pattern in the output, e.g. "
                            "frame-%%04d.png", job->frame_count, job->output);
    return RT_OK;
}

/* Checks the first output name: a format image_write() knows, a directory to write in,
 * and not the scene file. */
static rt_status check_first_output(const render_job *job, const char *output, rt_error *error)
{
    if (image_format_of(output) == IMAGE_FORMAT_UNKNOWN)
        return rt_error_set(error, RT_ERROR_INPUT, "cannot tell the format of '%s'; use .exr, .hdr, .png, .jpg or .tif",
                            output);
    if (!path_directory_writable(output))
        return rt_error_set(error, RT_ERROR_INPUT,
                            "cannot write '%s': its directory does not exist or is not writable", output);
    if (path_same_file(output, job->scene_path))
        return rt_error_set(error, RT_ERROR_INPUT, "the output '%s' is the scene file; refusing to overwrite it",
                            output);
    return RT_OK;
}

/* Checks --light-groups against the output and the other options: its layers need an
 * EXR; they must sum to the beauty, which denoise and blur change; a partial file keeps no
 * layers (no resume). Tiles, crops, sample ranges and shards are fine: merge carries the
 * layers (merge.h). */
static rt_status check_light_groups(const render_job *job, const char *output, rt_error *error)
{
    if (!job->light_groups)
        return RT_OK;
    if (image_format_of(output) != IMAGE_FORMAT_EXR)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--light-groups writes a layer per light group, which only .exr keeps; not '%s' "
                            "(rtspheres relight makes other formats from the EXR)", output);
    if (job->denoise || job->blur_sigma > 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--light-groups with --%s: the layers would no longer sum to the image; relight, "
                            "then post-process", job->denoise ? "denoise" : "blur");
    /* The layers gather light as each path goes, so when a render stops they also hold
     * parts of the paths in flight, which a resumed render traces again: carried in a
     * partial file they would count those twice. */
    if (job->resume_path != NULL)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--light-groups cannot --resume: a partial file keeps no layers (at a stop they hold "
                            "parts of the paths in flight, which the resumed render traces again); render the "
                            "rest as a sample range (--samples) and merge the parts");
    return RT_OK;
}

/* Checks a sweep against the job: no frames, no resume, no define of a column, and every
 * row's output its own file that is not the scene (the table's file:line of the row). */
static rt_status check_sweep(const render_job *job, rt_error *error)
{
    const sweep_table *table = job->sweep;
    if (table == NULL)
        return RT_OK;
    if (job->frame_count > 0)
        return rt_error_set(error, RT_ERROR_INPUT, "--sweep and --frames both make a list of images; give one");
    if (job->resume_path != NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "--resume continues one image, not a sweep's rows");
    for (int c = 0; c < table->column_count; c++)
        if (last_define(job, table->names[c]) != NULL)
            return rt_error_set(error, RT_ERROR_INPUT, "%s:%d: column '%s' and -D %s both set $%s; give one",
                                table->path, table->header_line, table->names[c], table->names[c], table->names[c]);
    char(*names)[RENDER_JOB_PATH_MAX] = malloc((size_t)table->row_count * sizeof *names);
    if (names == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory for the sweep's output names");
    rt_status status = RT_OK;
    for (int r = 0; r < table->row_count && status == RT_OK; r++) {
        status = sweep_output_name(job->output, table, r, names[r], sizeof names[r], error);
        if (status == RT_OK && path_same_file(names[r], job->scene_path))
            status = rt_error_set(error, RT_ERROR_INPUT, "%s:%d: this row's output '%s' is the scene file",
                                  table->path, table->lines[r], names[r]);
        for (int k = 0; k < r && status == RT_OK; k++)
            if (strcmp(names[k], names[r]) == 0)
                status = rt_error_set(error, RT_ERROR_INPUT,
                                      "%s:%d: this row writes '%s', as the row of line %d does; put {NAME} or "
                                      "%%d in the output pattern", table->path, table->lines[r], names[r],
                                      table->lines[k]);
    }
    free(names);
    return status;
}

/* Resolves the shard (its kind, and for tiles the band) into plan and checks it against
 * the other ways of choosing frames, samples and region. */
static rt_status plan_shard(const render_job *job, render_job_plan *plan, rt_error *error)
{
    if (job->shard_by != RENDER_SHARD_AUTO && job->shard_count == 0)
        return rt_error_set(error, RT_ERROR_INPUT, "--shard-by %s does nothing without --shard I/N",
                            render_job_shard_kind_name(job->shard_by));
    if (job->shard_count == 0)
        return RT_OK;
    render_job_shard_kind by = job->shard_by;
    /* A sweep's rows shard as frames do. */
    int images = job->sweep != NULL ? job->sweep->row_count : job->frame_count;
    const char *unit = job->sweep != NULL ? "sweep row" : "frame";
    if (by == RENDER_SHARD_AUTO)
        by = images > 1 ? RENDER_SHARD_FRAMES : RENDER_SHARD_SAMPLES;
    plan->shard_by = by;
    if (by == RENDER_SHARD_FRAMES && images == 0)
        return rt_error_set(error, RT_ERROR_INPUT, "--shard-by frames needs --frames");
    /* As with an empty sample shard or tile: a part with nothing to render is an error,
     * not a silent success that writes nothing. */
    if (by == RENDER_SHARD_FRAMES && job->shard_index >= images)
        return rt_error_set(error, RT_ERROR_INPUT, "shard %d/%d of %d %s%s is empty; use fewer shards",
                            job->shard_index, job->shard_count, images, unit, images == 1 ? "" : "s");
    if (by == RENDER_SHARD_SAMPLES && job->sample_count > 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--shard by samples and --samples both choose the samples; give one");
    if (by == RENDER_SHARD_TILES && (has_crop(job) || job->tile_count))
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--shard by tiles and --crop/--tile both choose the region; give one");
    if (by == RENDER_SHARD_TILES) {
        plan->tile_index = job->shard_index;
        plan->tile_count = job->shard_count;
    }
    return RT_OK;
}

rt_status render_job_check(const render_job *job, render_job_plan *plan, rt_error *error)
{
    memset(plan, 0, sizeof *plan);
    plan->frame_define = last_define(job, "frame");
    plan->tile_index = job->tile_index;
    plan->tile_count = job->tile_count;
    if (job->scene_path == NULL || job->output == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "a render job needs a scene file and an output name");
    rt_status status = plan_first_output(job, plan, error);
    if (status == RT_OK)
        status = check_first_output(job, plan->first_output, error);
    if (status != RT_OK)
        return status;
    if (has_crop(job) && job->tile_count)
        return rt_error_set(error, RT_ERROR_INPUT, "--crop and --tile both choose the region; give one");
    if (job->aovs && image_format_of(plan->first_output) != IMAGE_FORMAT_EXR)
        return rt_error_set(error, RT_ERROR_INPUT, "--aovs writes extra layers, which only .exr keeps; not '%s'",
                            plan->first_output);
    bool gltf_scene = scene_gltf_is_model_path(job->scene_path);
    if (job->camera != NULL && !gltf_scene)
        return rt_error_set(error, RT_ERROR_INPUT, "--camera picks a camera of a glTF file (.gltf, .glb); '%s' is a "
                            "scene file, whose camera statement sets the camera", job->scene_path);
    for (int i = 0; gltf_scene && i < job->define_count; i++)
        if (!job->defines[i].optional)
            return rt_error_set(error, RT_ERROR_INPUT, "-D %s: a glTF scene ('%s') has no variables",
                                job->defines[i].name, job->scene_path);
    if (job->variance && image_format_of(plan->first_output) != IMAGE_FORMAT_EXR)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--variance writes extra layers, which only .exr keeps; not '%s'", plan->first_output);
    if (job->variance && job->resume_path != NULL)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--variance needs the squares of every sample, which a partial file does not keep; "
                            "render without --resume");
    if (job->skip_existing && job->resume_path != NULL)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--skip-existing finds and resumes each image's partial file itself; not with --resume");
    if (job->resume_path != NULL && job->frame_count > 1)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--resume continues one image; render the frames one at a time");
    if (job->samples_map != NULL && job->frame_count > 1)
        return rt_error_set(error, RT_ERROR_INPUT, "--samples-map writes one image; not with several frames");
    if (job->samples_map != NULL && image_format_of(job->samples_map) == IMAGE_FORMAT_UNKNOWN)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "cannot tell the format of --samples-map '%s'; use .png, .exr, .hdr, .jpg or .tif",
                            job->samples_map);
    status = check_light_groups(job, plan->first_output, error);
    if (status == RT_OK)
        status = check_sweep(job, error);
    if (status != RT_OK)
        return status;
    status = plan_shard(job, plan, error);
    if (status == RT_OK && job->tracer.min_spp && !(job->tracer.noise_threshold > 0))
        return rt_error_set(error, RT_ERROR_INPUT, "--min-spp does nothing without --noise-threshold");
    if (status != RT_OK || !(job->tracer.noise_threshold > 0))
        return status;
    /* Each part would stop its pixels on its own samples, so parts would not add up. */
    if (job->shard_count && plan->shard_by == RENDER_SHARD_SAMPLES)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--noise-threshold cannot be combined with --shard-by samples: each part would stop "
                            "its pixels on its own samples; shard by tiles or frames");
    if (job->sample_count > 0 || job->sample_start > 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--noise-threshold cannot be combined with --samples: each part would stop its "
                            "pixels on its own samples; render all samples, or split by --tile or --crop");
    /* A region's decisions reach past it (core/render.c), and a partial keeps only the region. */
    if (job->resume_path != NULL && (has_crop(job) || job->tile_count || (job->shard_count && plan->shard_by == RENDER_SHARD_TILES)))
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--noise-threshold cannot --resume part of an image (--crop, --tile, --shard-by tiles): "
                            "its pixels' decisions depend on pixels past the part, which the partial file does not "
                            "hold; render the part afresh");
    return RT_OK;
}

bool render_job_includes_frame(const render_job *job, const render_job_plan *plan, int index)
{
    return !(job->shard_count && plan->shard_by == RENDER_SHARD_FRAMES && index % job->shard_count != job->shard_index);
}

rt_status render_job_output_name(const render_job *job, const render_job_plan *plan, int frame, char *name,
                                 size_t size, rt_error *error)
{
    if (frame >= 0)
        return output_pattern_format(job->output, frame, name, size, error);
    return output_name_without_frames(job->output, plan->frame_define, name, size, error);
}

int render_job_scene_defines(const render_job *job, int frame, scene_define *defines,
                             render_job_frame_values *values)
{
    int count = job->define_count;
    if (count > 0)
        memcpy(defines, job->defines, (size_t)count * sizeof defines[0]);
    if (frame >= 0) {
        double fps = job->frames_per_second > 0 ? job->frames_per_second : RENDER_JOB_DEFAULT_FRAMES_PER_SECOND;
        snprintf(values->frame, sizeof values->frame, "%d", frame);
        snprintf(values->time, sizeof values->time, "%.17g", frame / fps);
        defines[count++] = (scene_define){.name = "frame", .value = values->frame, .optional = true};
        defines[count++] = (scene_define){.name = "time", .value = values->time, .optional = true};
    }
    return count;
}

void render_job_apply_overrides(const render_job *job, scene_render_settings *settings)
{
    if (job->samples_per_pixel)
        settings->samples_per_pixel = job->samples_per_pixel;
    if (job->width)
        settings->width = job->width;
    if (job->height)
        settings->height = job->height;
    if (job->max_depth)
        settings->max_depth = job->max_depth;
    if (job->seed_set)
        settings->seed = job->seed;
}

rt_status render_job_plan_image(const render_job *job, const render_job_plan *plan,
                                const scene_render_settings *settings, int frame, render_job_image *image,
                                rt_error *error)
{
    image->frame = frame;
    long long start = 0, count = settings->samples_per_pixel;
    if (job->sample_count > 0) {
        start = job->sample_start;
        count = job->sample_count;
    } else if (job->shard_count && plan->shard_by == RENDER_SHARD_SAMPLES) {
        shard_range(job->shard_index, job->shard_count, settings->samples_per_pixel, &start, &count);
        if (count == 0)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "shard %d/%d of %d samples per pixel is empty; use fewer shards", job->shard_index,
                                job->shard_count, settings->samples_per_pixel);
    }
    image->sample_start = (uint32_t)start;
    image->samples_per_pixel = (int)count;

    memset(image->region, 0, sizeof image->region);
    if (has_crop(job)) {
        memcpy(image->region, job->crop, sizeof image->region);
    } else if (plan->tile_count) {
        long long row, rows;
        shard_range(plan->tile_index, plan->tile_count, settings->height, &row, &rows);
        if (rows == 0)
            return rt_error_set(error, RT_ERROR_INPUT, "tile %d/%d of a %d-row image is empty; use fewer tiles",
                                plan->tile_index, plan->tile_count, settings->height);
        int band[4] = {0, (int)row, settings->width, (int)(row + rows)};
        memcpy(image->region, band, sizeof band);
    }
    int whole[4] = {0, 0, settings->width, settings->height};
    memcpy(image->window, has_crop(job) || plan->tile_count ? image->region : whole, sizeof image->window);
    return RT_OK;
}
