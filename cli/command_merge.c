/* command_merge.c: `rtspheres merge PARTS... -o OUT.exr`: combines EXR parts of one render
 * (sample ranges, tiles, crops, shards) into the full image with core/merge.h, and writes
 * it with the merged metadata. Parts are read one at a time and freed once summed, so a
 * farm's parts never all sit in memory. Exit codes: 0 ok, 1 runtime (write failed, out of
 * memory), 2 bad input (mismatched, overlapping or missing parts, unreadable files). */
#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "commands.h"
#include "image_io.h"
#include "merge.h"
#include "version.h"

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres merge PARTS... -o OUTPUT [options]\n"
            "\n"
            "Merges EXR parts of one render (written by `rtspheres render` with --samples,\n"
            "--crop, --tile or --shard) into the full image. Parts with the same region are\n"
            "combined weighted by their per-pixel sample counts; regions are put in place by\n"
            "their data windows. Parts must share scene, size, seed, max depth and frame; sample\n"
            "ranges of one region must not overlap, regions must not overlap, and every pixel\n"
            "must be covered.\n"
            "\n"
            "options:\n"
            "  -o, --output FILE   the merged image (.exr keeps the samples channel and metadata;\n"
            "                      .png/.jpg/.tif/.hdr get the colour only)\n"
            "      --allow-missing pixels no part covers stay black with 0 samples\n"
            "  -q, --quiet         no summary line\n"
            "  -h, --help          this text\n"
            "\n"
            "exit status: 0 ok, 1 runtime failure, 2 bad input (mismatched, overlapping or\n"
            "missing parts, unreadable files)\n");
}

/* True when the two paths name the same existing file. */
static bool same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* Returns path's extension including the dot, or "" when its last component has none. */
static const char *extension_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot != NULL && strchr(dot, '/') == NULL ? dot : "";
}

static bool is_exr(const char *path)
{
    return strcasecmp(extension_of(path), ".exr") == 0;
}

/* True for the formats image_write knows, so a bad -o is refused before any part is read. */
static bool known_output(const char *path)
{
    static const char *const extensions[] = {".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    for (size_t i = 0; i < sizeof extensions / sizeof extensions[0]; i++)
        if (strcasecmp(extension_of(path), extensions[i]) == 0)
            return true;
    return false;
}

/* Writes merged to output: all four channels and the metadata for EXR, colour only for
 * the 8-bit and HDR formats (which cannot hold a sample count). Returns an exit code. */
static int write_merged(const char *output, const rt_image *merged, const merge_summary *summary)
{
    rt_error error = {{0}};
    rt_image rgb = {0};
    const rt_image *image = merged;
    if (!is_exr(output)) {
        if (image_create(&rgb, merged->width, merged->height, 3, &error) != RT_OK) {
            fprintf(stderr, "rtspheres merge: %s\n", error.message);
            return EXIT_RUNTIME;
        }
        size_t pixel_count = (size_t)rgb.width * rgb.height;
        for (size_t i = 0; i < pixel_count; i++)
            for (int c = 0; c < 3; c++)
                rgb.pixels[3 * i + c] = merged->pixels[4 * i + c];
        image = &rgb;
    }
    /* Numbers that may pass 2^31 are written as text, as render does. */
    char seed_text[24], sample_start_text[24], samples_text[32], segments_text[32];
    snprintf(seed_text, sizeof seed_text, "%llu", summary->metadata.seed);
    snprintf(sample_start_text, sizeof sample_start_text, "%llu", summary->sample_start);
    snprintf(samples_text, sizeof samples_text, "%.0f", summary->total_samples);
    snprintf(segments_text, sizeof segments_text, "%.0f", summary->path_segments);
    image_attribute attributes[] = {
        {.name = "rtspheres:version", .type = IMAGE_ATTRIBUTE_STRING, .string_value = RTSPHERES_VERSION},
        {.name = "rtspheres:scene", .type = IMAGE_ATTRIBUTE_STRING, .string_value = summary->metadata.scene},
        {.name = "rtspheres:scene_hash", .type = IMAGE_ATTRIBUTE_STRING, .string_value = summary->metadata.scene_hash},
        {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = summary->min_samples},
        {.name = "rtspheres:sample_start", .type = IMAGE_ATTRIBUTE_STRING, .string_value = sample_start_text},
        {.name = "rtspheres:seed", .type = IMAGE_ATTRIBUTE_STRING, .string_value = seed_text},
        {.name = "rtspheres:max_depth", .type = IMAGE_ATTRIBUTE_INT, .int_value = summary->metadata.max_depth},
        {.name = "rtspheres:frame", .type = IMAGE_ATTRIBUTE_INT, .int_value = summary->metadata.frame},
        {.name = "rtspheres:samples_finished", .type = IMAGE_ATTRIBUTE_STRING, .string_value = samples_text},
        {.name = "rtspheres:path_segments", .type = IMAGE_ATTRIBUTE_STRING, .string_value = segments_text},
        {.name = "rtspheres:complete", .type = IMAGE_ATTRIBUTE_INT, .int_value = summary->complete},
        {.name = "rtspheres:render_seconds", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = summary->render_seconds},
        {.name = "rtspheres:merged_parts", .type = IMAGE_ATTRIBUTE_INT, .int_value = summary->part_count},
    };
    image_write_options options = image_write_options_defaults();
    options.attributes = attributes;
    options.attribute_count = (int)(sizeof attributes / sizeof attributes[0]);
    rt_status status = image_write(output, image, &options, &error);
    image_free(&rgb);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres merge: %s\n", error.message);
        return exit_code_for_status(status);
    }
    return EXIT_OK;
}

