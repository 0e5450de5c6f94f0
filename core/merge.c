/* merge.c: see merge.h. */
#include "merge.h"

#include "array.h"
#include "luminance.h"
#include "metadata_keys.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What the merger remembers of one part after its pixels have been summed. */
typedef struct part_record {
    char *name;
    merge_metadata metadata;
    int region;                  /* index into merger.regions */
} part_record;

/* One data window; every part with exactly this window belongs to it. */
typedef struct region {
    int x, y, width, height;
    int first_part;              /* the part that brought the window, for messages */
} region;

struct merger {
    part_record *parts;
    int part_count;
    size_t part_capacity;
    region *regions;
    int region_count;
    size_t region_capacity;
    int full_width, full_height;
    /* Per pixel of the full image: R*n, G*n, B*n, n, summed over the parts in double. */
    double *sums;
    relight_layers layers;       /* the first part's light groups (count 0: none) */
    double *layer_sums;          /* per pixel: each layer's R*n, G*n, B*n, as sums */
    /* The AOV layers (merge.h): the parts that had them (and the emission too), and per
     * pixel the guides of the part of lowest sample start that had samples there (albedo
     * R, G, B, normal X, Y, Z, depth), that start, and emission R*n, G*n, B*n and
     * n * (variance.Y + L^2) summed, L the part's mean luminance. */
    int aov_parts, emission_parts;
    float *guides;
    unsigned long long *guide_start;
    double *aov_sums;
};

/* The AOV layers of a part that merge (render.h render_result.aovs), in the order they
 * are written: the guides, variance.Y, then the emission. */
static const char *const aov_names[] = {"albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z",
                                        "depth.Z", "variance.Y", "emission.R", "emission.G", "emission.B"};
#define GUIDE_CHANNELS 7
#define AOV_CHANNELS 8           /* the guides and variance.Y: what --aovs always has */
#define AOV_ALL_CHANNELS 11      /* with the emission (not after --resume) */

/* A half-open sample range [start, start + count). */
typedef struct sample_range {
    unsigned long long start, count;
} sample_range;

merge_options merge_options_defaults(void)
{
    merge_options options;
    memset(&options, 0, sizeof options);
    return options;
}

rt_status merger_create(merger **out, rt_error *error)
{
    *out = calloc(1, sizeof **out);
    if (*out == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "MERGE: out of memory");
    return RT_OK;
}

void merger_free(merger *m)
{
    if (m == NULL)
        return;
    for (int i = 0; i < m->part_count; i++)
        free(m->parts[i].name);
    free(m->parts);
    free(m->regions);
    free(m->sums);
    free(m->layer_sums);
    free(m->guides);
    free(m->guide_start);
    free(m->aov_sums);
    free(m);
}

/* Describes a window as inclusive columns and rows into text (size bytes), the way a
 * person reads "rows 12-23"; returns text. */
static const char *describe_window(int x, int y, int width, int height, char *text, size_t size)
{
    snprintf(text, size, "columns %d-%d, rows %d-%d", x, x + width - 1, y, y + height - 1);
    return text;
}

/* Formats a part's sample range as START:COUNT, the notation of `render --samples`. */
static const char *describe_range(const merge_metadata *metadata, char *text, size_t size)
{
    snprintf(text, size, "%llu:%lld", metadata->sample_start, metadata->spp);
    return text;
}

/* Checks that the new part agrees with the first part on everything that decides the
 * image apart from the samples. Size, seed, depth and frame come before the scene hash,
 * because they change the hash too and name the actual difference better. */
static rt_status check_same_render(const merger *m, const char *name, int full_width, int full_height,
                                   const merge_metadata *metadata, rt_error *error)
{
    const part_record *first = &m->parts[0];
    const merge_metadata *expected = &first->metadata;
    if (full_width != m->full_width || full_height != m->full_height)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' is part of a %dx%d image but '%s' of a %dx%d image; parts of one render "
                            "share the image size", first->name, m->full_width, m->full_height, name, full_width,
                            full_height);
    if (metadata->seed != expected->seed)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' has seed %llu but '%s' seed %llu; parts of one render share the seed",
                            first->name, expected->seed, name, metadata->seed);
    if (metadata->max_depth != expected->max_depth)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' has max depth %d but '%s' max depth %d; parts of one render share it",
                            first->name, expected->max_depth, name, metadata->max_depth);
    if (metadata->frame != expected->frame)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' is frame %d but '%s' frame %d; merge each frame's parts separately",
                            first->name, expected->frame, name, metadata->frame);
    if (strcmp(metadata->scene_hash, expected->scene_hash) != 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' (scene '%s', scene hash %s) and '%s' (scene '%s', scene hash %s) are "
                            "renders of different scenes or scene settings", first->name, expected->scene,
                            expected->scene_hash, name, metadata->scene, metadata->scene_hash);
    return RT_OK;
}

