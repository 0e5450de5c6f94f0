/* command_diff.c: `rtspheres diff A B [options]`: compares two images, by default the way
 * idiff does (fixed thresholds), with --test z by the statistical test of
 * core/image_stat_diff.h, and prints the metrics, one per line. Exit codes: 0 the images
 * match, 1 they differ (including different sizes), 2 an error (unreadable image, bad
 * option, NaN in an image, no variance layers for --test z, an output image that cannot
 * be written). */
#include <errno.h>
#include <float.h>
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "compare_arguments.h"
#include "image_compare.h"
#include "image_io.h"

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres diff A B [options]\n"
            "\n"
            "Compares images A and B pixel by pixel (the first three channels; alpha and extra\n"
            "channels are not compared). A pixel's error is its largest channel difference.\n"
            "Prints mean, RMS, PSNR and max error and how many pixels are over the threshold.\n"
            "With --test z, A and B are Monte Carlo renders (EXRs with a samples channel and\n"
            "variance.R/G/B layers from `render --variance`; one of them is enough) and they\n"
            "match when their difference is within their noise: per-pixel z-tests (Mitsuba 3's\n"
            "rule) and z-tests of the means of blocks of pixels (docs/regression.md).\n"
            "\n"
            "options:\n"
            "  --test idiff|z    the test (default idiff)\n"
            "  --fail X          idiff: a pixel fails when its error is over X (default %g)\n"
            "  --failpercent P   idiff: the images match when at most P%% of pixels fail (default %g)\n"
            "  --hardfail X      idiff: and no pixel's error is over X (default: no limit)\n"
            "  --alpha A         z: significance of the pixel test, Sidak-corrected over the\n"
            "                    pixel channels (default 0.01)\n"
            "  --pass-percent P  z: the pixel test passes when at least P%% of pixel channels\n"
            "                    pass (default 99.75)\n"
            "  --block-alpha A   z: significance of all block tests together (default 0.01)\n"
            "  --scales LIST     z: block sides, e.g. 4,8,16,32,64,image (the default), or none\n"
            "  --noise-floor R   z: a relative difference this small counts as one standard\n"
            "                    deviation, for pixels without noise (default 0.001)\n"
            "  --noise-floor-absolute X  z: and this absolute one (default 1e-05)\n"
            "  --diff-out FILE   write |A - B| * scale to FILE (.exr .png ...) when they differ\n"
            "  --diff-always     write --diff-out (and --z-out) even when the images match\n"
            "  --scale S         amplification of the difference image (default %g)\n"
            "  --z-out FILE      z: write the z-scores when they differ: .exr keeps z.R/G/B and\n"
            "                    significance (|z| / threshold), other formats get a heat map\n"
            "  -q, --quiet       print nothing when the images match\n"
            "  -h, --help        show this help\n"
            "\n"
            "exit status: 0 match, 1 differ (or different sizes), 2 error\n",
            IMAGE_DIFF_DEFAULT_FAIL_THRESHOLD, IMAGE_DIFF_DEFAULT_FAIL_PERCENT, IMAGE_DIFF_DEFAULT_SCALE);
}

/* Prints the result line: PASS, or FAIL with the reason. */
static void print_result(const image_diff_result *result, double fail_threshold,
                         double fail_percent, bool hard_fail_set, double hard_fail)
{
    if (result->passed) {
        printf("result: PASS\n");
    } else if (hard_fail_set && result->max_error > hard_fail) {
        printf("result: FAIL (max error %.6g is over --hardfail %g)\n", result->max_error,
               hard_fail);
    } else {
        printf("result: FAIL (%.2f%% of pixels are over %g; at most %g%% may be)\n",
               result->failing_percent, fail_threshold, fail_percent);
    }
}

/* Prints the metrics and the result line. */
static void print_comparison(const image_compare_result *result, const compare_arguments *comparison)
{
    char text[4096];
    image_compare_metrics(result, &comparison->options, text, sizeof text);
    fputs(text, stdout);
    if (result->test == IMAGE_COMPARE_IDIFF) {
        print_result(&result->idiff, comparison->fail_threshold, comparison->fail_percent,
                     comparison->hard_fail_set, comparison->hard_fail);
        return;
    }
    char reason[512];
    image_compare_describe(result, &comparison->options, reason, sizeof reason);
    printf(result->passed ? "result: PASS\n" : "result: FAIL (%s)\n", reason);
}

/* Writes the maps to path: as they are in an EXR, as a heat map otherwise. Returns the
 * status with error set. */
static rt_status write_maps(const char *path, const rt_image *maps, rt_error *error)
{
    if (image_format_of(path) == IMAGE_FORMAT_EXR)
        return image_write(path, maps, NULL, error);
    rt_image heat;
    rt_status status = image_stat_heat_map(maps, &heat, error);
    if (status == RT_OK)
        status = image_write(path, &heat, NULL, error);
    image_free(&heat);
    return status;
}

/* What the command was asked besides the comparison. */
typedef struct diff_request {
    compare_arguments comparison;
    const char *diff_out, *z_out;
    bool diff_always, quiet;
    const char *path_a, *path_b;
} diff_request;

/* Parses argv into *request. Returns EXIT_OK, -1 after --help, or an exit code after
 * printing why. */
