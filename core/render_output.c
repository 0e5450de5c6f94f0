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

/* The image attributes of metadata (metadata_keys.h), with the texts they point into. */
typedef struct output_attributes {
    image_attribute list[METADATA_KEY_COUNT];
    int count;
    char seed[24], sample_start[24], samples[24], segments[32];
} output_attributes;

/* Fills *attributes from metadata (which must outlive them). */
static void make_attributes(const render_output_metadata *metadata, output_attributes *attributes)
{
    /* Counters that may pass 2^31 would not fit an EXR int attribute: they go as text. */
    snprintf(attributes->seed, sizeof attributes->seed, "%llu", metadata->seed);
    snprintf(attributes->sample_start, sizeof attributes->sample_start, "%llu", metadata->sample_start);
    snprintf(attributes->samples, sizeof attributes->samples, "%llu", metadata->samples_finished);
    snprintf(attributes->segments, sizeof attributes->segments, "%.0f", metadata->path_segments);
    const image_attribute always[] = {
        {.name = METADATA_KEY_VERSION, .type = IMAGE_ATTRIBUTE_STRING, .string_value = RTSPHERES_VERSION},
        {.name = METADATA_KEY_SCENE, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->scene},
        {.name = METADATA_KEY_SCENE_HASH, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->scene_hash},
        {.name = METADATA_KEY_SPP, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->spp},
        {.name = METADATA_KEY_SAMPLE_START, .type = IMAGE_ATTRIBUTE_STRING, .string_value = attributes->sample_start},
        {.name = METADATA_KEY_SEED, .type = IMAGE_ATTRIBUTE_STRING, .string_value = attributes->seed},
        {.name = METADATA_KEY_MAX_DEPTH, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->max_depth},
        {.name = METADATA_KEY_FRAME, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->frame},
        {.name = METADATA_KEY_SAMPLES_FINISHED, .type = IMAGE_ATTRIBUTE_STRING, .string_value = attributes->samples},
        {.name = METADATA_KEY_PATH_SEGMENTS, .type = IMAGE_ATTRIBUTE_STRING, .string_value = attributes->segments},
        {.name = METADATA_KEY_COMPLETE, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->complete},
        {.name = METADATA_KEY_RENDER_SECONDS, .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = metadata->render_seconds},
    };
    int count = (int)(sizeof always / sizeof always[0]);
    memcpy(attributes->list, always, sizeof always);
    if (metadata->options_hash != NULL)
        attributes->list[count++] = (image_attribute){
            .name = METADATA_KEY_OPTIONS_HASH, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->options_hash};
    if (metadata->stop_reason != NULL) {   /* a render's keys (not a merge's) */
        attributes->list[count++] = (image_attribute){
            .name = METADATA_KEY_STOP_REASON, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->stop_reason};
        attributes->list[count++] = (image_attribute){.name = METADATA_KEY_NOISE_THRESHOLD,
                                                      .type = IMAGE_ATTRIBUTE_FLOAT,
                                                      .float_value = metadata->noise_threshold};
        attributes->list[count++] = (image_attribute){
            .name = METADATA_KEY_MIN_SPP, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->min_spp};
    }
    if (metadata->merged_parts > 0)
        attributes->list[count++] = (image_attribute){
            .name = METADATA_KEY_MERGED_PARTS, .type = IMAGE_ATTRIBUTE_INT, .int_value = metadata->merged_parts};
    if (metadata->light_groups != NULL)
        attributes->list[count++] = (image_attribute){
            .name = METADATA_KEY_LIGHT_GROUPS, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->light_groups};
    if (metadata->postprocess != NULL)
        attributes->list[count++] = (image_attribute){
            .name = METADATA_KEY_POSTPROCESS, .type = IMAGE_ATTRIBUTE_STRING, .string_value = metadata->postprocess};
    attributes->count = count;
}

/* The write options of an output with metadata's attributes (held in *attributes, which
 * must outlive the options) and exposure: what render_output_write and a stream share. */
static image_write_options output_write_options(const render_output_metadata *metadata, float exposure,
                                                output_attributes *attributes)
{
    make_attributes(metadata, attributes);
    image_write_options options = image_write_options_defaults();
    options.exposure = exposure;
    options.attributes = attributes->list;
    options.attribute_count = attributes->count;
    return options;
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
    output_attributes attributes;
    image_write_options options = output_write_options(metadata, exposure, &attributes);
    status = image_write(path, written, &options, error);
    image_free(&made);
    return status;
}

struct render_output_stream {
    image_stream *stream;
    bool exr;
};

rt_status render_output_stream_open(const char *path, const rt_image *layout, const render_output_metadata *metadata,
                                    float exposure, render_output_stream **out, rt_error *error)
{
    *out = calloc(1, sizeof **out);
    if (*out == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory opening '%s'", path);
    (*out)->exr = image_format_of(path) == IMAGE_FORMAT_EXR;
    rt_image written = *layout;
    written.pixels = NULL;
    if (!(*out)->exr) {
        written.channels = 3;
        memset(written.channel_names, 0, sizeof written.channel_names);
    }
    output_attributes attributes;
    image_write_options options = output_write_options(metadata, exposure, &attributes);
    rt_status status = image_stream_open(path, &written, &options, &(*out)->stream, error);
    if (status != RT_OK) {
        free(*out);
        *out = NULL;
    }
    return status;
}

rt_status render_output_stream_rows(render_output_stream *stream, const rt_image *rows, rt_error *error)
{
    rt_image made;
    rt_status status;
    const rt_image *written = stream->exr ? rows : image_for_format("colour.png", rows, NULL, &made, &status, error);
    if (!stream->exr && status != RT_OK)
        return status;
    status = image_stream_write_rows(stream->stream, written, error);
    if (!stream->exr)
        image_free(&made);
    return status;
}

rt_status render_output_stream_close(render_output_stream *stream, rt_error *error)
{
    rt_status status = image_stream_close(stream->stream, error);
    free(stream);
    return status;
}

void render_output_stream_abandon(render_output_stream *stream)
{
    if (stream == NULL)
        return;
    image_stream_abandon(stream->stream);
    free(stream);
}

rt_status render_output_derived_metadata(const char *input, const char *step, image_attribute_set *out,
                                         rt_error *error)
{
    rt_status status = image_read_attributes(input, "rtspheres:", out, error);
    if (status != RT_OK)
        return status;
    image_attribute_set_remove(out, METADATA_KEY_OPTIONS_HASH);
    const image_attribute *before = image_attribute_set_find(out, METADATA_KEY_POSTPROCESS);
    const char *earlier = before != NULL && before->string_value != NULL ? before->string_value : "";
    size_t size = strlen(earlier) + strlen(step) + 3;
    char *steps = malloc(size);
    if (steps == NULL) {
        image_attribute_set_free(out);
        return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory for the metadata of an image made from '%s'",
                            input);
    }
    snprintf(steps, size, "%s%s%s", earlier, earlier[0] != '\0' ? "; " : "", step);
    image_attribute postprocess = {.name = METADATA_KEY_POSTPROCESS, .type = IMAGE_ATTRIBUTE_STRING,
                                   .string_value = steps};
    status = image_attribute_set_put(out, &postprocess, error);
    free(steps);
    if (status != RT_OK)
        image_attribute_set_free(out);
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
