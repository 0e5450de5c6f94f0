/* image_diff.c: see image_diff.h. */
#include "image_diff.h"

#include <math.h>
#include <string.h>

#define DEFAULT_FAIL_THRESHOLD 0.016
#define DEFAULT_FAIL_PERCENT 1.0
#define DEFAULT_DIFF_SCALE 16.0

image_diff_options image_diff_options_defaults(void)
{
    image_diff_options options;
    memset(&options, 0, sizeof options);
    return options;
}

/* Returns value, or fallback when value is zero ("zero means default"). */
static double or_default(double value, double fallback)
{
    return value == 0.0 ? fallback : value;
}

/* Looks for a NaN in any channel of image (named "A" or "B" in the message). Returns
 * RT_OK, or RT_ERROR_INPUT naming the first NaN's pixel and channel. */
static rt_status check_for_nan(const rt_image *image, const char *which, rt_error *error)
{
    size_t count = (size_t)image->width * image->height * image->channels;
    for (size_t i = 0; i < count; i++) {
        if (isnan(image->pixels[i])) {
            size_t pixel = i / image->channels;
            return rt_error_set(error, RT_ERROR_INPUT,
                                "DIFF: image %s has NaN at pixel (%d, %d), channel %d", which,
                                (int)(pixel % image->width), (int)(pixel / image->width),
                                (int)(i % image->channels));
        }
    }
    return RT_OK;
}

/* Returns RT_OK when image has pixels to compare, else RT_ERROR_INPUT. */
static rt_status check_image(const rt_image *image, const char *which, rt_error *error)
{
    if (image == NULL || image->pixels == NULL || image->width <= 0 || image->height <= 0
        || image->channels <= 0)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: image %s is empty", which);
    return RT_OK;
}

/* The difference of two samples; equal infinities differ by 0, not by NaN. */
static double sample_difference(float a, float b)
{
    return a == b ? 0.0 : fabs((double)a - (double)b);
}

rt_status image_diff(const rt_image *a, const rt_image *b, const image_diff_options *options,
                     image_diff_result *result, rt_image *difference_image, rt_error *error)
{
    memset(result, 0, sizeof *result);
    if (difference_image != NULL)
        memset(difference_image, 0, sizeof *difference_image);

    rt_status status = check_image(a, "A", error);
    if (status == RT_OK)
        status = check_image(b, "B", error);
    if (status != RT_OK)
        return status;
    if (a->width != b->width || a->height != b->height)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: sizes differ: %dx%d vs %dx%d", a->width,
                            a->height, b->width, b->height);
    status = check_for_nan(a, "A", error);
    if (status == RT_OK)
        status = check_for_nan(b, "B", error);
    if (status != RT_OK)
        return status;

    image_diff_options defaults = image_diff_options_defaults();
    if (options == NULL)
        options = &defaults;
    double fail_threshold = or_default(options->fail_threshold, DEFAULT_FAIL_THRESHOLD);
    double fail_percent = or_default(options->fail_percent, DEFAULT_FAIL_PERCENT);
    double hard_fail = options->hard_fail;
    double diff_scale = or_default(options->diff_scale, DEFAULT_DIFF_SCALE);

    int compared = a->channels < b->channels ? a->channels : b->channels;
    if (compared > 3)
        compared = 3;

    if (difference_image != NULL) {
        status = image_create(difference_image, a->width, a->height, 3, error);
        if (status != RT_OK)
            return status;
    }

    /* Sums in double: a 4K image has 25 million samples, too many for float sums. */
    double sum_abs = 0.0, sum_squares = 0.0;
    double max_error = 0.0;
    int max_x = 0, max_y = 0;
    long failing = 0;
    for (int y = 0; y < a->height; y++) {
        for (int x = 0; x < a->width; x++) {
            size_t pixel = (size_t)y * a->width + x;
            const float *pa = a->pixels + pixel * a->channels;
            const float *pb = b->pixels + pixel * b->channels;
            double pixel_error = 0.0;
            for (int c = 0; c < compared; c++) {
                double d = sample_difference(pa[c], pb[c]);
                sum_abs += d;
                sum_squares += d * d;
                if (d > pixel_error)
                    pixel_error = d;
                if (difference_image != NULL)
                    difference_image->pixels[pixel * 3 + c] = (float)(d * diff_scale);
            }
            /* A single compared channel is shown as grey rather than red. */
            if (difference_image != NULL && compared == 1)
                difference_image->pixels[pixel * 3 + 1] = difference_image->pixels[pixel * 3 + 2] =
                    difference_image->pixels[pixel * 3];
            if (pixel_error > max_error) {
                max_error = pixel_error;
                max_x = x;
                max_y = y;
            }
            if (pixel_error > fail_threshold)
                failing++;
        }
    }

    double pixel_count = (double)a->width * a->height;
    double sample_count = pixel_count * compared;
    double mse = sum_squares / sample_count;
    result->mean_error = sum_abs / sample_count;
    result->rms_error = sqrt(mse);
    result->psnr = mse == 0.0 ? INFINITY : 10.0 * log10(1.0 / mse);
    result->max_error = max_error;
    result->max_x = max_x;
    result->max_y = max_y;
    result->failing_pixels = failing;
    result->failing_percent = 100.0 * (double)failing / pixel_count;
    result->passed = result->failing_percent <= fail_percent
                     && !(hard_fail > 0.0 && max_error > hard_fail);
    return RT_OK;
}