/* Finds where the new part goes: the index of the region with exactly its window, or
 * m->region_count when it is a new region (after checking that it overlaps none). */
static rt_status place_part(const merger *m, const char *name, const rt_image *image,
                            const merge_metadata *metadata, int *region_index, rt_error *error)
{
    char here[96], there[96], range_a[48], range_b[48];
    for (int r = 0; r < m->region_count; r++) {
        const region *existing = &m->regions[r];
        bool same = existing->x == image->x && existing->y == image->y && existing->width == image->width
                    && existing->height == image->height;
        if (same) {
            /* Sample-range parts of one region: their ranges must be disjoint. */
            for (int p = 0; p < m->part_count; p++) {
                const part_record *other = &m->parts[p];
                if (other->region != r)
                    continue;
                unsigned long long a0 = other->metadata.sample_start, a1 = a0 + (unsigned long long)other->metadata.spp;
                unsigned long long b0 = metadata->sample_start, b1 = b0 + (unsigned long long)metadata->spp;
                if (a0 < b1 && b0 < a1)
                    return rt_error_set(error, RT_ERROR_INPUT,
                                        "MERGE: '%s' (samples %s) and '%s' (samples %s) overlap in samples %llu-%llu "
                                        "of the same pixels; those samples would count twice", other->name,
                                        describe_range(&other->metadata, range_a, sizeof range_a), name,
                                        describe_range(metadata, range_b, sizeof range_b), a0 > b0 ? a0 : b0,
                                        (a1 < b1 ? a1 : b1) - 1);
            }
            *region_index = r;
            return RT_OK;
        }
        bool intersect = existing->x < image->x + image->width && image->x < existing->x + existing->width
                         && existing->y < image->y + image->height && image->y < existing->y + existing->height;
        if (intersect)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "MERGE: the regions of '%s' (%s) and '%s' (%s) overlap; tiles and crops of one "
                                "image must not", m->parts[existing->first_part].name,
                                describe_window(existing->x, existing->y, existing->width, existing->height, there,
                                                sizeof there),
                                name, describe_window(image->x, image->y, image->width, image->height, here,
                                                      sizeof here));
    }
    *region_index = m->region_count;
    return RT_OK;
}

/* Finds the light group layers of a part into *layers (count 0: none): those its
 * rtspheres:light_groups names, which must be the first part's groups. */
static rt_status find_light_groups(const merger *m, const char *name, const rt_image *image,
                                   const merge_metadata *metadata, relight_layers *layers, rt_error *error)
{
    memset(layers, 0, sizeof *layers);
    if (m->part_count > 0 && strcmp(metadata->light_groups, m->parts[0].metadata.light_groups) != 0) {
        const char *first = m->parts[0].metadata.light_groups;
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' has light groups %s%s%s but '%s' %s%s%s; merge parts rendered alike (all "
                            "with --light-groups or none)", m->parts[0].name, first[0] ? "'" : "",
                            first[0] ? first : "none", first[0] ? "'" : "", name, metadata->light_groups[0] ? "'" : "",
                            metadata->light_groups[0] ? metadata->light_groups : "none",
                            metadata->light_groups[0] ? "'" : "");
    }
    if (metadata->light_groups[0] == '\0')
        return RT_OK;
    rt_error found = {{0}};
    if (relight_find_layers(image, metadata->light_groups, layers, &found) != RT_OK) {
        const char *why = strncmp(found.message, "RELIGHT: ", 9) == 0 ? found.message + 9 : found.message;
        return rt_error_set(error, RT_ERROR_INPUT, "MERGE: '%s' lists light groups '%s' but its layers are not all "
                            "there: %s", name, metadata->light_groups, why);
    }
    return RT_OK;
}

/* Finds the AOV layers of a part, in aov_names' order, into aov; returns how many of
 * them it has before the first missing one (AOV_CHANNELS: the layers but the emission). */
