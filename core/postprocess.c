/* postprocess.c: see postprocess.h: the blur, tone mapping and montage (the denoiser is
 * core/postprocess_denoise.c). */
#include "postprocess.h"

#include <cglm/cglm.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "luminance.h"
#include "postprocess_internal.h"

rt_status postprocess_check_image(const rt_image *image, const char *which, rt_error *error)
{
    if (image == NULL || image->pixels == NULL || image->width <= 0 || image->height <= 0 || image->channels <= 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the %s image is empty", which);
    return RT_OK;
}

size_t postprocess_pixel_count(const rt_image *image)
{
    return (size_t)image->width * (size_t)image->height;
}

/* The number of colour channels: 3, or 1 for a grey image (whose second channel, if
 * any, is alpha). */
static int colour_channels(const rt_image *image)
{
    return image->channels >= 3 ? 3 : 1;
}

/* ---------------------------------------------------------------------------------- */
/* Gaussian blur                                                                        */

/* Maps i to [0, n) by mirroring at the borders (-1 -> 0, -2 -> 1, n -> n-1): the image
 * repeated as a mirror-symmetric sequence of period 2n, so any kernel radius works. */
static int mirror_index(long long i, int n)
{
    long long period = 2LL * n;
    long long m = i % period;
    if (m < 0)
        m += period;
    return (int)(m < n ? m : period - 1 - m);
}

/* Convolves count samples of channels-strided data (sample k at data[k * stride]) with
 * the kernel weights[-radius .. radius] (passed as its centre), mirrored at both ends,
 * through scratch (count floats). */
static void convolve_line(float *data, size_t stride, int count, const float *centre, int radius, float *scratch)
{
    for (int i = 0; i < count; i++) {
        double sum = 0.0;
        for (int t = -radius; t <= radius; t++)
            sum += centre[t] * data[(size_t)mirror_index((long long)i + t, count) * stride];
        scratch[i] = (float)sum;
    }
    for (int i = 0; i < count; i++)
        data[(size_t)i * stride] = scratch[i];
}

rt_status postprocess_gaussian_blur(rt_image *image, float sigma_pixels, int passes, rt_error *error)
{
    rt_status status = postprocess_check_image(image, "blurred", error);
    if (status != RT_OK)
        return status;
    if (!(sigma_pixels >= 0.0f) || sigma_pixels > POSTPROCESS_MAX_BLUR_SIGMA)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: blur sigma %g is not between 0 and %g pixels",
                            sigma_pixels, POSTPROCESS_MAX_BLUR_SIGMA);
    if (passes < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: blur passes %d is negative", passes);
    if (sigma_pixels == 0.0f || passes == 0)
        return RT_OK;

    int radius = (int)ceilf(3.0f * sigma_pixels);
    int longest = image->width > image->height ? image->width : image->height;
    float *kernel = malloc((size_t)(2 * radius + 1) * sizeof *kernel);
    float *scratch = malloc((size_t)longest * sizeof *scratch);
    if (kernel == NULL || scratch == NULL) {
        free(kernel);
        free(scratch);
        return rt_error_set(error, RT_ERROR_RUNTIME, "POSTPROCESS: out of memory for a blur of sigma %g",
                            sigma_pixels);
    }
    double sum = 0.0;
    for (int t = -radius; t <= radius; t++) {
        kernel[t + radius] = expf(-(float)t * (float)t / (2.0f * sigma_pixels * sigma_pixels));
        sum += kernel[t + radius];
    }
    for (int t = 0; t <= 2 * radius; t++)
        kernel[t] = (float)(kernel[t] / sum);

    const float *centre = kernel + radius;
    int channels = image->channels;
    for (int pass = 0; pass < passes; pass++)
        for (int c = 0; c < colour_channels(image); c++) {
            for (int y = 0; y < image->height; y++)
                convolve_line(image->pixels + (size_t)y * image->width * channels + c, (size_t)channels, image->width,
                              centre, radius, scratch);
            for (int x = 0; x < image->width; x++)
                convolve_line(image->pixels + (size_t)x * channels + c, (size_t)image->width * channels,
                              image->height, centre, radius, scratch);
        }
    free(kernel);
    free(scratch);
    return RT_OK;
}

int postprocess_blur_reach(float sigma_pixels, int passes)
{
    if (!(sigma_pixels > 0.0f) || passes <= 0)
        return 0;
    return passes * (int)ceilf(3.0f * sigma_pixels);
}

/* ---------------------------------------------------------------------------------- */
/* Tone mapping                                                                         */

/* Makes value a number in [0, +inf]: NaN and negatives become 0. */
static float non_negative(float value)
{
    return value > 0.0f ? value : 0.0f;
}

/* Narkowicz's ACES fit of one value in [0, inf], clamped to [0, 1]. */
static float aces_curve(float x)
{
    if (isinf(x))
        return 1.0f;
    float y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    return y < 0.0f ? 0.0f : (y > 1.0f ? 1.0f : y);
}

/* Reinhard on the luminance of rgb (three values in [0, inf]), in place. */
static void reinhard_pixel(float *rgb)
{
    if (isinf(rgb[0]) || isinf(rgb[1]) || isinf(rgb[2])) {
        /* The limit of L/(1+L) with the ratios of the infinite channels: white where all are. */
        for (int c = 0; c < 3; c++)
            rgb[c] = isinf(rgb[c]) ? 1.0f : 0.0f;
        return;
    }
    float luminance = luminance_float(rgb[0], rgb[1], rgb[2]);
    if (luminance <= 0.0f) {
        glm_vec3_zero(rgb);
        return;
    }
    float scale = 1.0f / (1.0f + luminance);   /* (L / (1 + L)) / L */
    float largest = glm_vec3_max(rgb) * scale;
    if (largest > 1.0f)
        scale /= largest;
    glm_vec3_scale(rgb, scale, rgb);
}

rt_status postprocess_tonemap(rt_image *image, postprocess_tonemap_operator op, float exposure_stops,
                              rt_error *error)
{
    rt_status status = postprocess_check_image(image, "tone-mapped", error);
    if (status != RT_OK)
        return status;
    if (op != TONEMAP_CLAMP && op != TONEMAP_REINHARD && op != TONEMAP_ACES)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: unknown tone mapping operator %d", (int)op);
    if (!isfinite(exposure_stops))
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: exposure %g stops is not a finite number",
                            exposure_stops);
    float gain = exp2f(exposure_stops);
    size_t count = postprocess_pixel_count(image);
    int channels = image->channels, used = colour_channels(image);
    for (size_t i = 0; i < count; i++) {
        float *pixel = &image->pixels[i * channels];
        if (op == TONEMAP_CLAMP) {
            for (int c = 0; c < used; c++)
                pixel[c] *= gain;
            continue;
        }
        float rgb[3];
        for (int c = 0; c < 3; c++)
            rgb[c] = non_negative(pixel[used == 3 ? c : 0] * gain);  /* grey: one value thrice */
        if (op == TONEMAP_REINHARD)
            reinhard_pixel(rgb);
        else
            for (int c = 0; c < 3; c++)
                rgb[c] = aces_curve(rgb[c]);
        for (int c = 0; c < used; c++)
            pixel[c] = rgb[c];
    }
    return RT_OK;
}

