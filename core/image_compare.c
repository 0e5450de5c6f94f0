/* image_compare.c: see image_compare.h. */
#include "image_compare.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

image_compare_options image_compare_options_defaults(void)
{
    return (image_compare_options){0};
}

const char *image_compare_test_name(image_compare_test test)
{
    return test == IMAGE_COMPARE_Z ? "z" : "idiff";
}

rt_status image_compare(const rt_image *a, const rt_image *b, const image_compare_options *options,
                        image_compare_result *result, rt_image *difference, rt_image *maps, rt_error *error)
{
    image_compare_options defaults = image_compare_options_defaults();
    if (options == NULL)
        options = &defaults;
    memset(result, 0, sizeof *result);
    if (difference != NULL)
        memset(difference, 0, sizeof *difference);
    if (maps != NULL)
        memset(maps, 0, sizeof *maps);
    result->test = options->test;
    result->width = a->width;
    result->height = a->height;
    result->other_width = b->width;
    result->other_height = b->height;
    /* A render at the wrong size is a regression like any other, not an input error. */
    if (a->width != b->width || a->height != b->height) {
        result->sizes_differ = true;
        return RT_OK;
    }
    int compared = a->channels < b->channels ? a->channels : b->channels;
    result->channels_compared = compared < 3 ? compared : 3;
    rt_status status = image_diff(a, b, &options->idiff, &result->idiff, difference, error);
    if (status == RT_OK && options->test == IMAGE_COMPARE_Z)
        status = image_stat_diff(a, b, &options->stat, &result->stat, maps, error);
    if (status != RT_OK) {
        if (difference != NULL)
            image_free(difference);
        return status;
    }
    result->passed = options->test == IMAGE_COMPARE_Z ? result->stat.passed : result->idiff.passed;
    return RT_OK;
}

void image_compare_scale_name(int block_size, char *text, size_t size)
{
    if (block_size == 1)
        snprintf(text, size, "pixels");
    else if (block_size == IMAGE_STAT_WHOLE_IMAGE)
        snprintf(text, size, "the whole image");
    else
        snprintf(text, size, "%dx%d blocks", block_size, block_size);
}

/* A threshold as the user gave it: the CLI passes a tolerance of 0 as DBL_MIN (zero means
 * default in the options). */
static double shown(double value, double fallback)
{
    if (value == 0.0)
        return fallback;
    return value <= DBL_MIN ? 0.0 : value;
}

static const char channel_letters[3] = {'R', 'G', 'B'};

/* The z test's line: the first failing scale, or the pixel share and the block test
 * closest to its threshold. */
static void describe_z(const image_stat_result *stat, char *text, size_t size)
{
    const image_stat_scale *pixels = &stat->scales[0];
    char name[32];
    for (int i = 0; i < stat->scale_count; i++) {
        const image_stat_scale *scale = &stat->scales[i];
        if (scale->passed)
            continue;
        image_compare_scale_name(scale->block_size, name, sizeof name);
        if (i == 0)
            snprintf(text, size,
                     "z: %.2f%% of pixel channels pass, fewer than the %.2f%% needed (|z| over %.2f; largest z %.3g "
                     "at (%d, %d) %c)",
                     100.0 * stat->passing_share, 100.0 * stat->required_share, pixels->z_threshold,
                     pixels->max_z, pixels->max_x, pixels->max_y, channel_letters[pixels->max_channel]);
        else
            snprintf(text, size, "z: %ld of %ld tests of %s over |z| %.2f; largest z %.3g at (%d, %d) %c", scale->failing,
                     scale->tests, name, scale->z_threshold, scale->max_z, scale->max_x, scale->max_y,
                     channel_letters[scale->max_channel]);
        return;
    }
    double closest = 0;
    int closest_scale = 0;
    for (int i = 1; i < stat->scale_count; i++) {
        double ratio = fabs(stat->scales[i].max_z) / stat->scales[i].z_threshold;
        if (ratio > closest) {
            closest = ratio;
            closest_scale = i;
        }
    }
    int used = snprintf(text, size, "z: %.2f%% of pixel channels pass; pixel z sd %.2f", 100.0 * stat->passing_share,
                        stat->z_sd);
    if (closest_scale > 0 && used >= 0 && (size_t)used < size) {
        const image_stat_scale *scale = &stat->scales[closest_scale];
        image_compare_scale_name(scale->block_size, name, sizeof name);
        snprintf(text + used, size - (size_t)used, "; largest block |z| %.2f of %.2f (%s)", fabs(scale->max_z),
                 scale->z_threshold, name);
    }
}