static int find_aov_channels(const rt_image *image, int aov[AOV_ALL_CHANNELS])
{
    int found = 0;
    while (found < AOV_ALL_CHANNELS && (aov[found] = image_channel_index(image, aov_names[found])) >= 0)
        found++;
    return found;
}

/* Makes the merger's AOV arrays for an image of full_pixels, once (merger's comment says
 * what they hold). False when memory runs out. */
static bool reserve_aov_sums(merger *m, size_t full_pixels)
{
    if (m->guides != NULL)
        return true;
    m->guides = calloc(full_pixels * GUIDE_CHANNELS, sizeof *m->guides);
    m->guide_start = malloc(full_pixels * sizeof *m->guide_start);
    m->aov_sums = calloc(full_pixels * 4, sizeof *m->aov_sums);
    if (m->guides == NULL || m->guide_start == NULL || m->aov_sums == NULL)
        return false;
    for (size_t i = 0; i < full_pixels; i++)
        m->guide_start[i] = ULLONG_MAX;
    return true;
}

/* Adds the AOV layers of one pixel of a part (channel: its R, G, B, samples; aov:
 * find_aov_channels'; n its samples there) at pixel at of the full image. */
static void add_aov_pixel(merger *m, size_t at, const float *pixel, const int channel[4], const int *aov,
                          bool has_emission, unsigned long long sample_start, double n)
{
    /* A render's guides come from its first samples' camera rays: the part that starts
     * lowest has them. */
    if (sample_start < m->guide_start[at]) {
        m->guide_start[at] = sample_start;
        for (int k = 0; k < GUIDE_CHANNELS; k++)
            m->guides[at * GUIDE_CHANNELS + k] = pixel[aov[k]];
    }
    /* As render.c makes variance.Y: E[L^2] - E[L]^2 of float luminances. */
    float luminance = luminance_float(pixel[channel[0]], pixel[channel[1]], pixel[channel[2]]);
    double *aov_sum = &m->aov_sums[at * 4];
    aov_sum[3] += n * ((double)pixel[aov[7]] + (double)luminance * luminance);
    for (int c = 0; has_emission && c < 3; c++)
        aov_sum[c] += (double)pixel[aov[8 + c]] * n;
}

/* Checks a part on its own: pixels, its R, G, B and samples channels (their indices into
 * channel), its spp, not post-processed, its data window within its full image (whose size goes
 * to *full_width, *full_height), finite sample counts. RT_ERROR_INPUT naming the part. */
static rt_status check_part(const char *name, const rt_image *image, const merge_metadata *metadata, int channel[4],
                            int *full_width, int *full_height, rt_error *error)
{
    if (image == NULL || image->pixels == NULL || image->width <= 0 || image->height <= 0)
        return rt_error_set(error, RT_ERROR_INPUT, "MERGE: '%s' has no pixels", name);
    static const char *const channel_names[4] = {"R", "G", "B", "samples"};
    for (int c = 0; c < 4; c++)
        channel[c] = image_channel_index(image, channel_names[c]);
    if (channel[0] < 0 || channel[1] < 0 || channel[2] < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "MERGE: '%s' lacks an R, G or B channel", name);
    if (channel[3] < 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' has no 'samples' channel, so its pixels cannot be weighted; merge EXR "
                            "parts written by rtspheres render", name);
    if (metadata->spp <= 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' has " METADATA_KEY_SPP " %lld; it must be at least 1", name, metadata->spp);
    /* A denoised (blurred, relit) colour weighted and summed would be neither the raw merge
     * nor its post-processed image. noisy.R: a --denoise render of before the postprocess key. */
    if (metadata->postprocess[0] != '\0')
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' is post-processed (" METADATA_KEY_POSTPROCESS " \"%s\"): its colour is no "
                            "longer the render's means; merge the raw parts (rendered with --aovs for `rtspheres "
                            "denoise`, --light-groups for `rtspheres relight`) and post-process the merge",
                            name, metadata->postprocess);
    if (image_channel_index(image, "noisy.R") >= 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' is denoised (it has noisy.R/G/B); merge raw parts (rendered with --aovs "
                            "rather than --denoise) and run `rtspheres denoise` on the merge", name);

    /* full_width 0 means the image is the full image. */
    *full_width = image->full_width > 0 ? image->full_width : image->width;
    *full_height = image->full_width > 0 ? image->full_height : image->height;
    /* In long long: a malformed file's window must not overflow the check itself. */
    if (image->x < 0 || image->y < 0 || (long long)image->x + image->width > *full_width
        || (long long)image->y + image->height > *full_height) {
        char window[96];
        return rt_error_set(error, RT_ERROR_INPUT, "MERGE: the data window of '%s' (%s) lies outside its %dx%d image",
                            name, describe_window(image->x, image->y, image->width, image->height, window,
                                                  sizeof window), *full_width, *full_height);
    }
    size_t pixel_count = (size_t)image->width * image->height;
    for (size_t i = 0; i < pixel_count; i++) {
        float n = image->pixels[i * image->channels + channel[3]];
        if (!(n >= 0.0f) || isinf(n))
            return rt_error_set(error, RT_ERROR_INPUT, "MERGE: '%s' has a sample count of %g at pixel (%d, %d)",
                                name, n, image->x + (int)(i % image->width), image->y + (int)(i / image->width));
    }
    return RT_OK;
}