int command_merge(int argc, char **argv)
{
    enum { OPTION_ALLOW_MISSING = 256 };
    static const struct option long_options[] = {
        {"output", required_argument, NULL, 'o'},
        {"allow-missing", no_argument, NULL, OPTION_ALLOW_MISSING},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char *output = NULL;
    bool quiet = false;
    merge_options options = merge_options_defaults();
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, "o:qh", long_options, NULL)) != -1) {
        switch (option) {
        case 'o': output = optarg; break;
        case OPTION_ALLOW_MISSING: options.allow_missing = true; break;
        case 'q': quiet = true; break;
        case 'h': print_help(stdout); return EXIT_OK;
        default: print_help(stderr); return EXIT_BAD_INPUT;
        }
    }
    if (output == NULL) {
        fprintf(stderr, "rtspheres merge: no output; give -o FILE.exr\n");
        return EXIT_BAD_INPUT;
    }
    if (!known_output(output)) {
        fprintf(stderr, "rtspheres merge: cannot tell the format of '%s'; use .exr (or .hdr, .png, .jpg, .tif for "
                        "the colour only)\n", output);
        return EXIT_BAD_INPUT;
    }
    if (optind >= argc) {
        fprintf(stderr, "rtspheres merge: no parts to merge; give the part files before or after -o\n");
        return EXIT_BAD_INPUT;
    }
    char **parts = argv + optind;
    int part_count = argc - optind;
    for (int i = 0; i < part_count; i++) {
        if (strcmp(parts[i], output) == 0 || same_file(parts[i], output)) {
            fprintf(stderr, "rtspheres merge: the output '%s' is one of the parts; refusing to overwrite it\n",
                    output);
            return EXIT_BAD_INPUT;
        }
        for (int j = 0; j < i; j++)
            if (strcmp(parts[i], parts[j]) == 0 || same_file(parts[i], parts[j])) {
                fprintf(stderr, "rtspheres merge: '%s' and '%s' are the same file; its samples would count twice\n",
                        parts[j], parts[i]);
                return EXIT_BAD_INPUT;
            }
    }

    merger *m = NULL;
    rt_error error = {{0}};
    rt_status status = merger_create(&m, &error);
    for (int i = 0; i < part_count && status == RT_OK; i++) {
        rt_image part;
        merge_metadata metadata;
        status = merge_read_part(parts[i], &part, &metadata, &error);
        if (status == RT_OK) {
            status = merger_add(m, parts[i], &part, &metadata, &error);
            image_free(&part);
        }
    }
    rt_image merged = {0};
    merge_summary summary;
    if (status == RT_OK)
        status = merger_finish(m, &options, &merged, &summary, &error);
    merger_free(m);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres merge: %s\n", error.message);
        return exit_code_for_status(status);
    }
    int shown = summary.warning_count < MERGE_MAX_WARNINGS ? summary.warning_count : MERGE_MAX_WARNINGS;
    for (int i = 0; i < shown; i++)
        fprintf(stderr, "rtspheres merge: warning: %s\n", summary.warnings[i]);
    if (summary.warning_count > shown)
        fprintf(stderr, "rtspheres merge: warning: and %d more like these\n", summary.warning_count - shown);
    if (summary.missing_pixels > 0)
        fprintf(stderr, "rtspheres merge: warning: %lld pixels not covered by any part are left black "
                        "(--allow-missing)\n", summary.missing_pixels);

    int exit_code = write_merged(output, &merged, &summary);
    image_free(&merged);
    if (exit_code == EXIT_OK && !quiet)
        fprintf(stderr, "rtspheres merge: %d part%s (%d region%s) -> %s: %dx%d, %lld to %lld samples per pixel%s\n",
                summary.part_count, summary.part_count == 1 ? "" : "s", summary.region_count,
                summary.region_count == 1 ? "" : "s", output, summary.full_width, summary.full_height,
                summary.min_samples, summary.max_samples, summary.complete ? ", complete" : ", not complete");
    return exit_code;
}
