/* command_relight.c: `rtspheres relight IN.exr -o OUT [--group NAME=SCALE|NAME=R,G,B]...`:
 * the weighted sum of an image's light group layers (core/relight.h), written as any
 * output format; 8-bit outputs are exposed and tone-mapped as renders are. Exit codes:
 * 0 ok, 1 runtime failure (write failed, out of memory), 2 bad input (usage, a file
 * without layers, a group the file has not). */
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "image_io.h"
#include "metadata_keys.h"
#include "paths.h"
#include "postprocess.h"
#include "relight.h"
#include "render_output.h"

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres relight IN.exr -o OUT [--group NAME=SCALE | NAME=R,G,B]... [options]\n"
            "\n"
            "Relights a render made with --light-groups: the image is the sum of its light\n"
            "group layers, each multiplied by its weight (1 unless --group says otherwise).\n"
            "Every weight 1 gives the render back; NAME=2 is the render with that group's\n"
            "lights twice as strong, NAME=1,0.5,0.2 tints them, NAME=0 turns them off.\n"
            "\n"
            "options:\n"
            "  -o, --output FILE    the relit image (.exr keeps the weighted layers; .hdr, .png,\n"
            "                       .jpg, .tif); never the input\n"
            "      --group NAME=W   the weight of light group NAME: a scale, or R,G,B\n"
            "      --exposure STOPS brighten 8-bit outputs by 2^STOPS (default 0)\n"
            "      --tonemap OP     for 8-bit outputs: clamp (default), reinhard or aces\n"
            "  -q, --quiet          no summary line\n"
            "  -h, --help           this text\n"
            "\n"
            "exit status: 0 ok, 1 runtime failure, 2 bad input (usage, a file without light\n"
            "group layers, a group the file does not have)\n");
}

/* Writes the relit image to output with metadata (the input's, render_output.h
 * render_output_derived_metadata): an EXR with its layers and their names, other formats
 * R, G, B only, 8-bit ones exposed and tone-mapped. */
static rt_status write_relit(const char *output, rt_image *relit, const relight_layers *layers,
                             image_attribute_set *metadata, postprocess_tonemap_operator tonemap, double exposure,
                             rt_error *error)
{
    image_format format = image_format_of(output);
    if (format != IMAGE_FORMAT_EXR) {
        image_attribute_set_remove(metadata, METADATA_KEY_LIGHT_GROUPS);   /* no layers there */
        return command_write_colour(output, relit, tonemap, exposure, metadata, error);
    }
    char groups[SCENE_LIGHT_GROUP_MAX * SCENE_NAME_MAX];
    relight_group_list(layers, groups, sizeof groups);
    image_attribute attribute = {.name = METADATA_KEY_LIGHT_GROUPS, .type = IMAGE_ATTRIBUTE_STRING,
                                 .string_value = groups};
    rt_status status = image_attribute_set_put(metadata, &attribute, error);
    image_write_options options = image_write_options_defaults();
    options.attributes = metadata->attributes;
    options.attribute_count = metadata->count;
    return status == RT_OK ? image_write(output, relit, &options, error) : status;
}

/* Parses the options into the outputs; returns EXIT_OK or an exit code after saying why. */
static int parse_options(int argc, char **argv, const char **output, relight_weight *weights, int *weight_count,
                         postprocess_tonemap_operator *tonemap, double *exposure, bool *quiet)
{
    enum { OPTION_GROUP = 256, OPTION_EXPOSURE, OPTION_TONEMAP };
    static const struct option long_options[] = {
        {"output", required_argument, NULL, 'o'},   {"group", required_argument, NULL, OPTION_GROUP},
        {"exposure", required_argument, NULL, OPTION_EXPOSURE}, {"tonemap", required_argument, NULL, OPTION_TONEMAP},
        {"quiet", no_argument, NULL, 'q'},          {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    optind = 1;
    int option;
    rt_error error = {{0}};
    while ((option = getopt_long(argc, argv, "o:qh", long_options, NULL)) != -1) {
        switch (option) {
        case 'o': *output = optarg; break;
        case 'q': *quiet = true; break;
        case OPTION_GROUP:
            if (*weight_count == SCENE_LIGHT_GROUP_MAX) {
                fprintf(stderr, "rtspheres relight: more than %d --group options\n", SCENE_LIGHT_GROUP_MAX);
                return EXIT_BAD_INPUT;
            }
            if (relight_parse_weight(optarg, &weights[*weight_count], &error) != RT_OK) {
                fprintf(stderr, "rtspheres relight: --group: %s\n", error.message);
                return EXIT_BAD_INPUT;
            }
            (*weight_count)++;
            break;
        case OPTION_EXPOSURE:
            if (command_parse_exposure("relight", optarg, exposure) != 0)
                return EXIT_BAD_INPUT;
            break;
        case OPTION_TONEMAP:
            if (command_parse_tonemap("relight", optarg, tonemap) != 0)
                return EXIT_BAD_INPUT;
            break;
        default: return command_help_exit(option, print_help);
        }
    }
    return EXIT_OK;
}

int command_relight(int argc, char **argv)
{
    const char *output = NULL;
    relight_weight weights[SCENE_LIGHT_GROUP_MAX];
    int weight_count = 0;
    postprocess_tonemap_operator tonemap = TONEMAP_CLAMP;
    double exposure = 0;
    bool quiet = false;
    int code = parse_options(argc, argv, &output, weights, &weight_count, &tonemap, &exposure, &quiet);
    if (code != EXIT_OK)
        return code;
    const char *input = NULL;
    code = command_image_to_image("relight", argc, argv, "an EXR rendered with --light-groups", output, &input);
    if (code != EXIT_OK)
        return code;
    rt_error error = {{0}};
    rt_image image = {0}, relit = {0};
    relight_layers layers;
    char groups[SCENE_LIGHT_GROUP_MAX * SCENE_NAME_MAX] = "";
    rt_status status = image_read(input, &image, &error);
    if (status == RT_OK && image_read_attribute(input, METADATA_KEY_LIGHT_GROUPS, groups, sizeof groups, &error) != RT_OK)
        status = rt_error_set(&error, RT_ERROR_INPUT,
                              "'%s' has no light group layers (no %s metadata); render it with --light-groups "
                              "to an .exr", input, METADATA_KEY_LIGHT_GROUPS);
    if (status == RT_OK)
        status = relight_find_layers(&image, groups, &layers, &error);
    if (status == RT_OK)
        status = relight_apply(&image, &layers, weights, weight_count, &relit, &error);
    image_free(&image);
    image_attribute_set metadata = {0};
    char step[SCENE_LIGHT_GROUP_MAX * (SCENE_NAME_MAX + 48) + 16];
    relight_describe(weights, weight_count, step, sizeof step);
    if (status == RT_OK)
        status = render_output_derived_metadata(input, step, &metadata, &error);
    if (status == RT_OK)
        status = write_relit(output, &relit, &layers, &metadata, tonemap, exposure, &error);
    image_attribute_set_free(&metadata);
    image_free(&relit);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres relight: %s\n", error.message);
        return exit_code_for_status(status);
    }
    if (!quiet)
        fprintf(stderr, "rtspheres relight: %s (%d light group%s: %s) -> %s\n", input, layers.count,
                layers.count == 1 ? "" : "s", groups, output);
    return EXIT_OK;
}
