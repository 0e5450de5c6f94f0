/* image_stat_diff.c: see image_stat_diff.h. Sums are in double: a block of the whole image
 * adds up every pixel. */
#include "image_stat_diff.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_ALPHA 0.01
#define DEFAULT_PASS_SHARE 0.9975
#define DEFAULT_BLOCK_ALPHA 0.01
#define DEFAULT_RELATIVE_FLOOR 1e-3
#define DEFAULT_ABSOLUTE_FLOOR 1e-5
static const int default_block_sizes[] = {4, 8, 16, 32, 64, IMAGE_STAT_WHOLE_IMAGE};

image_stat_options image_stat_options_defaults(void)
{
    return (image_stat_options){0};
}

/* Returns value, or fallback when value is zero ("zero means default"). */
static double or_default(double value, double fallback)
{
    return value == 0.0 ? fallback : value;
}

/* The per-test level that Šidák's correction gives m tests sharing alpha:
 * 1 - (1 - alpha)^(1/m), computed without losing the small result to rounding. */
static double sidak(double alpha, double m)
{
    return -expm1(log1p(-alpha) / m);
}

double image_stat_z_threshold(double test_alpha)
{
    /* Bisection on the two-sided p-value erfc(z / sqrt 2), which falls from 1 at z = 0;
     * at z = 38 it is below any double's smallest normal level a test could ask for. */
    double low = 0.0, high = 38.0;
    for (int i = 0; i < 200 && high - low > 1e-12; i++) {
        double middle = 0.5 * (low + high);
        if (erfc(middle / sqrt(2.0)) > test_alpha)
            low = middle;
        else
            high = middle;
    }
    return 0.5 * (low + high);
}

/* Returns the index of the channel called name, or of the unnamed channel at
 * default_index (image_io.h: "" is the default name, R G B A by position), or -1. */
static int find_channel(const rt_image *image, const char *name, int default_index)
{
    int named = image_channel_index(image, name);
    if (named >= 0)
        return named;
    if (default_index >= 0 && default_index < image->channels && image->channel_names[default_index][0] == '\0')
        return default_index;
    return -1;
}

/* Where one image's values are: R, G, B, samples, variance.R/G/B (-1: none). */
typedef struct image_channels {
    int colour[3];
    int samples;
    int variance[3];
    bool has_variance;
} image_channels;

/* Finds image's channels (which names "A" or "B" in messages). Returns RT_OK, or
 * RT_ERROR_INPUT when a colour or the samples channel is missing. */
static rt_status find_channels(const rt_image *image, const char *which, image_channels *found, rt_error *error)
{
    static const char *const colour_names[3] = {"R", "G", "B"};
    static const char *const variance_names[3] = {"variance.R", "variance.G", "variance.B"};
    if (image == NULL || image->pixels == NULL || image->width <= 0 || image->height <= 0)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: image %s is empty", which);
    found->has_variance = true;
    for (int c = 0; c < 3; c++) {
        found->colour[c] = find_channel(image, colour_names[c], c);
        found->variance[c] = find_channel(image, variance_names[c], -1);
        if (found->colour[c] < 0)
            return rt_error_set(error, RT_ERROR_INPUT, "DIFF: image %s has no %s channel", which, colour_names[c]);
        found->has_variance = found->has_variance && found->variance[c] >= 0;
    }
    found->samples = find_channel(image, "samples", -1);
    if (found->samples < 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "DIFF: image %s has no 'samples' channel; the statistical test needs each pixel's "
                            "sample count (an EXR from `rtspheres render`)", which);
    return RT_OK;
}

/* Returns RT_OK when no value of image (which: "A" or "B") that the test reads is NaN,
 * else RT_ERROR_INPUT naming the first. */
static rt_status check_for_nan(const rt_image *image, const image_channels *channels, const char *which,
                               rt_error *error)
{
    size_t pixels = (size_t)image->width * image->height;
    for (size_t p = 0; p < pixels; p++) {
        const float *pixel = image->pixels + p * image->channels;
        int read[7] = {channels->colour[0], channels->colour[1], channels->colour[2], channels->samples,
                       channels->variance[0], channels->variance[1], channels->variance[2]};
        for (int i = 0; i < 7; i++)
            if (read[i] >= 0 && isnan(pixel[read[i]]))
                return rt_error_set(error, RT_ERROR_INPUT, "DIFF: image %s has NaN at pixel (%d, %d) in %s", which,
                                    (int)(p % image->width), (int)(p / image->width),
                                    image->channel_names[read[i]][0] ? image->channel_names[read[i]] : "R/G/B");
    }
    return RT_OK;
}

