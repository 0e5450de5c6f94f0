/* command_merge.c: `rtspheres merge PARTS... -o OUT.exr`: combines EXR parts of one render
 * (sample ranges, tiles, crops, shards) into the full image with core/merge.h, and writes
 * it with the merged metadata. Parts are read one at a time and freed once summed, so a
 * farm's parts never all sit in memory. Exit codes: 0 ok, 1 runtime (write failed, out of
 * memory), 2 bad input (mismatched, overlapping or missing parts, unreadable files). */
#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "image_io.h"
#include "merge.h"
#include "paths.h"
#include "render_output.h"

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
            "must be covered. Light group layers (--light-groups) are merged as the colour is.\n"
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

/* Writes merged to output with the merged metadata and layers (AOVs then light groups, as
 * a render writes them; render_output.h: all four channels and the layers for EXR, the
 * colour only for the 8-bit and HDR formats). Returns an exit code. */
static int write_merged(const char *output, const rt_image *merged, const rt_image *layers, bool light_groups,
                        const merge_summary *summary)
{
    render_output_metadata metadata = {
        .scene = summary->metadata.scene,
        .scene_hash = summary->metadata.scene_hash,
        .spp = summary->min_samples,
        .sample_start = summary->sample_start,
        .seed = summary->metadata.seed,
        .max_depth = summary->metadata.max_depth,
        .frame = summary->metadata.frame,
        .samples_finished = (unsigned long long)summary->total_samples,
        .path_segments = summary->path_segments,
        .complete = summary->complete,
        .render_seconds = summary->render_seconds,
        .merged_parts = summary->part_count,
        .light_groups = light_groups ? summary->metadata.light_groups : NULL,
    };
    rt_error error = {{0}};
    rt_status status = render_output_write(output, merged, layers, &metadata, 0.0f, &error);
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
        default: return command_help_exit(option, print_help);
        }
    }
    if (output == NULL) {
        fprintf(stderr, "rtspheres merge: no output; give -o FILE.exr\n");
        return EXIT_BAD_INPUT;
    }
    if (image_format_of(output) == IMAGE_FORMAT_UNKNOWN) {
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
        if (strcmp(parts[i], output) == 0 || path_same_file(parts[i], output)) {
            fprintf(stderr, "rtspheres merge: the output '%s' is one of the parts; refusing to overwrite it\n",
                    output);
            return EXIT_BAD_INPUT;
        }
        for (int j = 0; j < i; j++)
            if (strcmp(parts[i], parts[j]) == 0 || path_same_file(parts[i], parts[j])) {
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
    rt_image merged = {0}, layers = {0}, groups = {0};
    merge_summary summary;
    if (status == RT_OK)
        status = merger_finish(m, &options, &merged, &summary, &error);
    if (status == RT_OK)
        status = merger_aovs(m, &layers, &error);
    if (status == RT_OK)
        status = merger_light_groups(m, &groups, &error);
    bool has_groups = groups.pixels != NULL;
    if (status == RT_OK && has_groups && layers.pixels != NULL) {
        rt_image joined;
        status = image_append_channels(&layers, &groups, &joined, &error);
        if (status == RT_OK) {
            image_free(&layers);
            layers = joined;
        }
    } else if (status == RT_OK && has_groups) {
        layers = groups;
        groups = (rt_image){0};
    }
    image_free(&groups);
    merger_free(m);
    if (status != RT_OK) {
        image_free(&merged);
        image_free(&layers);
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

    int exit_code = write_merged(output, &merged, &layers, has_groups, &summary);
    image_free(&merged);
    image_free(&layers);
    if (exit_code == EXIT_OK && !quiet)
        fprintf(stderr, "rtspheres merge: %d part%s (%d region%s) -> %s: %dx%d, %lld to %lld samples per pixel%s\n",
                summary.part_count, summary.part_count == 1 ? "" : "s", summary.region_count,
                summary.region_count == 1 ? "" : "s", output, summary.full_width, summary.full_height,
                summary.min_samples, summary.max_samples, summary.complete ? ", complete" : ", not complete");
    return exit_code;
}