rt_status merger_add(merger *m, const char *name, const rt_image *image, const merge_metadata *metadata,
                     rt_error *error)
{
    int channel[4], full_width = 0, full_height = 0;
    rt_status status = check_part(name, image, metadata, channel, &full_width, &full_height, error);
    if (status != RT_OK)
        return status;
    int region_index = 0;
    if (m->part_count > 0) {
        status = check_same_render(m, name, full_width, full_height, metadata, error);
        if (status != RT_OK)
            return status;
        status = place_part(m, name, image, metadata, &region_index, error);
        if (status != RT_OK)
            return status;
    }
    relight_layers layers = {0};
    status = find_light_groups(m, name, image, metadata, &layers, error);
    if (status != RT_OK)
        return status;

    /* Everything that can fail for lack of memory happens before the merger changes. */
    char *name_copy = strdup(name);
    if (name_copy == NULL
        || !array_reserve((void **)&m->parts, &m->part_capacity, (size_t)m->part_count + 1, sizeof *m->parts)
        || !array_reserve((void **)&m->regions, &m->region_capacity, (size_t)m->region_count + 1,
                          sizeof *m->regions)) {
        free(name_copy);
        return rt_error_set(error, RT_ERROR_RUNTIME, "MERGE: out of memory");
    }
    if (m->sums == NULL) {
        size_t full_pixels = (size_t)full_width * full_height;
        if (full_pixels > SIZE_MAX / (4 * sizeof(double)) || (m->sums = calloc(full_pixels * 4, sizeof(double))) == NULL) {
            free(name_copy);
            return rt_error_set(error, RT_ERROR_RUNTIME, "MERGE: out of memory for a %dx%d image", full_width,
                                full_height);
        }
        m->full_width = full_width;
        m->full_height = full_height;
    }
    int aov[AOV_ALL_CHANNELS];
    int aov_found = find_aov_channels(image, aov);
    bool has_aovs = aov_found >= AOV_CHANNELS, has_emission = aov_found == AOV_ALL_CHANNELS;
    if (has_aovs && !reserve_aov_sums(m, (size_t)full_width * full_height)) {
        free(name_copy);
        return rt_error_set(error, RT_ERROR_RUNTIME, "MERGE: out of memory for the AOV layers");
    }
    if (m->layer_sums == NULL && layers.count > 0) {
        size_t full_values = (size_t)full_width * full_height * 3 * (size_t)layers.count;
        if ((m->layer_sums = calloc(full_values, sizeof(double))) == NULL) {
            free(name_copy);
            return rt_error_set(error, RT_ERROR_RUNTIME, "MERGE: out of memory for %d light group layers",
                                layers.count);
        }
        m->layers = layers;
    }

    if (region_index == m->region_count) {
        m->regions[m->region_count++] = (region){.x = image->x, .y = image->y, .width = image->width,
                                                 .height = image->height, .first_part = m->part_count};
    }
    m->parts[m->part_count++] = (part_record){.name = name_copy, .metadata = *metadata, .region = region_index};
    m->aov_parts += has_aovs;
    m->emission_parts += has_emission;

    for (int row = 0; row < image->height; row++)
        for (int column = 0; column < image->width; column++) {
            const float *pixel = &image->pixels[((size_t)row * image->width + column) * image->channels];
            double n = pixel[channel[3]];
            if (n == 0)
                continue;  /* nothing rendered here; its colour means nothing */
            size_t at = (size_t)(image->y + row) * full_width + image->x + column;
            double *sum = &m->sums[at * 4];
            for (int c = 0; c < 3; c++)
                sum[c] += (double)pixel[channel[c]] * n;
            sum[3] += n;
            double *layer_sum = m->layer_sums + at * 3 * (size_t)layers.count;
            for (int g = 0; g < layers.count; g++)
                for (int c = 0; c < 3; c++)
                    layer_sum[3 * g + c] += (double)pixel[layers.channels[g][c]] * n;
            if (has_aovs)
                add_aov_pixel(m, at, pixel, channel, aov, has_emission, metadata->sample_start, n);
        }
    return RT_OK;
}