/* What the tests read of each pixel and channel: the difference d, the variance of d
 * without the floor, and the mean magnitude the floor scales with. */
typedef struct pixel_table {
    int width, height;
    double *difference, *variance, *magnitude;   /* 3 per pixel */
    unsigned char *tested;                       /* 1 per pixel */
} pixel_table;

static void pixel_table_free(pixel_table *table)
{
    free(table->difference);
    free(table->variance);
    free(table->magnitude);
    free(table->tested);
    memset(table, 0, sizeof *table);
}

/* Fills table from a and b. The variance of a pixel's mean is s^2 / (n - 1). */
static rt_status fill_pixel_table(const rt_image *a, const image_channels *in_a, const rt_image *b,
                                  const image_channels *in_b, pixel_table *table, image_stat_result *result,
                                  rt_error *error)
{
    size_t pixels = (size_t)a->width * a->height;
    table->width = a->width;
    table->height = a->height;
    table->difference = malloc(pixels * 3 * sizeof(double));
    table->variance = malloc(pixels * 3 * sizeof(double));
    table->magnitude = malloc(pixels * 3 * sizeof(double));
    table->tested = malloc(pixels);
    if (!table->difference || !table->variance || !table->magnitude || !table->tested)
        return rt_error_set(error, RT_ERROR_RUNTIME, "DIFF: out of memory comparing %dx%d images", a->width,
                            a->height);
    for (size_t p = 0; p < pixels; p++) {
        const float *pixel_a = a->pixels + p * a->channels, *pixel_b = b->pixels + p * b->channels;
        double n_a = pixel_a[in_a->samples], n_b = pixel_b[in_b->samples];
        table->tested[p] = n_a >= 2 && n_b >= 2;
        if (table->tested[p])
            result->tested_pixels++;
        else
            result->skipped_pixels++;
        for (int c = 0; c < 3; c++) {
            double mean_a = pixel_a[in_a->colour[c]], mean_b = pixel_b[in_b->colour[c]];
            double spread_a = pixel_a[in_a->variance[c]], spread_b = pixel_b[in_b->variance[c]];
            size_t i = p * 3 + (size_t)c;
            table->difference[i] = table->tested[p] ? mean_a - mean_b : 0.0;
            table->variance[i] = table->tested[p] ? fmax(spread_a, 0.0) / (n_a - 1) + fmax(spread_b, 0.0) / (n_b - 1)
                                                  : 0.0;
            table->magnitude[i] = table->tested[p] ? 0.5 * (fabs(mean_a) + fabs(mean_b)) : 0.0;
        }
    }
    return RT_OK;
}

/* The options with defaults filled in and checked. */
typedef struct stat_settings {
    double alpha, pass_share, block_alpha, relative_floor, absolute_floor;
    int block_sizes[IMAGE_STAT_MAX_BLOCK_SCALES];
    int block_count;
} stat_settings;

static rt_status settle_options(const image_stat_options *options, stat_settings *settings, rt_error *error)
{
    settings->alpha = or_default(options->alpha, DEFAULT_ALPHA);
    settings->pass_share = or_default(options->pass_share, DEFAULT_PASS_SHARE);
    settings->block_alpha = or_default(options->block_alpha, DEFAULT_BLOCK_ALPHA);
    settings->relative_floor = or_default(options->relative_floor, DEFAULT_RELATIVE_FLOOR);
    settings->absolute_floor = or_default(options->absolute_floor, DEFAULT_ABSOLUTE_FLOOR);
    if (!(settings->alpha > 0 && settings->alpha < 1) || !(settings->block_alpha > 0 && settings->block_alpha < 1))
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: a significance level must be between 0 and 1");
    if (!(settings->pass_share > 0 && settings->pass_share <= 1))
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: the pass share must be above 0 and at most 1");
    if (!(settings->relative_floor >= 0) || !(settings->absolute_floor >= 0) || isinf(settings->relative_floor)
        || isinf(settings->absolute_floor))
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: the noise floor must be a finite number of 0 or more");
    if (options->pixels_only) {
        settings->block_count = 0;
        return RT_OK;
    }
    if (options->block_count < 0 || options->block_count > IMAGE_STAT_MAX_BLOCK_SCALES)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: at most %d block sizes", IMAGE_STAT_MAX_BLOCK_SCALES);
    if (options->block_count == 0) {
        settings->block_count = (int)(sizeof default_block_sizes / sizeof default_block_sizes[0]);
        memcpy(settings->block_sizes, default_block_sizes, sizeof default_block_sizes);
        return RT_OK;
    }
    settings->block_count = options->block_count;
    for (int i = 0; i < options->block_count; i++) {
        int size = options->block_sizes[i];
        if (size != IMAGE_STAT_WHOLE_IMAGE && size < 2)
            return rt_error_set(error, RT_ERROR_INPUT, "DIFF: a block size must be 2 pixels or more, not %d", size);
        settings->block_sizes[i] = size;
    }
    return RT_OK;
}

