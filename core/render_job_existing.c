/* render_job_existing.c: --skip-existing's half of render_job.h ("Existing outputs"): the
 * options hash, and what an image's output and partial file already hold. Reads files'
 * metadata only; renders nothing and writes nothing. */
#include "render_job.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hash.h"
#include "image_io.h"
#include "metadata_keys.h"
#include "render_output.h"

/* Bumped when the hash covers other fields, so older files never match by accident. */
#define OPTIONS_HASH_VERSION 1

uint64_t render_job_options_hash(const render_job *job, const render_job_image *image,
                                 const scene_render_settings *settings)
{
    const render_options *tracer = &job->tracer;
    bool adaptive = tracer->noise_threshold > 0;
    /* Whole numbers and floats in fixed-size fields, so the hash is of values, not of a
     * struct's padding. */
    int64_t numbers[] = {
        OPTIONS_HASH_VERSION,
        settings->width, settings->height, settings->max_depth, settings->seed,
        image->sample_start, image->samples_per_pixel,
        image->window[0], image->window[1], image->window[2], image->window[3],
        tracer->integrator, tracer->sampler, tracer->no_light_sampling, tracer->russian_roulette_depth,
        adaptive ? tracer->min_spp : 0,
        job->aovs, job->light_groups, job->variance, job->denoise,
        job->blur_sigma > 0 ? (job->blur_passes > 0 ? job->blur_passes : 1) : 0,
        job->tonemap,
    };
    double reals[] = {adaptive ? tracer->noise_threshold : 0.0, job->blur_sigma > 0 ? job->blur_sigma : 0.0,
                      job->exposure};
    uint64_t hash = hash_bytes(HASH_START, numbers, sizeof numbers);
    hash = hash_bytes(hash, reals, sizeof reals);
    /* Only when set, so that every other render keeps the hash it had before the option. */
    if (tracer->no_light_tree)
        hash = hash_bytes(hash, "no light tree", 13);
    return hash;
}

/* The metadata of a file that decides what to do with it ("" where a key is missing). */
typedef struct file_metadata {
    char scene_hash[32], options_hash[32], complete[16], stop_reason[32], spp[32], seed[32], samples[32];
} file_metadata;

/* Reads path's metadata into *metadata. Returns false when it has no rtspheres scene
 * hash (not an image, or not one rtspheres rendered). */