/* The idiff test's line: why it failed, or the share over the threshold. */
static void describe_idiff(const image_diff_result *idiff, const image_diff_options *options, char *text,
                           size_t size)
{
    double threshold = shown(options->fail_threshold, IMAGE_DIFF_DEFAULT_FAIL_THRESHOLD);
    double percent = shown(options->fail_percent, IMAGE_DIFF_DEFAULT_FAIL_PERCENT);
    double hard = options->hard_fail;
    if (!idiff->passed && hard > 0 && idiff->max_error > hard)
        snprintf(text, size, "idiff: max error %.6g at (%d, %d) is over the hard limit %g", idiff->max_error,
                 idiff->max_x, idiff->max_y, shown(hard, 0));
    else
        snprintf(text, size, "idiff: %.2f%% of pixels over %g (at most %g%% may be); max error %.6g at (%d, %d), "
                 "RMS %.3g", idiff->failing_percent, threshold, percent, idiff->max_error, idiff->max_x,
                 idiff->max_y, idiff->rms_error);
}

void image_compare_describe(const image_compare_result *result, const image_compare_options *options, char *text,
                            size_t size)
{
    image_compare_options defaults = image_compare_options_defaults();
    if (options == NULL)
        options = &defaults;
    if (result->sizes_differ)
        snprintf(text, size, "sizes differ: %dx%d vs %dx%d", result->width, result->height, result->other_width,
                 result->other_height);
    else if (result->test == IMAGE_COMPARE_Z)
        describe_z(&result->stat, text, size);
    else
        describe_idiff(&result->idiff, &options->idiff, text, size);
}

/* Appends printf-style text at *used of text (size bytes), keeping it terminated. */
__attribute__((format(printf, 4, 5))) static void append(char *text, size_t size, size_t *used, const char *format,
                                                         ...)
{
    if (*used >= size)
        return;
    va_list arguments;
    va_start(arguments, format);
    int written = vsnprintf(text + *used, size - *used, format, arguments);
    va_end(arguments);
    if (written > 0)
        *used += (size_t)written < size - *used ? (size_t)written : size - *used - 1;
}

void image_compare_metrics(const image_compare_result *result, const image_compare_options *options, char *text,
                           size_t size)
{
    image_compare_options defaults = image_compare_options_defaults();
    if (options == NULL)
        options = &defaults;
    size_t used = 0;
    text[0] = '\0';
    const image_diff_result *idiff = &result->idiff;
    if (result->sizes_differ) {
        append(text, size, &used, "sizes differ: %dx%d vs %dx%d\n", result->width, result->height,
               result->other_width, result->other_height);
        return;
    }
    if (result->test == IMAGE_COMPARE_IDIFF) {
        int compared = result->channels_compared;
        append(text, size, &used, "size: %dx%d, %d channel%s compared\n", result->width, result->height, compared,
               compared == 1 ? "" : "s");
        append(text, size, &used, "mean error: %.6g\nrms error: %.6g\npsnr: %.2f dB\n", idiff->mean_error,
               idiff->rms_error, idiff->psnr);
        append(text, size, &used, "max error: %.6g at (%d, %d)\n", idiff->max_error, idiff->max_x, idiff->max_y);
        append(text, size, &used, "pixels over %g: %ld of %ld (%.2f%%)\n",
               shown(options->idiff.fail_threshold, IMAGE_DIFF_DEFAULT_FAIL_THRESHOLD), idiff->failing_pixels,
               (long)result->width * result->height, idiff->failing_percent);
        return;
    }
    const image_stat_result *stat = &result->stat;
    append(text, size, &used, "size: %dx%d, %ld pixels tested, %ld skipped (fewer than 2 samples)\n", result->width,
           result->height, stat->tested_pixels, stat->skipped_pixels);
    append(text, size, &used, "mean error: %.6g\nrms error: %.6g\n", idiff->mean_error, idiff->rms_error);
    append(text, size, &used, "max error: %.6g at (%d, %d)\n", idiff->max_error, idiff->max_x, idiff->max_y);
    append(text, size, &used, "pixel z-scores: mean %.4f, sd %.4f\n", stat->z_mean, stat->z_sd);
    for (int i = 0; i < stat->scale_count; i++) {
        const image_stat_scale *scale = &stat->scales[i];
        char name[32];
        image_compare_scale_name(scale->block_size, name, sizeof name);
        append(text, size, &used, "%s: %ld of %ld tests over |z| %.3f (level %.3g each)", name, scale->failing,
               scale->tests, scale->z_threshold, scale->test_alpha);
        if (i == 0)
            append(text, size, &used, ", %.3f%% pass (%.3f%% must)", 100.0 * stat->passing_share,
                   100.0 * stat->required_share);
        append(text, size, &used, "; largest z %.3f at (%d, %d) %c: %s\n", scale->max_z, scale->max_x, scale->max_y,
               channel_letters[scale->max_channel], scale->passed ? "pass" : "FAIL");
    }
}
