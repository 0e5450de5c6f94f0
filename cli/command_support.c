/* command_support.c: the helpers every command shares (declared in commands.h). */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "paths.h"
#include "status.h"

int exit_code_for_status(int status)
{
    switch ((rt_status)status) {
    case RT_OK: return EXIT_OK;
    case RT_ERROR_INPUT: return EXIT_BAD_INPUT;
    case RT_ERROR_RUNTIME:
    case RT_ERROR_NO_DEVICE:
    case RT_ERROR_INTERRUPTED: return EXIT_RUNTIME;
    }
    return EXIT_RUNTIME;
}

int command_parse_integer(const char *text, long long minimum, long long maximum, long long *value)
{
    char *end = NULL;
    errno = 0;
    long long parsed = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno != 0 || parsed < minimum || parsed > maximum)
        return -1;
    *value = parsed;
    return 0;
}

int command_help_exit(int option, void (*print_help)(FILE *stream))
{
    bool asked = option == 'h';
    print_help(asked ? stdout : stderr);
    return asked ? EXIT_OK : EXIT_BAD_INPUT;
}

int command_parse_exposure(const char *command, const char *text, double *exposure)
{
    char *end = NULL;
    double value = strtod(text, &end);
    if (end == text || *end != '\0' || !(fabs(value) <= 64)) {
        fprintf(stderr, "rtspheres %s: --exposure wants a number of stops (-64 to 64), not '%s'\n", command, text);
        return -1;
    }
    *exposure = value;
    return 0;
}

int command_parse_tonemap(const char *command, const char *text, postprocess_tonemap_operator *tonemap)
{
    if (strcmp(text, "clamp") == 0)
        *tonemap = TONEMAP_CLAMP;
    else if (strcmp(text, "reinhard") == 0)
        *tonemap = TONEMAP_REINHARD;
    else if (strcmp(text, "aces") == 0)
        *tonemap = TONEMAP_ACES;
    else {
        fprintf(stderr, "rtspheres %s: --tonemap wants clamp, reinhard or aces, not '%s'\n", command, text);
        return -1;
    }
    return 0;
}

rt_status command_write_colour(const char *output, const rt_image *image, postprocess_tonemap_operator tonemap,
                               double exposure, const image_attribute_set *metadata, rt_error *error)
{
    rt_image colour = {0};
    rt_status status = image_create(&colour, image->width, image->height, 3, error);
    if (status != RT_OK)
        return status;
    size_t pixel_count = (size_t)image->width * image->height;
    for (size_t i = 0; i < pixel_count; i++)
        memcpy(colour.pixels + 3 * i, image->pixels + i * (size_t)image->channels, 3 * sizeof(float));
    image_write_options options = image_write_options_defaults();
    options.exposure = (float)exposure;
    if (metadata != NULL) {
        options.attributes = metadata->attributes;
        options.attribute_count = metadata->count;
    }
    if (image_format_of(output) == IMAGE_FORMAT_EIGHT_BIT && tonemap != TONEMAP_CLAMP) {
        /* The writer's exposure would apply a second time after tone mapping. */
        status = postprocess_tonemap(&colour, tonemap, (float)exposure, error);
        options.exposure = 0;
    }
    if (status == RT_OK)
        status = image_write(output, &colour, &options, error);
    image_free(&colour);
    return status;
}

int command_image_to_image(const char *command, int argc, char **argv, const char *what, const char *output,
                           const char **input)
{
    if (optind != argc - 1) {
        fprintf(stderr, "rtspheres %s: give one input image (%s)\n", command, what);
        return EXIT_BAD_INPUT;
    }
    *input = argv[optind];
    if (output == NULL || image_format_of(output) == IMAGE_FORMAT_UNKNOWN) {
        fprintf(stderr, "rtspheres %s: %s; give -o OUT.exr (or .hdr, .png, .jpg, .tif)\n", command,
                output == NULL ? "no output" : "cannot tell the output's format");
        return EXIT_BAD_INPUT;
    }
    if (strcmp(*input, output) == 0 || path_same_file(*input, output)) {
        fprintf(stderr, "rtspheres %s: the output '%s' is the input; refusing to overwrite it\n", command, output);
        return EXIT_BAD_INPUT;
    }
    return EXIT_OK;
}