/* Orders sample ranges by start, for qsort. */
static int compare_ranges(const void *a, const void *b)
{
    const sample_range *x = a, *y = b;
    return x->start < y->start ? -1 : x->start > y->start;
}

/* Collects the sample ranges of region r's parts into ranges (room for m->part_count),
 * sorted and with touching ranges joined. Returns how many remain: 1 when contiguous. */
static int region_ranges(const merger *m, int r, sample_range *ranges)
{
    int count = 0;
    for (int p = 0; p < m->part_count; p++)
        if (m->parts[p].region == r)
            ranges[count++] = (sample_range){m->parts[p].metadata.sample_start,
                                             (unsigned long long)m->parts[p].metadata.spp};
    qsort(ranges, (size_t)count, sizeof *ranges, compare_ranges);
    int joined = 0;
    for (int i = 0; i < count; i++) {
        if (joined > 0 && ranges[joined - 1].start + ranges[joined - 1].count == ranges[i].start)
            ranges[joined - 1].count += ranges[i].count;
        else
            ranges[joined++] = ranges[i];
    }
    return joined;
}

/* Formats joined ranges as "0:16" or "0:8 and 12:4" into text (size bytes). */
static const char *describe_ranges(const sample_range *ranges, int count, char *text, size_t size)
{
    size_t used = 0;
    text[0] = '\0';
    for (int i = 0; i < count && used < size; i++) {
        int n = snprintf(text + used, size - used, "%s%llu:%llu", i == 0 ? "" : " and ", ranges[i].start,
                         ranges[i].count);
        if (n < 0)
            break;
        used += (size_t)n;
    }
    return text;
}