/* ---------------------------------------------------------------------------------- */
/* Montage                                                                              */

rt_status postprocess_montage(const rt_image *images, int count, int columns, int gap_pixels, rt_image *out,
                              rt_error *error)
{
    memset(out, 0, sizeof *out);
    if (images == NULL || count < 1)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: a montage needs at least one image");
    if (columns < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: montage columns %d is negative", columns);
    if (gap_pixels < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: montage gap %d is negative", gap_pixels);
    for (int i = 0; i < count; i++) {
        char which[32];
        snprintf(which, sizeof which, "montage's image %d", i + 1);
        rt_status status = postprocess_check_image(&images[i], which, error);
        if (status != RT_OK)
            return status;
        if (images[i].width != images[0].width || images[i].height != images[0].height)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "POSTPROCESS: montage images must have one size: image %d is %dx%d, image 1 is %dx%d",
                                i + 1, images[i].width, images[i].height, images[0].width, images[0].height);
    }
    if (columns == 0) {
        columns = (int)ceil(sqrt((double)count));
        while ((long long)columns * columns < count)  /* sqrt rounding, for very large counts */
            columns++;
    }
    if (columns > count)
        columns = count;
    int rows = (count + columns - 1) / columns;
    int tile_width = images[0].width, tile_height = images[0].height;
    long long sheet_width = (long long)columns * tile_width + (long long)(columns - 1) * gap_pixels;
    long long sheet_height = (long long)rows * tile_height + (long long)(rows - 1) * gap_pixels;
    if (sheet_width > POSTPROCESS_MAX_MONTAGE_SIDE || sheet_height > POSTPROCESS_MAX_MONTAGE_SIDE)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the montage would be %lldx%lld pixels, more than %d a side",
                            sheet_width, sheet_height, POSTPROCESS_MAX_MONTAGE_SIDE);
    rt_status status = image_create(out, (int)sheet_width, (int)sheet_height, 3, error);
    if (status != RT_OK)
        return status;
    for (int i = 0; i < count; i++) {
        const rt_image *tile = &images[i];
        int left = (i % columns) * (tile_width + gap_pixels);
        int top = (i / columns) * (tile_height + gap_pixels);
        int used = colour_channels(tile);
        for (int y = 0; y < tile_height; y++)
            for (int x = 0; x < tile_width; x++) {
                const float *from = &tile->pixels[((size_t)y * tile_width + x) * tile->channels];
                float *to = &out->pixels[((size_t)(top + y) * out->width + (left + x)) * 3];
                for (int c = 0; c < 3; c++)
                    to[c] = from[used == 3 ? c : 0];
            }
    }
    return RT_OK;
}