static int parse_request(int argc, char **argv, diff_request *request)
{
    enum { OPTION_DIFF_OUT = 256, OPTION_DIFF_ALWAYS, OPTION_Z_OUT };
    struct option long_options[COMPARE_LONG_OPTION_COUNT + 6] = {
        {"diff-out", required_argument, NULL, OPTION_DIFF_OUT},
        {"diff-always", no_argument, NULL, OPTION_DIFF_ALWAYS},
        {"z-out", required_argument, NULL, OPTION_Z_OUT},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
    };
    memcpy(&long_options[5], compare_long_options, sizeof compare_long_options);
    memset(request, 0, sizeof *request);
    compare_arguments_init(&request->comparison, IMAGE_COMPARE_IDIFF);

    /* Our own messages instead of getopt's, which would say "diff: ..." */
    opterr = 0;
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, ":qh", long_options, NULL)) != -1) {
        if (compare_arguments_owns(option)) {
            const char *complaint = compare_arguments_take(&request->comparison, option, optarg);
            if (complaint != NULL) {
                fprintf(stderr, "rtspheres diff: %s, not '%s'\n", complaint, optarg);
                return EXIT_BAD_INPUT;
            }
            continue;
        }
        switch (option) {
        case OPTION_DIFF_OUT: request->diff_out = optarg; break;
        case OPTION_DIFF_ALWAYS: request->diff_always = true; break;
        case OPTION_Z_OUT: request->z_out = optarg; break;
        case 'q': request->quiet = true; break;
        case 'h':
            print_help(stdout);
            return -1;
        case ':':
            fprintf(stderr, "rtspheres diff: %s needs a value (see 'rtspheres diff --help')\n",
                    argv[optind - 1]);
            return EXIT_BAD_INPUT;
        default:
            fprintf(stderr, "rtspheres diff: unknown option '%s' (see 'rtspheres diff --help')\n",
                    argv[optind - 1]);
            return EXIT_BAD_INPUT;
        }
    }
    char text[256];
    const char *complaint = compare_arguments_finish(&request->comparison, text, sizeof text);
    if (complaint != NULL) {
        fprintf(stderr, "rtspheres diff: %s\n", complaint);
        return EXIT_BAD_INPUT;
    }
    if (argc - optind != 2) {
        fprintf(stderr, "rtspheres diff: expected two images, got %d; usage: rtspheres diff A B "
                        "[options]\n", argc - optind);
        return EXIT_BAD_INPUT;
    }
    if (request->diff_always && request->diff_out == NULL && request->z_out == NULL) {
        fprintf(stderr, "rtspheres diff: --diff-always needs --diff-out FILE\n");
        return EXIT_BAD_INPUT;
    }
    if (request->z_out != NULL && request->comparison.options.test != IMAGE_COMPARE_Z) {
        fprintf(stderr, "rtspheres diff: --z-out needs --test z\n");
        return EXIT_BAD_INPUT;
    }
    request->path_a = argv[optind];
    request->path_b = argv[optind + 1];
    return EXIT_OK;
}

/* Writes what was asked of the comparison's images; an unwritable one is an error, not a
 * verdict about the images. Returns the exit code. */
static int write_outputs(const diff_request *request, const image_compare_result *result,
                         const rt_image *difference, const rt_image *maps, bool show, int exit_code)
{
    rt_error error;
    bool wanted = request->diff_always || !result->passed;
    if (request->diff_out != NULL && wanted) {
        if (image_write(request->diff_out, difference, NULL, &error) != RT_OK) {
            fprintf(stderr, "rtspheres diff: %s\n", error.message);
            return EXIT_BAD_INPUT;
        }
        if (show)
            printf("difference image: %s\n", request->diff_out);
    }
    if (request->z_out != NULL && wanted) {
        if (write_maps(request->z_out, maps, &error) != RT_OK) {
            fprintf(stderr, "rtspheres diff: %s\n", error.message);
            return EXIT_BAD_INPUT;
        }
        if (show)
            printf("z-score image: %s\n", request->z_out);
    }
    return exit_code;
}

int command_diff(int argc, char **argv)
{
    diff_request request;
    int code = parse_request(argc, argv, &request);
    if (code != EXIT_OK)
        return code < 0 ? EXIT_OK : code;
    const compare_arguments *comparison = &request.comparison;

    rt_error error;
    rt_image a, b;
    if (image_read(request.path_a, &a, &error) != RT_OK) {
        fprintf(stderr, "rtspheres diff: %s\n", error.message);
        return EXIT_BAD_INPUT;
    }
    if (image_read(request.path_b, &b, &error) != RT_OK) {
        fprintf(stderr, "rtspheres diff: %s\n", error.message);
        image_free(&a);
        return EXIT_BAD_INPUT;
    }

    image_compare_result result;
    rt_image difference = {0}, maps = {0};
    rt_status status = image_compare(&a, &b, &comparison->options, &result, request.diff_out ? &difference : NULL,
                                     request.z_out ? &maps : NULL, &error);
    int exit_code = EXIT_OK;
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres diff: %s (A is '%s', B is '%s')\n", error.message, request.path_a,
                request.path_b);
        exit_code = EXIT_BAD_INPUT;
    } else if (result.sizes_differ) {
        /* Different sizes are a failed comparison, not an error: a render at the wrong
         * resolution is a regression like any other. */
        printf("result: FAIL (sizes differ: %dx%d vs %dx%d)\n", a.width, a.height, b.width, b.height);
        exit_code = EXIT_RUNTIME;
    } else {
        /* --quiet silences a match only: a failure's numbers are what one looks at next. */
        bool show = !request.quiet || !result.passed;
        if (show)
            print_comparison(&result, comparison);
        exit_code = write_outputs(&request, &result, &difference, &maps, show,
                                  result.passed ? EXIT_OK : EXIT_RUNTIME);
    }
    image_free(&difference);
    image_free(&maps);
    image_free(&a);
    image_free(&b);
    return exit_code;
}
