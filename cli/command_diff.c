/* command_diff.c: `rtspheres diff A B [options]`: compares two images the way idiff does
 * and prints the metrics, one per line. Exit codes: 0 the images match within tolerance,
 * 1 they differ (including different sizes), 2 an error (unreadable image, bad option,
 * NaN in an image, the difference image cannot be written). */
#include <errno.h>
#include <float.h>
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "image_diff.h"
#include "image_io.h"

#define DEFAULT_FAIL 0.016
#define DEFAULT_FAIL_PERCENT 1.0
#define DEFAULT_SCALE 16.0

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres diff A B [options]\n"
            "\n"
            "Compares images A and B pixel by pixel (the first three channels; alpha and extra\n"
            "channels are not compared). A pixel's error is its largest channel difference.\n"
            "Prints mean, RMS, PSNR and max error and how many pixels are over the threshold.\n"
            "\n"
            "options:\n"
            "  --fail X          a pixel fails when its error is over X (default %g)\n"
            "  --failpercent P   the images match when at most P%% of pixels fail (default %g)\n"
            "  --hardfail X      and no pixel's error is over X (default: no limit)\n"
            "  --diff-out FILE   write |A - B| * scale to FILE (.exr .png ...) when they differ\n"
            "  --diff-always     write --diff-out even when the images match\n"
            "  --scale S         amplification of the difference image (default %g)\n"
            "  -q, --quiet       print nothing when the images match\n"
            "  -h, --help        show this help\n"
            "\n"
            "exit status: 0 match, 1 differ (or different sizes), 2 error\n",
            DEFAULT_FAIL, DEFAULT_FAIL_PERCENT, DEFAULT_SCALE);
}

/* Parses all of text as a finite number in [minimum, maximum] into *value. Returns true
 * on success; "", "abc", "1x", "nan" and out-of-range values are refused. */
static bool parse_number(const char *text, double minimum, double maximum, double *value)
{
    char *end = NULL;
    errno = 0;
    double parsed = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(parsed) || parsed < minimum
        || parsed > maximum)
        return false;
    *value = parsed;
    return true;
}

/* image_diff_options treat 0 as "use the default", so a tolerance of exactly zero is passed
 * as the smallest positive double. The differences of float samples are either 0 or far
 * above DBL_MIN, so "error > DBL_MIN" means the same as "error > 0". */
static double zero_as_smallest(double value)
{
    return value == 0.0 ? DBL_MIN : value;
}

static void print_metrics(const image_diff_result *result, const rt_image *a, int compared,
                          double fail_threshold)
{
    printf("size: %dx%d, %d channel%s compared\n", a->width, a->height, compared,
           compared == 1 ? "" : "s");
    printf("mean error: %.6g\n", result->mean_error);
    printf("rms error: %.6g\n", result->rms_error);
    printf("psnr: %.2f dB\n", result->psnr);
    printf("max error: %.6g at (%d, %d)\n", result->max_error, result->max_x, result->max_y);
    printf("pixels over %g: %ld of %ld (%.2f%%)\n", fail_threshold, result->failing_pixels,
           (long)a->width * a->height, result->failing_percent);
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

/* What the command line asks for. */
typedef struct diff_arguments {
    double fail_threshold, fail_percent, hard_fail, scale;
    bool hard_fail_set, diff_always, quiet;
    const char *diff_out;  /* NULL: no difference image */
    const char *path_a, *path_b;
} diff_arguments;

/* Reads the options and the two paths into *arguments; returns true to go on, or false
 * with the command's exit code in *exit_code (after --help, or a message on stderr). */
static bool parse_arguments(int argc, char **argv, diff_arguments *arguments, int *exit_code)
{
    enum { OPTION_FAIL = 256, OPTION_FAIL_PERCENT, OPTION_HARD_FAIL, OPTION_DIFF_OUT,
           OPTION_DIFF_ALWAYS, OPTION_SCALE };
    static const struct option long_options[] = {
        {"fail", required_argument, NULL, OPTION_FAIL},
        {"failpercent", required_argument, NULL, OPTION_FAIL_PERCENT},
        {"hardfail", required_argument, NULL, OPTION_HARD_FAIL},
        {"diff-out", required_argument, NULL, OPTION_DIFF_OUT},
        {"diff-always", no_argument, NULL, OPTION_DIFF_ALWAYS},
        {"scale", required_argument, NULL, OPTION_SCALE},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    *arguments = (diff_arguments){
        .fail_threshold = DEFAULT_FAIL, .fail_percent = DEFAULT_FAIL_PERCENT, .scale = DEFAULT_SCALE};

    /* Our own messages instead of getopt's, which would say "diff: ..." */
    opterr = 0;
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, ":qh", long_options, NULL)) != -1) {
        switch (option) {
        case OPTION_FAIL:
            if (!parse_number(optarg, 0.0, HUGE_VAL, &arguments->fail_threshold)) {
                fprintf(stderr, "rtspheres diff: --fail wants an error of 0 or more, e.g. 0.016, "
                                "not '%s'\n", optarg);
                *exit_code = EXIT_BAD_INPUT;
                return false;
            }
            break;
        case OPTION_FAIL_PERCENT:
            if (!parse_number(optarg, 0.0, 100.0, &arguments->fail_percent)) {
                fprintf(stderr, "rtspheres diff: --failpercent wants a percentage from 0 to 100, "
                                "not '%s'\n", optarg);
                *exit_code = EXIT_BAD_INPUT;
                return false;
            }
            break;
        case OPTION_HARD_FAIL:
            if (!parse_number(optarg, 0.0, HUGE_VAL, &arguments->hard_fail)) {
                fprintf(stderr, "rtspheres diff: --hardfail wants an error of 0 or more, "
                                "not '%s'\n", optarg);
                *exit_code = EXIT_BAD_INPUT;
                return false;
            }
            arguments->hard_fail_set = true;
            break;
        case OPTION_DIFF_OUT:
            arguments->diff_out = optarg;
            break;
        case OPTION_DIFF_ALWAYS:
            arguments->diff_always = true;
            break;
        case OPTION_SCALE:
            if (!parse_number(optarg, 0.0, HUGE_VAL, &arguments->scale) || arguments->scale == 0.0) {
                fprintf(stderr, "rtspheres diff: --scale wants a factor above 0, e.g. 16, "
                                "not '%s'\n", optarg);
                *exit_code = EXIT_BAD_INPUT;
                return false;
            }
            break;
        case 'q':
            arguments->quiet = true;
            break;
        case 'h':
            print_help(stdout);
            *exit_code = EXIT_OK;
            return false;
        case ':':
            fprintf(stderr, "rtspheres diff: %s needs a value (see 'rtspheres diff --help')\n",
                    argv[optind - 1]);
            *exit_code = EXIT_BAD_INPUT;
            return false;
        default:
            fprintf(stderr, "rtspheres diff: unknown option '%s' (see 'rtspheres diff --help')\n",
                    argv[optind - 1]);
            *exit_code = EXIT_BAD_INPUT;
            return false;
        }
    }
    if (argc - optind != 2) {
        fprintf(stderr, "rtspheres diff: expected two images, got %d; usage: rtspheres diff A B "
                        "[options]\n", argc - optind);
        *exit_code = EXIT_BAD_INPUT;
        return false;
    }
    if (arguments->diff_always && arguments->diff_out == NULL) {
        fprintf(stderr, "rtspheres diff: --diff-always needs --diff-out FILE\n");
        *exit_code = EXIT_BAD_INPUT;
        return false;
    }
    arguments->path_a = argv[optind];
    arguments->path_b = argv[optind + 1];
    return true;
}