/* The noise floor's variance for values of mean magnitude magnitude. */
static double floor_variance(const stat_settings *settings, double magnitude)
{
    double floor = settings->relative_floor * magnitude + settings->absolute_floor;
    return floor * floor;
}

/* Notes the test of value z at (x, y, channel) in scale when it is the largest so far. */
static void note_extreme(image_stat_scale *scale, double z, int x, int y, int channel)
{
    if (fabs(z) > fabs(scale->max_z) || scale->tests == 1) {
        scale->max_z = z;
        scale->max_x = x;
        scale->max_y = y;
        scale->max_channel = channel;
    }
}

/* Keeps in *kept the z of larger magnitude of *kept and z. */
static void keep_larger(float *kept, double z)
{
    if (fabs(z) > fabsf(*kept))
        *kept = (float)z;
}

/* Runs the pixel scale into result->scales[0] and the z-score moments; z_scores (NULL or
 * 3 per pixel) gets the z-scores, significance (NULL or one per pixel) each pixel's z of
 * largest magnitude over its channels / the threshold. */
static void pixel_scale(const pixel_table *table, const stat_settings *settings, image_stat_result *result,
                        float *z_scores, float *significance)
{
    image_stat_scale *scale = &result->scales[0];
    scale->block_size = 1;
    double channel_tests = 3.0 * (double)result->tested_pixels;
    scale->test_alpha = sidak(settings->alpha, channel_tests);
    scale->z_threshold = image_stat_z_threshold(scale->test_alpha);
    double sum = 0, sum_squares = 0;
    size_t pixels = (size_t)table->width * table->height;
    for (size_t p = 0; p < pixels; p++) {
        for (int c = 0; c < 3 && table->tested[p]; c++) {
            size_t i = p * 3 + (size_t)c;
            double z = table->difference[i]
                       / sqrt(table->variance[i] + floor_variance(settings, table->magnitude[i]));
            scale->tests++;
            note_extreme(scale, z, (int)(p % table->width), (int)(p / table->width), c);
            if (fabs(z) > scale->z_threshold)
                scale->failing++;
            sum += z;
            sum_squares += z * z;
            if (z_scores != NULL)
                z_scores[i] = (float)z;
            if (significance != NULL)
                keep_larger(&significance[p], z / scale->z_threshold);
        }
    }
    result->passing_share = 1.0 - (double)scale->failing / channel_tests;
    result->required_share = settings->pass_share;
    scale->passed = result->passing_share >= settings->pass_share;
    result->z_mean = sum / channel_tests;
    result->z_sd = sqrt(fmax(0.0, sum_squares / channel_tests - result->z_mean * result->z_mean));
}

/* Runs the block scale of side size (IMAGE_STAT_WHOLE_IMAGE: one block) with its share
 * scale_alpha into *scale; significance (NULL or one per pixel) gets the z of largest
 * magnitude over the channels of each pixel's block / the threshold. block_z is scratch
 * of at least 3 * the number of blocks. */
