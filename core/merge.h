/* merge.h: combines EXR parts of one render (sample ranges, tiles, crops, shards) into
 * the full image, exactly. Plain C on rt_image arrays; never prints, never exits.
 *
 * A part is an image with channels R, G, B (the mean radiance of its samples) and
 * `samples` (per-pixel count of finished samples), placed in the full image by its data
 * window (rt_image x, y, full_width, full_height), plus the rtspheres metadata that says
 * which render it belongs to (merge_metadata).
 *
 * The rules:
 *   - Every part must agree with the first on full image size, seed, max depth, frame and
 *     scene hash; otherwise RT_ERROR_INPUT naming both parts and both values.
 *   - Parts with the same data window are sample-range parts of one region. Their sample
 *     ranges [sample_start, sample_start + spp) must not intersect (the same samples
 *     would count twice). Per pixel: colour = sum(colour_i * n_i) / sum(n_i) in double,
 *     samples = sum(n_i); a pixel with no samples stays 0.
 *   - Regions with different data windows must not intersect. Pixels no region covers
 *     are an error ("missing pieces: ...") unless allow_missing is set; they stay 0 with
 *     0 samples.
 *   - A region whose set of sample ranges differs from the first region's is a warning
 *     (merge_summary.warnings), not an error: its per-pixel counts stay right.
 *   - The summary's complete is true only when every part is complete, each region's
 *     sample ranges are contiguous, every region has the same ranges and every pixel is
 *     covered.
 *   - Light group layers (render --light-groups: NAME.R/G/B per group, the groups listed
 *     in rtspheres:light_groups) are merged as the colour is, weighted by the samples of
 *     each pixel and put in place by region, so that they still sum to the merged colour
 *     (to float rounding) and a tile's are exactly the whole render's. Every part must
 *     list the same groups as the first, or none when it lists none: RT_ERROR_INPUT
 *     otherwise.
 *   - AOV layers (render --aovs: albedo.R/G/B, normal.X/Y/Z, depth.Z, variance.Y, and
 *     emission.R/G/B but after --resume) are merged when every part has them, for
 *     `rtspheres denoise` of the merged image: the guides (albedo, normal, depth) of each
 *     pixel are those of the part with the lowest sample start that has samples there
 *     (a render's guides come from its first samples' camera rays, so a split render's
 *     are the whole render's), emission is weighted by samples as the colour is, and
 *     variance.Y is recombined from each part's: E[L^2] - E[L]^2 with each part's
 *     E[L^2] = variance.Y + L^2 (L its mean luminance), to float rounding of the whole
 *     render's. Some parts without them: a warning, and no AOV layers. variance.R/G/B
 *     (--variance) are not merged.
 *   - A denoised part (it has noisy.R/G/B: render --denoise, `rtspheres denoise`) is
 *     RT_ERROR_INPUT: merge the raw parts and denoise the merge.
 *
 * Use: merger_create, merger_add once per part (it validates the part against the ones
 * added before and adds its pixels to running double sums, so the caller may free the
 * part's pixels at once and a farm's parts never all sit in memory), merger_finish,
 * merger_free. merge_read_part reads a part file with its metadata.
 */
#ifndef RT_MERGE_H
#define RT_MERGE_H

#include <stdbool.h>

#include "image_io.h"
#include "relight.h"
#include "status.h"

#define MERGE_TEXT_MAX 512
#define MERGE_MAX_WARNINGS 8
#define MERGE_WARNING_MAX 512
#define MERGE_LIGHT_GROUPS_MAX (SCENE_LIGHT_GROUP_MAX * SCENE_NAME_MAX)

/* The rtspheres:* metadata of one part that the merge checks or carries over (the keys
 * and what they hold: metadata_keys.h). */