static bool read_metadata(const char *path, file_metadata *metadata)
{
    memset(metadata, 0, sizeof *metadata);
    struct {
        const char *key;
        char *value;
        int size;
    } keys[] = {
        {METADATA_KEY_SCENE_HASH, metadata->scene_hash, sizeof metadata->scene_hash},
        {METADATA_KEY_OPTIONS_HASH, metadata->options_hash, sizeof metadata->options_hash},
        {METADATA_KEY_COMPLETE, metadata->complete, sizeof metadata->complete},
        {METADATA_KEY_STOP_REASON, metadata->stop_reason, sizeof metadata->stop_reason},
        {METADATA_KEY_SPP, metadata->spp, sizeof metadata->spp},
        {METADATA_KEY_SEED, metadata->seed, sizeof metadata->seed},
        {METADATA_KEY_SAMPLES_FINISHED, metadata->samples, sizeof metadata->samples},
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (image_read_attribute(path, keys[i].key, keys[i].value, keys[i].size, NULL) != RT_OK)
            keys[i].value[0] = '\0';
    return metadata->scene_hash[0] != '\0';
}

/* The hashes a file is compared with; the scene hash is computed on first need. */
typedef struct expected_hashes {
    const render_job *job;
    const scene *s;
    bool scene_known;
    uint64_t scene;
    uint64_t options;
} expected_hashes;

/* Says in text (size bytes) how the file at path (with metadata) differs from this
 * image's scene and options, or leaves text empty when it does not. */
static rt_status describe_difference(const char *path, const file_metadata *metadata, expected_hashes *expected,
                                     const render_job_image *image, char *text, size_t size, rt_error *error)
{
    text[0] = '\0';
    if (!expected->scene_known) {
        rt_status status = render_scene_hash(expected->s, &expected->job->tracer, &expected->scene, error);
        if (status != RT_OK)
            return status;
        expected->scene_known = true;
    }
    char scene[24], options[24];
    snprintf(scene, sizeof scene, "%016llx", (unsigned long long)expected->scene);
    snprintf(options, sizeof options, "%016llx", (unsigned long long)expected->options);
    if (strcmp(metadata->scene_hash, scene) != 0) {
        snprintf(text, size, "%s was rendered from another scene, camera, size or depth (scene hash %s, this "
                 "render %s)", path, metadata->scene_hash, scene);
    } else if (strcmp(metadata->options_hash, options) != 0) {
        /* Name the options a user most often changes when they are the difference. */
        char detail[96] = "";
        if (metadata->spp[0] != '\0' && strtoll(metadata->spp, NULL, 10) != image->samples_per_pixel)
            snprintf(detail, sizeof detail, ": %s spp, this render %d", metadata->spp, image->samples_per_pixel);
        else if (strtoull(metadata->seed, NULL, 10) != expected->s->render.seed)
            snprintf(detail, sizeof detail, ": seed %s, this render %u", metadata->seed, expected->s->render.seed);
        snprintf(text, size, "%s was rendered with other options%s (options hash %s, this render %s)", path,
                 detail[0] != '\0' ? detail : metadata->options_hash[0] == '\0' ? " (it has no options hash)" : "",
                 metadata->options_hash[0] != '\0' ? metadata->options_hash : "none", options);
    }
    return RT_OK;
}

/* Reads the file at path to resume it (render_output_read_partial()'s checks of seed,
 * samples and region). Returns true with *resume filled, or false with why in text. */
static bool load_for_resume(const char *path, const render_job_image *image, const scene *s, rt_image *resume,
                            uint64_t *resume_scene_hash, char *text, size_t size)
{
    render_output_resume_check check = {.seed = s->render.seed,
                                        .sample_start = image->sample_start,
                                        .spp = image->samples_per_pixel};
    memcpy(check.region, image->window, sizeof check.region);
    rt_error read_error = {{0}};
    if (render_output_read_partial(path, &check, resume, resume_scene_hash, &read_error) == RT_OK)
        return true;
    snprintf(text, size, "%.*s", (int)size - 1, read_error.message);
    return false;
}

/* Why this job cannot resume any file of image (NULL: it can): the options
 * render_job_check() and render_scene() refuse with a resume. */
static const char *resume_refused(const render_job *job, const render_job_image *image, const scene *s)
{
    const int *w = image->window;
    bool whole = w[0] == 0 && w[1] == 0 && w[2] == s->render.width && w[3] == s->render.height;
    if (job->tracer.noise_threshold > 0 && !whole)
        return "--noise-threshold over part of the image cannot resume (its decisions reach past the part)";
    if (job->variance)
        return "--variance cannot resume (a partial keeps no squares)";
    if (job->light_groups)
        return "--light-groups cannot resume (a partial keeps no layers)";
    return NULL;
}

rt_status render_job_examine_existing(const render_job *job, const render_job_image *image, const scene *s,
                                      render_job_existing *decision, rt_image *resume, uint64_t *resume_scene_hash,
                                      rt_error *error)
{
    memset(decision, 0, sizeof *decision);
    *resume = (rt_image){0};
    *resume_scene_hash = 0;
    expected_hashes expected = {.job = job, .s = s, .options = image->options_hash};
    bool output_there = access(image->output, F_OK) == 0, partial_there = access(image->partial, F_OK) == 0;
    if (!output_there && !partial_there)
        return RT_OK;
    char output_state[700] = "", text[700];
    file_metadata metadata, output_metadata;
    memset(&output_metadata, 0, sizeof output_metadata);
    bool incomplete_output = false;
    /* 1. The output: complete and the same: skip it. */
    if (output_there) {
        if (!read_metadata(image->output, &metadata)) {
            snprintf(output_state, sizeof output_state, "%s has no rtspheres metadata (not a render of rtspheres?)",
                     image->output);
        } else {
            rt_status status =
                describe_difference(image->output, &metadata, &expected, image, output_state, sizeof output_state,
                                    error);
            if (status != RT_OK)
                return status;
            /* 8-bit formats and HDR keep only the string keys (OpenImageIO writes text chunks
             * of strings): there the stop reason tells, since only a render that ended by its
             * own rule (spp, noise) writes its output with one of those. */
            bool complete = strcmp(metadata.complete, "1") == 0
                            || (metadata.complete[0] == '\0'
                                && (strcmp(metadata.stop_reason, "spp") == 0
                                    || strcmp(metadata.stop_reason, "noise") == 0));
            if (output_state[0] == '\0' && complete) {
                decision->kind = RENDER_JOB_EXISTING_SKIP;
                snprintf(decision->reason, sizeof decision->reason,
                         "%s is complete (%s samples, stopped by %s) and was rendered from the same scene and "
                         "options", image->output, metadata.samples, metadata.stop_reason);
                return RT_OK;
            }
            if (output_state[0] == '\0') {
                incomplete_output = true;
                output_metadata = metadata;
                snprintf(output_state, sizeof output_state, "%s is incomplete (%s samples, stopped by %s)",
                         image->output, metadata.samples, metadata.stop_reason[0] ? metadata.stop_reason : "?");
            }
        }
    }
    /* 2. The partial file, then an incomplete raw output: resume one of them. */
    const char *refused = resume_refused(job, image, s);
    const char *candidates[2] = {partial_there ? image->partial : NULL, NULL};
    if (incomplete_output && image_format_of(image->output) == IMAGE_FORMAT_EXR && !job->denoise
        && !(job->blur_sigma > 0))
        candidates[1] = image->output;
    char partial_state[700] = "";
    for (int i = 0; i < 2; i++) {
        const char *path = candidates[i];
        if (path == NULL)
            continue;
        if (i == 0 && !read_metadata(path, &metadata)) {
            snprintf(partial_state, sizeof partial_state, "%s has no rtspheres metadata", path);
            continue;
        }
        if (i == 0) {
            rt_status status =
                describe_difference(path, &metadata, &expected, image, partial_state, sizeof partial_state, error);
            if (status != RT_OK)
                return status;
            if (partial_state[0] != '\0')
                continue;
        }
        if (refused != NULL && i == 0) {
            snprintf(partial_state, sizeof partial_state, "%s is of this scene and options, but %s", path, refused);
            continue;
        }
        if (refused != NULL) {
            size_t used = strlen(output_state);
            snprintf(output_state + used, sizeof output_state - used, ", but %s", refused);
            continue;
        }
        if (!load_for_resume(path, image, s, resume, resume_scene_hash, text, sizeof text)) {
            snprintf(i == 0 ? partial_state : output_state, sizeof partial_state, "%s", text);
            continue;
        }
        if (job->tracer.noise_threshold > 0 && !render_partial_has_adaptive_state(resume)) {
            image_free(resume);
            *resume_scene_hash = 0;
            snprintf(i == 0 ? partial_state : output_state, sizeof partial_state,
                     "%s has no adaptive state to resume with --noise-threshold (written by an older rtspheres)",
                     path);
            continue;
        }
        decision->kind = RENDER_JOB_EXISTING_RESUME;
        snprintf(decision->resume_path, sizeof decision->resume_path, "%s", path);
        if (i == 1)
            snprintf(decision->reason, sizeof decision->reason, "%s; continuing it", output_state);
        else
            snprintf(decision->reason, sizeof decision->reason, "%s%s%s holds %s samples of this scene and options",
                     output_state, output_state[0] != '\0' ? "; " : "", path, metadata.samples);
        return RT_OK;
    }
    /* 3. Nothing to keep: say what was there. */
    decision->kind = RENDER_JOB_EXISTING_RENDER;
    snprintf(decision->reason, sizeof decision->reason, "%s%s%s", output_state,
             output_state[0] != '\0' && partial_state[0] != '\0' ? "; " : "", partial_state);
    return RT_OK;
}