static void block_scale(const pixel_table *table, const stat_settings *settings, int size, double scale_alpha,
                        image_stat_scale *scale, double *block_z, float *significance)
{
    int side_x = size == IMAGE_STAT_WHOLE_IMAGE ? table->width : size;
    int side_y = size == IMAGE_STAT_WHOLE_IMAGE ? table->height : size;
    int blocks_x = (table->width + side_x - 1) / side_x, blocks_y = (table->height + side_y - 1) / side_y;
    scale->block_size = size;
    /* First the z of every block with a tested pixel (NAN: none), to count the tests. */
    for (int by = 0; by < blocks_y; by++)
        for (int bx = 0; bx < blocks_x; bx++) {
            double sums[3][3] = {{0}};   /* [channel][difference, variance, magnitude] */
            long count = 0;
            for (int y = by * side_y; y < (by + 1) * side_y && y < table->height; y++)
                for (int x = bx * side_x; x < (bx + 1) * side_x && x < table->width; x++) {
                    size_t p = (size_t)y * table->width + x;
                    if (!table->tested[p])
                        continue;
                    count++;
                    for (int c = 0; c < 3; c++) {
                        sums[c][0] += table->difference[p * 3 + c];
                        sums[c][1] += table->variance[p * 3 + c];
                        sums[c][2] += table->magnitude[p * 3 + c];
                    }
                }
            for (int c = 0; c < 3; c++) {
                double *z = &block_z[((size_t)by * blocks_x + bx) * 3 + c];
                *z = NAN;
                if (count == 0)
                    continue;
                double k = (double)count;
                *z = (sums[c][0] / k) / sqrt(sums[c][1] / (k * k) + floor_variance(settings, sums[c][2] / k));
                scale->tests++;
                note_extreme(scale, *z, bx * side_x, by * side_y, c);
            }
        }
    scale->test_alpha = sidak(scale_alpha, scale->tests > 0 ? (double)scale->tests : 1.0);
    scale->z_threshold = image_stat_z_threshold(scale->test_alpha);
    for (size_t i = 0; i < (size_t)blocks_x * blocks_y * 3; i++)
        if (!isnan(block_z[i]) && fabs(block_z[i]) > scale->z_threshold)
            scale->failing++;
    scale->passed = scale->failing == 0;
    if (significance == NULL)
        return;
    for (int y = 0; y < table->height; y++)
        for (int x = 0; x < table->width; x++) {
            const double *z = &block_z[((size_t)(y / side_y) * blocks_x + (size_t)(x / side_x)) * 3];
            float *s = &significance[(size_t)y * table->width + x];
            for (int c = 0; c < 3; c++)
                if (!isnan(z[c]))
                    keep_larger(s, z[c] / scale->z_threshold);
        }
}

/* Runs every scale; maps (may be NULL) is filled as the header says. */
static rt_status run_scales(const pixel_table *table, const stat_settings *settings, image_stat_result *result,
                            rt_image *maps, rt_error *error)
{
    size_t pixels = (size_t)table->width * table->height;
    float *z_scores = NULL, *significance = NULL;
    if (maps != NULL) {
        z_scores = calloc(pixels * 3, sizeof *z_scores);
        significance = calloc(pixels, sizeof *significance);
    }
    /* The most blocks of any scale: 2x2 pixels each, rounded up. */
    double *block_z = malloc(((size_t)(table->width + 1) / 2) * ((size_t)(table->height + 1) / 2) * 3 * sizeof *block_z);
    rt_status status = RT_OK;
    if (block_z == NULL || (maps != NULL && (z_scores == NULL || significance == NULL)))
        status = rt_error_set(error, RT_ERROR_RUNTIME, "DIFF: out of memory comparing %dx%d images", table->width,
                              table->height);
    if (status == RT_OK) {
        pixel_scale(table, settings, result, z_scores, NULL);
        double scale_alpha = settings->block_count > 0 ? sidak(settings->block_alpha, settings->block_count) : 0;
        for (int i = 0; i < settings->block_count; i++)
            block_scale(table, settings, settings->block_sizes[i], scale_alpha, &result->scales[1 + i], block_z,
                        NULL);
        result->scale_count = 1 + settings->block_count;
        result->passed = true;
        for (int i = 0; i < result->scale_count; i++)
            result->passed = result->passed && result->scales[i].passed;
        /* The map shows the finest scale that fails (the pixels when none does): where
         * the difference is, as sharply as the test can tell. */
        result->map_scale = 0;
        while (result->map_scale < result->scale_count - 1 && result->scales[result->map_scale].passed)
            result->map_scale++;
        if (result->scales[result->map_scale].passed)
            result->map_scale = 0;
        if (significance != NULL && result->map_scale == 0) {
            image_stat_result again = *result;
            pixel_scale(table, settings, &again, NULL, significance);
        } else if (significance != NULL) {
            image_stat_scale again = {0};
            block_scale(table, settings, settings->block_sizes[result->map_scale - 1], scale_alpha, &again, block_z,
                        significance);
        }
    }
    if (status == RT_OK && maps != NULL)
        status = image_create(maps, table->width, table->height, 4, error);
    if (status == RT_OK && maps != NULL) {
        static const char *const names[4] = {"z.R", "z.G", "z.B", "significance"};
        for (int c = 0; c < 4; c++)
            strcpy(maps->channel_names[c], names[c]);
        for (size_t p = 0; p < pixels; p++) {
            for (int c = 0; c < 3; c++)
                maps->pixels[p * 4 + c] = z_scores[p * 3 + c];
            maps->pixels[p * 4 + 3] = significance[p];
        }
    }
    free(z_scores);
    free(significance);
    free(block_z);
    return status;
}