typedef struct merge_metadata {
    char scene[MERGE_TEXT_MAX];          /* rtspheres:scene, the scene file's path */
    char scene_hash[MERGE_TEXT_MAX];     /* rtspheres:scene_hash */
    unsigned long long seed;             /* rtspheres:seed */
    int max_depth;                       /* rtspheres:max_depth */
    int frame;                           /* rtspheres:frame, -1 without --frames */
    unsigned long long sample_start;     /* rtspheres:sample_start */
    long long spp;                       /* rtspheres:spp: the samples the part was asked for */
    bool complete;                       /* rtspheres:complete */
    double render_seconds;               /* rtspheres:render_seconds, 0 when absent */
    double path_segments;                /* rtspheres:path_segments, 0 when absent */
    char light_groups[MERGE_LIGHT_GROUPS_MAX];   /* rtspheres:light_groups, "" when absent */
    char postprocess[MERGE_TEXT_MAX];    /* rtspheres:postprocess, "" when absent (a raw part) */
} merge_metadata;

typedef struct merge_options {
    bool allow_missing;                  /* uncovered pixels are not an error */
} merge_options;

/* What merger_finish found, besides the image. */
typedef struct merge_summary {
    int part_count;
    int region_count;
    int full_width, full_height;
    long long min_samples;               /* smallest per-pixel sample count of the full image */
    long long max_samples;
    double total_samples;                /* sum of the samples channel */
    unsigned long long sample_start;     /* lowest sample_start of any part */
    bool complete;                       /* see the rules above */
    long long missing_pixels;            /* uncovered pixels (only with allow_missing) */
    merge_metadata metadata;             /* the common values, from the first part */
    double render_seconds;               /* sums over the parts */
    double path_segments;
    int warning_count;                   /* may exceed MERGE_MAX_WARNINGS; the rest are dropped */
    char warnings[MERGE_MAX_WARNINGS][MERGE_WARNING_MAX];
} merge_summary;

typedef struct merger merger;

/* Returns options with every field at its default (all false). */
merge_options merge_options_defaults(void);

/* Creates an empty merger into *out. Returns RT_ERROR_RUNTIME when memory runs out.
 * Free with merger_free(). */
rt_status merger_create(merger **out, rt_error *error);

/* Frees the merger and everything it holds; NULL is allowed. */
void merger_free(merger *m);

/* Checks part image (named name in messages) with its metadata against the parts added
 * before and adds its pixels to the sums. The image must have channels named R, G, B and
 * samples. Returns RT_ERROR_INPUT naming both parts on a mismatch or overlap (the merger
 * is then unchanged and should be freed), RT_ERROR_RUNTIME when memory runs out. The
 * merger keeps copies of name and metadata, not the image: the caller still owns it. */
rt_status merger_add(merger *m, const char *name, const rt_image *image, const merge_metadata *metadata,
                     rt_error *error);

/* Assembles the full image into *out (channels R, G, B, samples; no data-window offset;
 * allocated, free with image_free()) and fills *summary. options may be NULL. No parts,
 * or missing pieces without allow_missing: RT_ERROR_INPUT; out is then left empty. */
rt_status merger_finish(merger *m, const merge_options *options, rt_image *out, merge_summary *summary,
                        rt_error *error);

/* Returns the merged light group layers into *layers (NAME.R/G/B for each group of
 * summary.metadata.light_groups in that order, full size; allocated, free with
 * image_free()) after a successful merger_finish(); empty (RT_OK) when the parts have no
 * layers. RT_ERROR_RUNTIME when memory runs out. */
rt_status merger_light_groups(const merger *m, rt_image *layers, rt_error *error);

/* Returns the merged AOV layers into *aovs (albedo.R/G/B, normal.X/Y/Z, depth.Z,
 * variance.Y and, when every part had it, emission.R/G/B; full size; allocated, free with
 * image_free()) after a successful merger_finish(); empty (RT_OK) unless every part had
 * AOV layers. RT_ERROR_RUNTIME when memory runs out. */
rt_status merger_aovs(const merger *m, rt_image *aovs, rt_error *error);

/* Reads the part file at path: its pixels into *image (allocated; free with image_free())
 * and its rtspheres metadata into *metadata. A file that cannot be read, lacks the
 * rtspheres metadata or the `samples` channel is RT_ERROR_INPUT naming the file; *image
 * is then empty. */
rt_status merge_read_part(const char *path, rt_image *image, merge_metadata *metadata, rt_error *error);

#endif