/* Compares the two images of arguments and prints the verdict (and writes the difference
 * image); returns the command's exit code. */
static int compare_images(const diff_arguments *arguments)
{
    const char *path_a = arguments->path_a, *path_b = arguments->path_b;
    const char *diff_out = arguments->diff_out;
    double fail_threshold = arguments->fail_threshold, fail_percent = arguments->fail_percent;
    double hard_fail = arguments->hard_fail;
    bool hard_fail_set = arguments->hard_fail_set;

    rt_error error;
    rt_image a, b;
    if (image_read(path_a, &a, &error) != RT_OK) {
        fprintf(stderr, "rtspheres diff: %s\n", error.message);
        return EXIT_BAD_INPUT;
    }
    if (image_read(path_b, &b, &error) != RT_OK) {
        fprintf(stderr, "rtspheres diff: %s\n", error.message);
        image_free(&a);
        return EXIT_BAD_INPUT;
    }

    /* Different sizes are a failed comparison, not an error: a render at the wrong
     * resolution is a regression like any other. */
    if (a.width != b.width || a.height != b.height) {
        printf("result: FAIL (sizes differ: %dx%d vs %dx%d)\n", a.width, a.height, b.width,
                   b.height);
        image_free(&a);
        image_free(&b);
        return EXIT_RUNTIME;
    }

    image_diff_options options = image_diff_options_defaults();
    options.fail_threshold = zero_as_smallest(fail_threshold);
    options.fail_percent = zero_as_smallest(fail_percent);
    /* --hardfail 0 means "no difference at all", not image_diff's "off". */
    options.hard_fail = hard_fail_set ? zero_as_smallest(hard_fail) : 0.0;
    options.diff_scale = arguments->scale;
    image_diff_result result;
    rt_image difference = {0};
    rt_status status = image_diff(&a, &b, &options, &result, diff_out ? &difference : NULL,
                                  &error);
    int compared = a.channels < b.channels ? a.channels : b.channels;
    compared = compared < 3 ? compared : 3;
    int exit_code = EXIT_OK;
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres diff: %s (A is '%s', B is '%s')\n", error.message, path_a,
                path_b);
        exit_code = EXIT_BAD_INPUT;
    } else {
        /* --quiet silences a match only: a failure's numbers are what one looks at next. */
        bool show = !arguments->quiet || !result.passed;
        if (show) {
            print_metrics(&result, &a, compared, fail_threshold);
            print_result(&result, fail_threshold, fail_percent, hard_fail_set, hard_fail);
        }
        exit_code = result.passed ? EXIT_OK : EXIT_RUNTIME;
        if (diff_out != NULL && (arguments->diff_always || !result.passed)) {
            /* An unwritable difference image is an error, not a verdict about the images. */
            if (image_write(diff_out, &difference, NULL, &error) != RT_OK) {
                fprintf(stderr, "rtspheres diff: %s\n", error.message);
                exit_code = EXIT_BAD_INPUT;
            } else if (show) {
                printf("difference image: %s\n", diff_out);
            }
        }
        image_free(&difference);
    }
    image_free(&a);
    image_free(&b);
    return exit_code;
}

int command_diff(int argc, char **argv)
{
    diff_arguments arguments;
    int exit_code;
    if (!parse_arguments(argc, argv, &arguments, &exit_code))
        return exit_code;
    return compare_images(&arguments);
}