/* Adds a warning to the summary; those beyond MERGE_MAX_WARNINGS are only counted. */
static void add_warning(merge_summary *summary, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void add_warning(merge_summary *summary, const char *format, ...)
{
    if (summary->warning_count < MERGE_MAX_WARNINGS) {
        va_list arguments;
        va_start(arguments, format);
        vsnprintf(summary->warnings[summary->warning_count], MERGE_WARNING_MAX, format, arguments);
        va_end(arguments);
    }
    summary->warning_count++;
}

/* Counts the pixels of the full image no region covers, and describes where they are:
 * runs of rows holding uncovered pixels with the columns they span, at most three.
 * Returns the count; text gets "" when it is 0. covered: full_width*full_height bytes. */
static long long describe_missing(const merger *m, const unsigned char *covered, char *text, size_t size)
{
    long long missing = 0;
    int runs = 0;
    size_t used = 0;
    text[0] = '\0';
    int run_first = -1, run_x0 = 0, run_x1 = 0;
    for (int y = 0; y <= m->full_height; y++) {
        int x0 = -1, x1 = -1;
        if (y < m->full_height)
            for (int x = 0; x < m->full_width; x++)
                if (!covered[(size_t)y * m->full_width + x]) {
                    missing++;
                    if (x0 < 0)
                        x0 = x;
                    x1 = x;
                }
        if (x0 >= 0 && run_first < 0) {
            run_first = y;
            run_x0 = x0;
            run_x1 = x1;
        } else if (x0 >= 0) {
            run_x0 = x0 < run_x0 ? x0 : run_x0;
            run_x1 = x1 > run_x1 ? x1 : run_x1;
        } else if (run_first >= 0) {
            if (runs < 3 && used < size) {
                int n = snprintf(text + used, size - used, "%srows %d-%d (columns %d-%d)", runs ? "; " : "",
                                 run_first, y - 1, run_x0, run_x1);
                used += n > 0 ? (size_t)n : 0;
            }
            runs++;
            run_first = -1;
        }
    }
    if (runs > 3 && used < size)
        snprintf(text + used, size - used, "; and %d more", runs - 3);
    return missing;
}

rt_status merger_finish(merger *m, const merge_options *options, rt_image *out, merge_summary *summary,
                        rt_error *error)
{
    memset(out, 0, sizeof *out);
    memset(summary, 0, sizeof *summary);
    merge_options defaults = merge_options_defaults();
    if (options == NULL)
        options = &defaults;
    if (m->part_count == 0)
        return rt_error_set(error, RT_ERROR_INPUT, "MERGE: no parts to merge");

    size_t full_pixels = (size_t)m->full_width * m->full_height;
    unsigned char *covered = calloc(full_pixels, 1);
    sample_range *ranges = malloc((size_t)m->part_count * sizeof *ranges);
    sample_range *first_ranges = malloc((size_t)m->part_count * sizeof *first_ranges);
    if (covered == NULL || ranges == NULL || first_ranges == NULL) {
        free(covered);
        free(ranges);
        free(first_ranges);
        return rt_error_set(error, RT_ERROR_RUNTIME, "MERGE: out of memory");
    }
    for (int r = 0; r < m->region_count; r++) {
        const region *area = &m->regions[r];
        for (int y = area->y; y < area->y + area->height; y++)
            memset(&covered[(size_t)y * m->full_width + area->x], 1, (size_t)area->width);
    }
    char where[512];
    long long missing = describe_missing(m, covered, where, sizeof where);
    free(covered);
    if (missing > 0 && !options->allow_missing) {
        free(ranges);
        free(first_ranges);
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: missing pieces: %lld pixel%s of the %dx%d image not covered by any part, e.g. %s",
                            missing, missing == 1 ? "" : "s", m->full_width, m->full_height, where);
    }

    bool complete = missing == 0;
    for (int p = 0; p < m->part_count; p++)
        complete = complete && m->parts[p].metadata.complete;
    int first_count = region_ranges(m, 0, first_ranges);
    complete = complete && first_count == 1;
    for (int r = 1; r < m->region_count; r++) {
        int count = region_ranges(m, r, ranges);
        complete = complete && count == 1;
        bool same = count == first_count && memcmp(ranges, first_ranges, (size_t)count * sizeof *ranges) == 0;
        if (!same) {
            char this_window[96], first_window[96], this_ranges[160], first_text[160];
            const region *area = &m->regions[r], *first = &m->regions[0];
            add_warning(summary,
                        "the region %s ('%s') has samples %s but the region %s ('%s') has samples %s; the merged "
                        "image has different sample counts there (the samples channel says how many)",
                        describe_window(area->x, area->y, area->width, area->height, this_window, sizeof this_window),
                        m->parts[area->first_part].name, describe_ranges(ranges, count, this_ranges, sizeof this_ranges),
                        describe_window(first->x, first->y, first->width, first->height, first_window,
                                        sizeof first_window),
                        m->parts[first->first_part].name,
                        describe_ranges(first_ranges, first_count, first_text, sizeof first_text));
            complete = false;
        }
    }
    free(ranges);
    free(first_ranges);
    if (m->aov_parts > 0 && m->aov_parts < m->part_count)
        add_warning(summary, "%d of the %d parts have AOV layers (render --aovs): the merged image has none",
                    m->aov_parts, m->part_count);
    else if (m->emission_parts > 0 && m->emission_parts < m->part_count)
        add_warning(summary, "%d of the %d parts have emission.R/G/B (a resumed part has none): the merged image "
                    "has none, and `rtspheres denoise` filters the lights' edges with the rest",
                    m->emission_parts, m->part_count);

    rt_status status = image_create(out, m->full_width, m->full_height, 4, error);
    if (status != RT_OK)
        return status;
    static const char *const names[4] = {"R", "G", "B", "samples"};
    for (int c = 0; c < 4; c++)
        snprintf(out->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
    double min_samples = INFINITY, max_samples = 0, total_samples = 0;
    for (size_t i = 0; i < full_pixels; i++) {
        const double *sum = &m->sums[i * 4];
        float *pixel = &out->pixels[i * 4];
        double n = sum[3];
        if (n > 0)
            for (int c = 0; c < 3; c++)
                pixel[c] = (float)(sum[c] / n);
        pixel[3] = (float)n;
        min_samples = n < min_samples ? n : min_samples;
        max_samples = n > max_samples ? n : max_samples;
        total_samples += n;
    }

    summary->part_count = m->part_count;
    summary->region_count = m->region_count;
    summary->full_width = m->full_width;
    summary->full_height = m->full_height;
    summary->min_samples = (long long)min_samples;
    summary->max_samples = (long long)max_samples;
    summary->total_samples = total_samples;
    summary->missing_pixels = missing;
    summary->complete = complete;
    summary->metadata = m->parts[0].metadata;
    summary->sample_start = m->parts[0].metadata.sample_start;
    for (int p = 0; p < m->part_count; p++) {
        const merge_metadata *part = &m->parts[p].metadata;
        if (part->sample_start < summary->sample_start)
            summary->sample_start = part->sample_start;
        summary->render_seconds += part->render_seconds;
        summary->path_segments += part->path_segments;
    }
    return RT_OK;
}

rt_status merger_light_groups(const merger *m, rt_image *layers, rt_error *error)
{
    memset(layers, 0, sizeof *layers);
    int count = m->layers.count;
    if (count == 0 || m->layer_sums == NULL)
        return RT_OK;
    rt_status status = image_create(layers, m->full_width, m->full_height, 3 * count, error);
    if (status != RT_OK)
        return status;
    static const char channels[3] = {'R', 'G', 'B'};
    for (int g = 0; g < count; g++)
        for (int c = 0; c < 3; c++)
            snprintf(layers->channel_names[3 * g + c], IMAGE_CHANNEL_NAME_MAX, "%s.%c", m->layers.names[g],
                     channels[c]);
    size_t values = 3 * (size_t)count;
    for (size_t i = 0; i < (size_t)m->full_width * m->full_height; i++) {
        double n = m->sums[i * 4 + 3];
        for (size_t v = 0; v < values; v++)
            layers->pixels[i * values + v] = n > 0 ? (float)(m->layer_sums[i * values + v] / n) : 0.0f;
    }
    return RT_OK;
}

rt_status merger_aovs(const merger *m, rt_image *aovs, rt_error *error)
{
    memset(aovs, 0, sizeof *aovs);
    if (m->part_count == 0 || m->aov_parts != m->part_count)
        return RT_OK;
    int channels = m->emission_parts == m->part_count ? AOV_ALL_CHANNELS : AOV_CHANNELS;
    rt_status status = image_create(aovs, m->full_width, m->full_height, channels, error);
    if (status != RT_OK)
        return status;
    for (int c = 0; c < channels; c++)
        snprintf(aovs->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", aov_names[c]);
    for (size_t i = 0; i < (size_t)m->full_width * m->full_height; i++) {
        float *out = aovs->pixels + i * (size_t)channels;
        double n = m->sums[i * 4 + 3];
        if (n <= 0)
            continue;
        memcpy(out, m->guides + i * GUIDE_CHANNELS, GUIDE_CHANNELS * sizeof *out);
        float mean[3];
        for (int c = 0; c < 3; c++)
            mean[c] = (float)(m->sums[i * 4 + c] / n);
        float luminance = luminance_float(mean[0], mean[1], mean[2]);
        out[7] = (float)fmax(0.0, m->aov_sums[i * 4 + 3] / n - (double)luminance * luminance);
        for (int c = 0; c < channels - AOV_CHANNELS; c++)
            out[AOV_CHANNELS + c] = (float)(m->aov_sums[i * 4 + c] / n);
    }
    return RT_OK;
}

/* Reads the attribute name of path as text into value. Returns RT_OK, or RT_ERROR_INPUT
 * saying the file is not an rtspheres part when required and absent; an absent optional
 * attribute leaves value "" and returns RT_OK. */
static rt_status read_text(const char *path, const char *name, bool required, char *value, int size,
                           rt_error *error)
{
    if (image_read_attribute(path, name, value, size, NULL) == RT_OK)
        return RT_OK;
    value[0] = '\0';
    if (!required)
        return RT_OK;
    return rt_error_set(error, RT_ERROR_INPUT,
                        "MERGE: '%s' has no %s metadata; merge EXR parts written by rtspheres render", path, name);
}

/* Parses all of text as a whole number in [minimum, maximum] into *value; on failure sets
 * the error naming the file and attribute. */
static rt_status parse_whole(const char *path, const char *name, const char *text, long long minimum,
                             unsigned long long maximum, unsigned long long *value, long long *signed_value,
                             rt_error *error)
{
    char *end = NULL;
    errno = 0;
    bool negative = text[0] == '-';
    long long parsed_signed = 0;
    unsigned long long parsed = 0;
    if (negative)
        parsed_signed = strtoll(text, &end, 10);
    else
        parsed = strtoull(text, &end, 10);
    bool ok = end != text && *end == '\0' && errno == 0
              && (negative ? parsed_signed >= minimum
                           : parsed <= maximum && (minimum <= 0 || parsed >= (unsigned long long)minimum));
    if (!ok)
        return rt_error_set(error, RT_ERROR_INPUT, "MERGE: '%s' has %s '%s'; expected a whole number", path, name,
                            text);
    if (value != NULL)
        *value = negative ? 0 : parsed;
    if (signed_value != NULL)
        *signed_value = negative ? parsed_signed : (long long)parsed;
    return RT_OK;
}

rt_status merge_read_part(const char *path, rt_image *image, merge_metadata *metadata, rt_error *error)
{
    memset(metadata, 0, sizeof *metadata);
    rt_status status = image_read(path, image, error);
    if (status != RT_OK)
        return status;
    if (image_channel_index(image, "samples") < 0) {
        image_free(image);
        return rt_error_set(error, RT_ERROR_INPUT,
                            "MERGE: '%s' has no 'samples' channel, so its pixels cannot be weighted; merge EXR "
                            "parts written by rtspheres render", path);
    }
    char text[MERGE_TEXT_MAX];
    long long number;
    unsigned long long whole;
    /* scene_hash first: when it is absent the file is no rtspheres part at all. */
    if ((status = read_text(path, METADATA_KEY_SCENE_HASH, true, metadata->scene_hash, MERGE_TEXT_MAX, error))
            != RT_OK
        || (status = read_text(path, METADATA_KEY_SCENE, false, metadata->scene, MERGE_TEXT_MAX, error)) != RT_OK
        || (status = read_text(path, METADATA_KEY_SEED, true, text, sizeof text, error)) != RT_OK
        || (status = parse_whole(path, METADATA_KEY_SEED, text, 0, UINT32_MAX, &metadata->seed, NULL, error))
               != RT_OK
        || (status = read_text(path, METADATA_KEY_MAX_DEPTH, true, text, sizeof text, error)) != RT_OK
        || (status = parse_whole(path, METADATA_KEY_MAX_DEPTH, text, 1, INT32_MAX, NULL, &number, error)) != RT_OK)
        goto failed;
    metadata->max_depth = (int)number;
    if ((status = read_text(path, METADATA_KEY_FRAME, true, text, sizeof text, error)) != RT_OK
        || (status = parse_whole(path, METADATA_KEY_FRAME, text, -1, INT32_MAX, NULL, &number, error)) != RT_OK)
        goto failed;
    metadata->frame = (int)number;
    if ((status = read_text(path, METADATA_KEY_SAMPLE_START, true, text, sizeof text, error)) != RT_OK
        || (status = parse_whole(path, METADATA_KEY_SAMPLE_START, text, 0, UINT32_MAX, &metadata->sample_start,
                                 NULL, error)) != RT_OK
        || (status = read_text(path, METADATA_KEY_SPP, true, text, sizeof text, error)) != RT_OK
        || (status = parse_whole(path, METADATA_KEY_SPP, text, 1, UINT32_MAX, NULL, &metadata->spp, error)) != RT_OK
        || (status = read_text(path, METADATA_KEY_COMPLETE, true, text, sizeof text, error)) != RT_OK
        || (status = parse_whole(path, METADATA_KEY_COMPLETE, text, 0, 1, &whole, NULL, error)) != RT_OK)
        goto failed;
    metadata->complete = whole == 1;
    /* Only carried into the merged file's totals; a part without them still merges. */
    read_text(path, METADATA_KEY_RENDER_SECONDS, false, text, sizeof text, NULL);
    metadata->render_seconds = text[0] ? strtod(text, NULL) : 0;
    read_text(path, METADATA_KEY_PATH_SEGMENTS, false, text, sizeof text, NULL);
    metadata->path_segments = text[0] ? strtod(text, NULL) : 0;
    read_text(path, METADATA_KEY_LIGHT_GROUPS, false, metadata->light_groups, MERGE_LIGHT_GROUPS_MAX, NULL);
    read_text(path, METADATA_KEY_POSTPROCESS, false, metadata->postprocess, MERGE_TEXT_MAX, NULL);
    return RT_OK;

failed:
    image_free(image);
    return status;
}
