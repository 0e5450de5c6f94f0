/* command_stats.c: `rtspheres stats IMAGE [--crop x0,y0,x1,y1]`: prints the image's size,
 * channels, per-channel mean/min/max over a region, and the rtspheres metadata of an EXR.
 * Used by the analytic tests and handy for checking a render by hand. */
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "image_io.h"
#include "metadata_keys.h"

static void print_help(FILE *stream)
{
    fprintf(stream, "usage: rtspheres stats IMAGE [--crop x0,y0,x1,y1]\n"
                    "  --crop x0,y0,x1,y1   only pixels x0 <= x < x1, y0 <= y < y1 (row 0 at the top)\n"
                    "Prints one line per channel: 'channel NAME: mean M min A max B', then the\n"
                    "rtspheres:* metadata of the file, one 'metadata NAME: VALUE' line each.\n");
}

static const char *const metadata_names[METADATA_KEY_COUNT] = METADATA_KEYS_IN_STATS_ORDER;

int command_stats(int argc, char **argv)
{
    static const struct option long_options[] = {
        {"crop", required_argument, NULL, 'c'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    int crop[4] = {0, 0, -1, -1};
    bool cropped = false;
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, "h", long_options, NULL)) != -1) {
        switch (option) {
        case 'c': {
            char extra;
            if (sscanf(optarg, "%d,%d,%d,%d%c", &crop[0], &crop[1], &crop[2], &crop[3], &extra) != 4) {
                fprintf(stderr, "rtspheres stats: --crop wants x0,y0,x1,y1 (whole numbers), not '%s'\n", optarg);
                return EXIT_BAD_INPUT;
            }
            cropped = true;
            break;
        }
        default:
            return command_help_exit(option, print_help);
        }
    }
    if (optind + 1 != argc) {
        fprintf(stderr, "rtspheres stats: give exactly one image\n");
        return EXIT_BAD_INPUT;
    }
    const char *path = argv[optind];
    rt_image image;
    rt_error error = {{0}};
    rt_status status = image_read(path, &image, &error);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres stats: %s\n", error.message);
        return exit_code_for_status(status);
    }
    if (!cropped) {
        crop[2] = image.width;
        crop[3] = image.height;
    }
    if (crop[0] < 0 || crop[1] < 0 || crop[2] > image.width || crop[3] > image.height || crop[0] >= crop[2]
        || crop[1] >= crop[3]) {
        fprintf(stderr, "rtspheres stats: --crop %d,%d,%d,%d is not a non-empty region of the %dx%d image\n", crop[0],
                crop[1], crop[2], crop[3], image.width, image.height);
        image_free(&image);
        return EXIT_BAD_INPUT;
    }
    printf("size: %dx%d\n", image.width, image.height);
    printf("channels: %d\n", image.channels);
    for (int c = 0; c < image.channels; c++) {
        double sum = 0, minimum = INFINITY, maximum = -INFINITY;
        for (int y = crop[1]; y < crop[3]; y++)
            for (int x = crop[0]; x < crop[2]; x++) {
                double value = image.pixels[((size_t)y * image.width + x) * image.channels + c];
                sum += value;
                minimum = fmin(minimum, value);
                maximum = fmax(maximum, value);
            }
        double count = (double)(crop[2] - crop[0]) * (crop[3] - crop[1]);
        const char *name = image.channel_names[c][0] ? image.channel_names[c] : (c < 4 ? (const char *[]){"R", "G", "B", "A"}[c] : "?");
        printf("channel %s: mean %.9g min %.9g max %.9g\n", name, sum / count, minimum, maximum);
    }
    image_free(&image);
    for (size_t i = 0; i < sizeof metadata_names / sizeof metadata_names[0]; i++) {
        char value[512];
        if (image_read_attribute(path, metadata_names[i], value, sizeof value, NULL) == RT_OK)
            printf("metadata %s: %s\n", metadata_names[i], value);
    }
    return EXIT_OK;
}
