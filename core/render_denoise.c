/* render_denoise.c: see render_denoise.h. */
#include "render_denoise.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "metadata_keys.h"
#include "postprocess.h"

/* Copies the channels named names[0 .. count-1] of image into a new image (*out; the
 * caller frees it). False when image lacks one of them. */
static bool copy_named(const rt_image *image, const char *const *names, int count, rt_image *out, rt_status *status,
                       rt_error *error)
{
    int channels[4];
    for (int k = 0; k < count; k++)
        if ((channels[k] = image_channel_index(image, names[k])) < 0)
            return false;
    *status = image_create(out, image->width, image->height, count, error);
    size_t pixels = (size_t)image->width * image->height;
    for (size_t i = 0; *status == RT_OK && i < pixels; i++)
        for (int k = 0; k < count; k++)
            out->pixels[i * count + k] = image->pixels[i * image->channels + channels[k]];
    return true;
}

rt_status render_denoise(rt_image *colour, const rt_image *beauty, const rt_image *layers, rt_error *error)
{
    static const char *const albedo_names[3] = {"albedo.R", "albedo.G", "albedo.B"};
    static const char *const normal_names[3] = {"normal.X", "normal.Y", "normal.Z"};
    static const char *const depth_names[1] = {"depth.Z"};
    static const char *const emission_names[3] = {"emission.R", "emission.G", "emission.B"};
    static const char *const variance_names[1] = {"variance.Y"};
    rt_image albedo = {0}, normal = {0}, depth = {0}, emission = {0}, mean_variance = {0};
    rt_status status = RT_OK;
    const char *missing = NULL;
    if (!copy_named(layers, albedo_names, 3, &albedo, &status, error))
        missing = "albedo.R/G/B";
    else if (status == RT_OK && !copy_named(layers, normal_names, 3, &normal, &status, error))
        missing = "normal.X/Y/Z";
    else if (status == RT_OK && !copy_named(layers, depth_names, 1, &depth, &status, error))
        missing = "depth.Z";
    if (missing != NULL)
        status = rt_error_set(error, RT_ERROR_INPUT,
                              "DENOISE: the image has no %s layer, which guides the denoiser; render it with --aovs "
                              "(or --denoise) to an .exr", missing);
    bool has_emission = status == RT_OK && copy_named(layers, emission_names, 3, &emission, &status, error);
    bool has_variance = status == RT_OK && copy_named(layers, variance_names, 1, &mean_variance, &status, error);

    /* Per pixel: what its samples allow (render_denoise.h). */
    int samples_channel = beauty != NULL ? image_channel_index(beauty, "samples") : -1;
    size_t pixels = (size_t)layers->width * layers->height;
    for (size_t i = 0; status == RT_OK && i < pixels; i++) {
        float samples = samples_channel >= 0 ? beauty->pixels[i * beauty->channels + samples_channel] : INFINITY;
        if (has_emission && samples < RENDER_DENOISE_EMISSION_MIN_SAMPLES)
            emission.pixels[3 * i] = emission.pixels[3 * i + 1] = emission.pixels[3 * i + 2] = 0.0f;
        /* variance.Y is E[L^2] - E[L]^2 over n samples: the variance of the mean is it / (n - 1). */
        if (has_variance)
            mean_variance.pixels[i] = samples_channel < 0 ? -1.0f
                                      : samples >= RENDER_DENOISE_VARIANCE_MIN_SAMPLES
                                          ? mean_variance.pixels[i] / (samples - 1)
                                          : -1.0f;
    }
    if (status == RT_OK) {
        postprocess_denoise_guides guides = {.albedo = &albedo, .normal = &normal, .depth = &depth,
                                             .emission = has_emission ? &emission : NULL,
                                             .variance = has_variance ? &mean_variance : NULL};
        status = postprocess_denoise(colour, &guides, NULL, error);
    }
    image_free(&albedo);
    image_free(&normal);
    image_free(&depth);
    image_free(&emission);
    image_free(&mean_variance);
    return status;
}

int render_denoise_reach(void)
{
    return postprocess_denoise_reach(NULL);   /* render_denoise() runs the defaults */
}

rt_status render_denoise_check_raw(const char *path, const rt_image *image, rt_error *error)
{
    char steps[256] = "";
    image_read_attribute(path, METADATA_KEY_POSTPROCESS, steps, sizeof steps, NULL);
    if (image_channel_index(image, "noisy.R") < 0 && steps[0] == '\0')
        return RT_OK;
    return rt_error_set(error, RT_ERROR_INPUT, "'%s' is post-processed already (%s); denoise the render it came from",
                        path, steps[0] != '\0' ? steps : "it has noisy.R/G/B");
}
