/* render_output.c: see render_output.h. */
#include "render_output.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metadata_keys.h"
#include "paths.h"
#include "version.h"

/* Makes the image to write into *made (allocated only when the format needs another
 * layout; the caller frees it) and returns it: for an EXR the four channels plus layers,
 * for other formats R, G, B. It keeps image's place in the full image. */
static const rt_image *image_for_format(const char *path, const rt_image *image, const rt_image *layers,
                                        rt_image *made, rt_status *status, rt_error *error)
{
    *status = RT_OK;
    *made = (rt_image){0};
    bool exr = image_format_of(path) == IMAGE_FORMAT_EXR;
    if (exr && (layers == NULL || layers->pixels == NULL))
        return image;
    if (exr) {
        *status = image_append_channels(image, layers, made, error);
    } else {
        *status = image_create(made, image->width, image->height, 3, error);
        size_t pixel_count = (size_t)image->width * image->height;
        for (size_t i = 0; i < pixel_count && *status == RT_OK; i++)
            for (int c = 0; c < 3; c++)
                made->pixels[3 * i + c] = image->pixels[(size_t)image->channels * i + c];
    }
    made->x = image->x;
    made->y = image->y;
    made->full_width = image->full_width;
    made->full_height = image->full_height;
    return made;
}

rt_status render_output_write(const char *path, const rt_image *image, const rt_image *layers,
                              const render_output_metadata *metadata, float exposure, rt_error *error)
{
    rt_image made;
    rt_status status;
    const rt_image *written = image_for_format(path, image, layers, &made, &status, error);
    if (status != RT_OK) {
        image_free(&made);
        return status;
    }
    /* Counters that may pass 2^31 would not fit an EXR int attribute: they go as text. */
    char seed_text[24], sample_start_text[24], samples_text[24], segments_text[32];
    snprintf(seed_text, sizeof seed_text, "%llu", metadata->seed);
    snprintf(sample_start_text, sizeof sample_start_text, "%llu", metadata->sample_start);
    snprintf(samples_text, sizeof samples_text, "%llu", metadata->samples_finished);
    snprintf(segments_text, sizeof segments_text, "%.0f", metadata->path_segments);
    image_attribute attributes[] = {
        {.name = METADATA_KEY_VERSION, .type = IMAGE_ATTRIBUTE_STRING, .string_value = RTSPHERES_VERSION},
        {.name = METADATA_KEY_SCENE, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->scene},
        {.name = METADATA_KEY_SCENE_HASH, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->scene_hash},
        {.name = METADATA_KEY_SPP, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->spp},
        {.name = METADATA_KEY_SAMPLE_START, .type = IMAGE_ATTRIBUTE_STRING, .string_value = sample_start_text},
        {.name = METADATA_KEY_SEED, .type = IMAGE_ATTRIBUTE_STRING, .string_value = seed_text},
        {.name = METADATA_KEY_MAX_DEPTH, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->max_depth},
        {.name = METADATA_KEY_FRAME, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->frame},
        {.name = METADATA_KEY_SAMPLES_FINISHED, .type = IMAGE_ATTRIBUTE_STRING, .string_value = samples_text},
        {.name = METADATA_KEY_PATH_SEGMENTS, .type = IMAGE_ATTRIBUTE_STRING, .string_value = segments_text},
        {.name = METADATA_KEY_COMPLETE, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->complete},
        {.name = METADATA_KEY_RENDER_SECONDS, .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = metadata->render_seconds},
        {0}, {0}, {0}, {0}, {0}, {0},   /* the optional keys, added below when they apply */
    };
    int count = (int)(sizeof attributes / sizeof attributes[0]) - 6;
    if (metadata->options_hash != NULL)
        attributes[count++] = (image_attribute){.name = METADATA_KEY_OPTIONS_HASH, .type = IMAGE_ATTRIBUTE_STRING,
                                                .string_value = metadata->options_hash};
    if (metadata->stop_reason != NULL) {   /* a render's keys (not a merge's) */
        attributes[count++] = (image_attribute){.name = METADATA_KEY_STOP_REASON, .type = IMAGE_ATTRIBUTE_STRING,
                                                .string_value = metadata->stop_reason};
        attributes[count++] = (image_attribute){.name = METADATA_KEY_NOISE_THRESHOLD, .type = IMAGE_ATTRIBUTE_FLOAT,
                                                .float_value = metadata->noise_threshold};
        attributes[count++] = (image_attribute){.name = METADATA_KEY_MIN_SPP, .type = IMAGE_ATTRIBUTE_INT,
                                                .int_value = metadata->min_spp};
    }
    if (metadata->merged_parts > 0)
        attributes[count++] = (image_attribute){.name = METADATA_KEY_MERGED_PARTS, .type = IMAGE_ATTRIBUTE_INT,
                                                .int_value = metadata->merged_parts};
    if (metadata->light_groups != NULL)
        attributes[count++] = (image_attribute){.name = METADATA_KEY_LIGHT_GROUPS, .type = IMAGE_ATTRIBUTE_STRING,
                                                .string_value = metadata->light_groups};
    image_write_options options = image_write_options_defaults();
    options.exposure = exposure;
    options.attributes = attributes;
    options.attribute_count = count;
    status = image_write(path, written, &options, error);
    image_free(&made);
    return status;
}

