/* command_denoise.c: `rtspheres denoise IN.exr -o OUT`: denoises an EXR rendered with
 * --aovs (core/render_denoise.h) as `render --denoise` would have, for the renders that
 * cannot denoise themselves (a farm's parts, merged) or whose denoised image is wanted
 * beside the raw one. Exit codes: 0 ok, 1 runtime failure (write
 * failed, out of memory), 2 bad input (usage, a file without the AOV layers, one already
 * denoised, the output being the input). */
#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "image_io.h"
#include "postprocess.h"
#include "render_denoise.h"
#include "render_output.h"

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres denoise IN.exr -o OUT [options]\n"
            "\n"
            "Denoises a render made with --aovs (an .exr with albedo.R/G/B, normal.X/Y/Z and\n"
            "depth.Z; variance.Y, samples and emission.R/G/B when it has them), as\n"
            "`rtspheres render --denoise` would have: for a farm's parts after\n"
            "`rtspheres merge`, or to keep the raw render beside the denoised one.\n"
            "\n"
            "options:\n"
            "  -o, --output FILE    the denoised image (.exr keeps every layer of the input and\n"
            "                       adds the noisy colour as noisy.R/G/B; .hdr, .png, .jpg,\n"
            "                       .tif); never the input\n"
            "      --exposure STOPS brighten 8-bit outputs by 2^STOPS (default 0)\n"
            "      --tonemap OP     for 8-bit outputs: clamp (default), reinhard or aces\n"
            "  -q, --quiet          no summary line\n"
            "  -h, --help           this text\n"
            "\n"
            "exit status: 0 ok, 1 runtime failure, 2 bad input (usage, a file without the\n"
            "AOV layers or already denoised)\n");
}

/* Parses the options into the outputs; returns EXIT_OK or an exit code after saying why. */
static int parse_options(int argc, char **argv, const char **output, postprocess_tonemap_operator *tonemap,
                         double *exposure, bool *quiet)
{
    enum { OPTION_EXPOSURE = 256, OPTION_TONEMAP };
    static const struct option long_options[] = {
        {"output", required_argument, NULL, 'o'},
        {"exposure", required_argument, NULL, OPTION_EXPOSURE},
        {"tonemap", required_argument, NULL, OPTION_TONEMAP},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, "o:qh", long_options, NULL)) != -1) {
        switch (option) {
        case 'o': *output = optarg; break;
        case 'q': *quiet = true; break;
        case OPTION_EXPOSURE:
            if (command_parse_exposure("denoise", optarg, exposure) != 0)
                return EXIT_BAD_INPUT;
            break;
        case OPTION_TONEMAP:
            if (command_parse_tonemap("denoise", optarg, tonemap) != 0)
                return EXIT_BAD_INPUT;
            break;
        default: return command_help_exit(option, print_help);
        }
    }
    return EXIT_OK;
}

/* Denoises image (read from input) into *out, the input's channels with R, G, B denoised
 * and then noisy.R/G/B (the input's R, G, B), and *colour, the denoised R, G, B alone.
 * The caller frees both. */
static rt_status denoise_image(const char *input, const rt_image *image, rt_image *out, rt_image *colour,
                               rt_error *error)
{
    static const char *const colour_names[3] = {"R", "G", "B"};
    int colour_channels[3];
    for (int c = 0; c < 3; c++)
        if ((colour_channels[c] = image_channel_index(image, colour_names[c])) < 0)
            return rt_error_set(error, RT_ERROR_INPUT, "'%s' has no %s channel", input, colour_names[c]);
    rt_status status = render_denoise_check_raw(input, image, error);
    if (status != RT_OK)
        return status;
    rt_image noisy = {0};
    status = image_create(colour, image->width, image->height, 3, error);
    size_t pixels = (size_t)image->width * image->height;
    for (size_t i = 0; status == RT_OK && i < pixels; i++)
        for (int c = 0; c < 3; c++)
            colour->pixels[3 * i + c] = image->pixels[i * image->channels + colour_channels[c]];
    if (status == RT_OK)
        status = image_create(&noisy, image->width, image->height, 3, error);
    if (status == RT_OK) {
        memcpy(noisy.pixels, colour->pixels, pixels * 3 * sizeof(float));
        for (int c = 0; c < 3; c++)
            snprintf(noisy.channel_names[c], IMAGE_CHANNEL_NAME_MAX, "noisy.%s", colour_names[c]);
        status = render_denoise(colour, image, image, error);
    }
    if (status == RT_OK)
        status = image_append_channels(image, &noisy, out, error);
    for (size_t i = 0; status == RT_OK && i < pixels; i++)
        for (int c = 0; c < 3; c++)
            out->pixels[i * out->channels + colour_channels[c]] = colour->pixels[3 * i + c];
    image_free(&noisy);
    return status;
}

int command_denoise(int argc, char **argv)
{
    const char *output = NULL;
    postprocess_tonemap_operator tonemap = TONEMAP_CLAMP;
    double exposure = 0;
    bool quiet = false;
    int code = parse_options(argc, argv, &output, &tonemap, &exposure, &quiet);
    if (code != EXIT_OK)
        return code;
    const char *input = NULL;
    code = command_image_to_image("denoise", argc, argv, "an EXR rendered with --aovs", output, &input);
    if (code != EXIT_OK)
        return code;
    rt_error error = {{0}};
    rt_image image = {0}, denoised = {0}, colour = {0};
    rt_status status = image_read(input, &image, &error);
    if (status == RT_OK)
        status = denoise_image(input, &image, &denoised, &colour, &error);
    image_free(&image);
    image_attribute_set metadata = {0};
    if (status == RT_OK)
        status = render_output_derived_metadata(input, "denoise", &metadata, &error);
    image_write_options options = image_write_options_defaults();
    options.attributes = metadata.attributes;
    options.attribute_count = metadata.count;
    if (status == RT_OK && image_format_of(output) == IMAGE_FORMAT_EXR)
        status = image_write(output, &denoised, &options, &error);
    else if (status == RT_OK)
        status = command_write_colour(output, &colour, tonemap, exposure, &metadata, &error);
    image_attribute_set_free(&metadata);
    image_free(&denoised);
    image_free(&colour);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres denoise: %s\n", error.message);
        return exit_code_for_status(status);
    }
    if (!quiet)
        fprintf(stderr, "rtspheres denoise: %s -> %s\n", input, output);
    return EXIT_OK;
}