rt_status image_stat_diff(const rt_image *a, const rt_image *b, const image_stat_options *options,
                          image_stat_result *result, rt_image *maps, rt_error *error)
{
    memset(result, 0, sizeof *result);
    if (maps != NULL)
        memset(maps, 0, sizeof *maps);
    image_stat_options defaults = image_stat_options_defaults();
    stat_settings settings = {0};
    image_channels in_a, in_b;
    rt_status status = settle_options(options != NULL ? options : &defaults, &settings, error);
    if (status == RT_OK)
        status = find_channels(a, "A", &in_a, error);
    if (status == RT_OK)
        status = find_channels(b, "B", &in_b, error);
    if (status != RT_OK)
        return status;
    if (a->width != b->width || a->height != b->height)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: sizes differ: %dx%d vs %dx%d", a->width, a->height,
                            b->width, b->height);
    for (int i = 0; i < 2; i++)
        if (!(i == 0 ? in_a : in_b).has_variance)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "DIFF: image %s has no variance.R/G/B layers, which the statistical test needs of "
                                "both images; render it with --variance",
                                i == 0 ? "A" : "B");
    status = check_for_nan(a, &in_a, "A", error);
    if (status == RT_OK)
        status = check_for_nan(b, &in_b, "B", error);
    if (status != RT_OK)
        return status;
    pixel_table table = {0};
    status = fill_pixel_table(a, &in_a, b, &in_b, &table, result, error);
    if (status == RT_OK && result->tested_pixels == 0)
        status = rt_error_set(error, RT_ERROR_INPUT,
                              "DIFF: no pixel has 2 or more samples in both images: there is nothing to test");
    if (status == RT_OK)
        status = run_scales(&table, &settings, result, maps, error);
    pixel_table_free(&table);
    return status;
}

/* The heat map's colours at signed significance s (z / threshold): black at 0; new
 * brighter than the reference (s > 0) dark red at 0.5, red at 1 (a failing test), yellow
 * at 1.5; darker (s < 0) dark blue, blue, cyan; white from 2 on. */
static void heat_colour(float s, float *rgb)
{
    static const float warm[5][3] = {{0, 0, 0}, {0.35f, 0.02f, 0.02f}, {1, 0.05f, 0.02f}, {1, 0.85f, 0}, {1, 1, 1}};
    static const float cool[5][3] = {{0, 0, 0}, {0.02f, 0.05f, 0.4f}, {0.05f, 0.25f, 1}, {0, 0.9f, 1}, {1, 1, 1}};
    const float(*stops)[3] = s >= 0 ? warm : cool;
    float position = fminf(fabsf(s), 2.0f) * 2.0f;   /* 0 .. 4 */
    int low = (int)position < 4 ? (int)position : 3;
    float t = position - (float)low;
    for (int c = 0; c < 3; c++)
        rgb[c] = stops[low][c] + t * (stops[low + 1][c] - stops[low][c]);
}

rt_status image_stat_heat_map(const rt_image *maps, rt_image *heat, rt_error *error)
{
    int significance = find_channel(maps, "significance", -1);
    if (significance < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: the maps have no significance channel");
    rt_status status = image_create(heat, maps->width, maps->height, 3, error);
    if (status != RT_OK)
        return status;
    size_t pixels = (size_t)maps->width * maps->height;
    for (size_t p = 0; p < pixels; p++)
        heat_colour(maps->pixels[p * maps->channels + significance], heat->pixels + p * 3);
    return RT_OK;
}