void render_output_partial_path(const char *output, char *path, size_t size)
{
    const char *extension = path_extension(output);
    snprintf(path, size, "%.*s.partial.exr", (int)(strlen(output) - strlen(extension)), output);
}

/* The rtspheres metadata of a partial file that resuming checks, as text ("" when absent). */
typedef struct partial_metadata {
    char seed[32], sample_start[32], spp[32], scene_hash[32];
} partial_metadata;

/* Returns how the partial file (its pixels image, its metadata) differs from expected, or
 * NULL when it belongs to this render; a formatted answer goes into text (64 bytes, the
 * length the render command always gave it). */
static const char *describe_mismatch(const rt_image *image, const partial_metadata *metadata,
                                     const render_output_resume_check *expected, char text[64])
{
    const int *region = expected->region;
    if (metadata->scene_hash[0] == '\0')
        return "it has no rtspheres metadata (was it written by rtspheres render to .exr?)";
    if (strtoull(metadata->seed, NULL, 10) != expected->seed) {
        snprintf(text, 64, "seed %s, this render %u", metadata->seed, expected->seed);
        return text;
    }
    if (strtoll(metadata->sample_start, NULL, 10) != expected->sample_start) {
        snprintf(text, 64, "first sample %s, this render %lld", metadata->sample_start, expected->sample_start);
        return text;
    }
    if (strtoll(metadata->spp, NULL, 10) != expected->spp) {
        snprintf(text, 64, "%s spp, this render %d", metadata->spp, expected->spp);
        return text;
    }
    if (image->x != region[0] || image->y != region[1] || image->width != region[2] - region[0]
        || image->height != region[3] - region[1])
        return "it covers another region of the image (size or crop differ)";
    return NULL;
}

rt_status render_output_read_partial(const char *path, const render_output_resume_check *expected, rt_image *image,
                                     uint64_t *scene_hash, rt_error *error)
{
    rt_error read_error = {{0}};
    if (image_read(path, image, &read_error) != RT_OK)
        return rt_error_set(error, RT_ERROR_INPUT, "--resume: %s", read_error.message);
    partial_metadata metadata;
    memset(&metadata, 0, sizeof metadata);
    image_read_attribute(path, METADATA_KEY_SEED, metadata.seed, sizeof metadata.seed, NULL);
    image_read_attribute(path, METADATA_KEY_SAMPLE_START, metadata.sample_start, sizeof metadata.sample_start, NULL);
    image_read_attribute(path, METADATA_KEY_SPP, metadata.spp, sizeof metadata.spp, NULL);
    image_read_attribute(path, METADATA_KEY_SCENE_HASH, metadata.scene_hash, sizeof metadata.scene_hash, NULL);
    char text[64];
    const char *problem = describe_mismatch(image, &metadata, expected, text);
    if (problem != NULL) {
        image_free(image);
        return rt_error_set(error, RT_ERROR_INPUT, "--resume %s does not belong to this render: %s", path, problem);
    }
    *scene_hash = strtoull(metadata.scene_hash, NULL, 16);
    return RT_OK;
}
