/* command_render.c: `rtspheres render SCENE -o OUTPUT [options]`: parses options, loads
 * the scene, renders it on the GPU context and writes the image. Turns every failure
 * into a message on stderr and an exit code (0 ok, 1 runtime/interrupted, 2 bad input). */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "commands.h"
#include "gpu.h"
#include "image_io.h"
#include "render.h"
#include "scene_parse.h"
#include "version.h"

#define MAX_DEFINES 256

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres render SCENE -o OUTPUT [options]\n"
            "\n"
            "Renders the scene file SCENE and writes OUTPUT; the format follows the extension:\n"
            ".exr (linear float, with metadata and a per-pixel 'samples' channel), .hdr,\n"
            ".png/.jpg/.tif (8-bit sRGB).\n"
            "\n"
            "options (each overrides the scene file's `render` settings):\n"
            "  -o, --output FILE      the image to write (required)\n"
            "  -s, --spp N            samples per pixel\n"
            "      --size WxH         image size in pixels, e.g. 640x360\n"
            "      --max-depth N      path segments per sample at most\n"
            "      --seed N           random seed (same seed, same image)\n"
            "  -D NAME=VALUE          set scene variable $NAME (wins over the file's `set`)\n"
            "      --exposure STOPS   brighten 8-bit outputs by 2^STOPS (default 0)\n"
            "      --pass-budget N    fixed work units per pixel per GPU pass (default: adapted\n"
            "                         so a pass takes about 0.25 s; the image is the same)\n"
            "      --roulette-depth N paths may end at random (Russian roulette, unbiased)\n"
            "                         after N segments (default 4)\n"
            "      --device N         use EGL device N (see `rtspheres info`)\n"
            "  -q, --quiet            no progress bar and no summary line\n"
            "  -v, --verbose          OpenGL debug messages and set-up details on stderr\n"
            "  -h, --help             this text\n");
}

static volatile sig_atomic_t stop_requested = 0;

/* First SIGINT/SIGTERM: finish the pass in flight and write what is done. Second: the
 * default action (the handler resets itself), so the user can always get out. */
static void on_stop_signal(int signal_number)
{
    stop_requested = 1;
    signal(signal_number, SIG_DFL);
}

/* Parses a whole decimal integer in [minimum, maximum] into *value. Returns 0 or -1. */
static int parse_integer(const char *text, long long minimum, long long maximum, long long *value)
{
    char *end = NULL;
    errno = 0;
    long long parsed = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno != 0 || parsed < minimum || parsed > maximum)
        return -1;
    *value = parsed;
    return 0;
}

typedef struct progress_state {
    bool tty;
    int last_percent;
    double last_draw;
} progress_state;

static void draw_progress(void *context, const render_progress *progress)
{
    progress_state *state = context;
    if (!state->tty || progress->samples_total == 0)
        return;
    double fraction = (double)progress->samples_done / (double)progress->samples_total;
    if (progress->elapsed_seconds - state->last_draw < 0.1 && fraction < 1.0)
        return;
    state->last_draw = progress->elapsed_seconds;
    int width = 30, filled = (int)(fraction * width);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    double eta = fraction > 0 ? progress->elapsed_seconds * (1.0 - fraction) / fraction : 0;
    fprintf(stderr, "\r[%s] %5.1f%%  %llu/%llu samples  %.1f s elapsed, ETA %.1f s ", bar, 100.0 * fraction,
            (unsigned long long)progress->samples_done, (unsigned long long)progress->samples_total,
            progress->elapsed_seconds, eta);
    fflush(stderr);
}

static void log_to_stderr(void *context, const char *message)
{
    (void)context;
    fprintf(stderr, "rtspheres: %s\n", message);
}

/* True when the two paths name the same existing file. */
static bool same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* True when the directory part of path exists and may be written, so a bad -o is found
 * before the render rather than after it. */
static bool output_directory_writable(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (slash == NULL)
        return access(".", W_OK) == 0;
    if (slash == path)
        return access("/", W_OK) == 0;
    char directory[4096];
    snprintf(directory, sizeof directory, "%.*s", (int)(slash - path), path);
    struct stat info;
    return stat(directory, &info) == 0 && S_ISDIR(info.st_mode) && access(directory, W_OK) == 0;
}

static bool is_float_output(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot != NULL && (strcasecmp(dot, ".exr") == 0 || strcasecmp(dot, ".hdr") == 0);
}

static bool known_output(const char *path)
{
    static const char *const extensions[] = {".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    const char *dot = strrchr(path, '.');
    if (dot == NULL || strchr(dot, '/') != NULL)
        return false;
    for (size_t i = 0; i < sizeof extensions / sizeof extensions[0]; i++)
        if (strcasecmp(dot, extensions[i]) == 0)
            return true;
    return false;
}

int command_render(int argc, char **argv)
{
    enum { OPTION_SIZE = 256, OPTION_MAX_DEPTH, OPTION_SEED, OPTION_EXPOSURE, OPTION_PASS_BUDGET, OPTION_DEVICE,
           OPTION_ROULETTE_DEPTH };
    static const struct option long_options[] = {
        {"output", required_argument, NULL, 'o'},
        {"spp", required_argument, NULL, 's'},
        {"size", required_argument, NULL, OPTION_SIZE},
        {"max-depth", required_argument, NULL, OPTION_MAX_DEPTH},
        {"seed", required_argument, NULL, OPTION_SEED},
        {"exposure", required_argument, NULL, OPTION_EXPOSURE},
        {"pass-budget", required_argument, NULL, OPTION_PASS_BUDGET},
        {"device", required_argument, NULL, OPTION_DEVICE},
        {"roulette-depth", required_argument, NULL, OPTION_ROULETTE_DEPTH},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char *output = NULL;
    long long spp = 0, width = 0, height = 0, max_depth = 0, seed = -1, pass_budget = 0, device = -1;
    long long roulette_depth = 0;
    double exposure = 0;
    bool quiet = false, verbose = false;
    scene_define defines[MAX_DEFINES];
    char *define_copies[MAX_DEFINES];
    int define_count = 0;
    int exit_code = EXIT_OK;

    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, "o:s:D:qvh", long_options, NULL)) != -1) {
        switch (option) {
        case 'o':
            output = optarg;
            break;
        case 's':
            if (parse_integer(optarg, 1, 1 << 30, &spp)) {
                fprintf(stderr, "rtspheres render: --spp wants a whole number from 1 to 1073741824, not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        case OPTION_SIZE: {
            char *x = strchr(optarg, 'x');
            char copy[64];
            snprintf(copy, sizeof copy, "%s", optarg);
            char *separator = x ? copy + (x - optarg) : NULL;
            if (separator)
                *separator = '\0';
            if (!separator || parse_integer(copy, 1, 16384, &width) || parse_integer(separator + 1, 1, 16384, &height)) {
                fprintf(stderr, "rtspheres render: --size wants WIDTHxHEIGHT, each 1 to 16384, e.g. 640x360, not '%s'\n",
                        optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        }
        case OPTION_MAX_DEPTH:
            if (parse_integer(optarg, 1, 100000, &max_depth)) {
                fprintf(stderr, "rtspheres render: --max-depth wants a whole number from 1 to 100000, not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        case OPTION_SEED:
            if (parse_integer(optarg, 0, UINT32_MAX, &seed)) {
                fprintf(stderr, "rtspheres render: --seed wants a whole number from 0 to 4294967295, not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        case OPTION_PASS_BUDGET:
            if (parse_integer(optarg, 1, 50000, &pass_budget)) {
                fprintf(stderr, "rtspheres render: --pass-budget wants a whole number from 1 to 50000, not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        case OPTION_ROULETTE_DEPTH:
            if (parse_integer(optarg, 1, 100000, &roulette_depth)) {
                fprintf(stderr, "rtspheres render: --roulette-depth wants a whole number from 1 to 100000, not '%s'\n",
                        optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        case OPTION_DEVICE:
            if (parse_integer(optarg, 0, 255, &device)) {
                fprintf(stderr, "rtspheres render: --device wants a device number (0, 1, ...), not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        case OPTION_EXPOSURE: {
            char *end = NULL;
            exposure = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !isfinite(exposure) || fabs(exposure) > 64) {
                fprintf(stderr, "rtspheres render: --exposure wants a number of stops (-64 to 64), not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
            }
            break;
        }
        case 'D': {
            const char *equals = strchr(optarg, '=');
            if (equals == NULL || equals == optarg || equals[1] == '\0') {
                fprintf(stderr, "rtspheres render: -D wants NAME=VALUE, e.g. -D aperture=0.1, not '%s'\n", optarg);
                exit_code = EXIT_BAD_INPUT;
                break;
            }
            if (define_count == MAX_DEFINES) {
                fprintf(stderr, "rtspheres render: more than %d -D options\n", MAX_DEFINES);
                exit_code = EXIT_BAD_INPUT;
                break;
            }
            char *copy = strdup(optarg);
            if (copy == NULL) {
                fprintf(stderr, "rtspheres render: out of memory\n");
                exit_code = EXIT_RUNTIME;
                break;
            }
            copy[equals - optarg] = '\0';
            define_copies[define_count] = copy;
            defines[define_count] = (scene_define){.name = copy, .value = copy + (equals - optarg) + 1};
            define_count++;
            break;
        }
        case 'q':
            quiet = true;
            break;
        case 'v':
            verbose = true;
            break;
        case 'h':
            print_help(stdout);
            goto done;
        default:
            exit_code = EXIT_BAD_INPUT;
            break;
        }
    }
    if (exit_code != EXIT_OK)
        goto done;
    if (optind >= argc) {
        fprintf(stderr, "rtspheres render: which scene? usage: rtspheres render SCENE -o OUTPUT\n");
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    if (optind + 1 < argc) {
        fprintf(stderr, "rtspheres render: one scene at a time; unexpected '%s'\n", argv[optind + 1]);
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    const char *scene_path = argv[optind];
    if (output == NULL) {
        fprintf(stderr, "rtspheres render: no output file; add -o OUTPUT (.exr, .png, .jpg, .hdr, .tif)\n");
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    if (!known_output(output)) {
        fprintf(stderr, "rtspheres render: cannot tell the format of '%s'; use .exr, .hdr, .png, .jpg or .tif\n",
                output);
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    if (!output_directory_writable(output)) {
        fprintf(stderr, "rtspheres render: cannot write '%s': its directory does not exist or is not writable\n",
                output);
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }
    if (same_file(output, scene_path)) {
        fprintf(stderr, "rtspheres render: the output '%s' is the scene file; refusing to overwrite it\n", output);
        exit_code = EXIT_BAD_INPUT;
        goto done;
    }

    scene_parse_options parse_options = scene_parse_options_defaults();
    parse_options.defines = defines;
    parse_options.define_count = define_count;
    scene s;
    rt_error error = {{0}};
    rt_status status = scene_load_file(scene_path, &parse_options, &s, &error);
    if (status != RT_OK) {
        fprintf(stderr, "%s\n", error.message);
        exit_code = exit_code_for_status(status);
        goto done;
    }
    if (spp) s.render.samples_per_pixel = (int)spp;
    if (width) { s.render.width = (int)width; s.render.height = (int)height; }
    if (max_depth) s.render.max_depth = (int)max_depth;
    if (seed >= 0) s.render.seed = (uint32_t)seed;

    gpu_options gpu = gpu_options_defaults();
    gpu.device = device >= 0 ? (int)device + 1 : 0;
    gpu.debug_output = verbose;
    gpu.log = log_to_stderr;
    gpu_context *context = NULL;
    status = gpu_create(&gpu, &context, &error);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        scene_free(&s);
        exit_code = exit_code_for_status(status);
        goto done;
    }
    if (verbose) {
        gpu_info info;
        gpu_get_info(context, &info);
        fprintf(stderr, "rtspheres: rendering on %s (%s, %s)\n", info.gl_renderer, info.platform, info.gl_version);
    }

    progress_state progress = {.tty = !quiet && isatty(STDERR_FILENO), .last_draw = -1};
    render_options options = render_options_defaults();
    options.pass_work_budget = (uint32_t)pass_budget;
    options.russian_roulette_depth = (uint32_t)roulette_depth;
    options.progress = draw_progress;
    options.progress_context = &progress;
    options.stop_requested = &stop_requested;
    stop_requested = 0;
    signal(SIGINT, on_stop_signal);
    signal(SIGTERM, on_stop_signal);
    render_result result;
    status = render_scene(context, &s, &options, &result, &error);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    gpu_destroy(context);
    if (progress.tty)
        fprintf(stderr, "\n");
    if (status != RT_OK && status != RT_ERROR_INTERRUPTED) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        scene_free(&s);
        exit_code = exit_code_for_status(status);
        goto done;
    }
    rt_status render_status = status;

    /* 8-bit formats get the colour channels only; float formats keep the sample counts. */
    rt_image colour = result.image;
    rt_image rgb = {0};
    if (!is_float_output(output) || strcasecmp(strrchr(output, '.'), ".hdr") == 0) {
        if (image_create(&rgb, result.image.width, result.image.height, 3, &error) != RT_OK) {
            fprintf(stderr, "rtspheres render: %s\n", error.message);
            image_free(&result.image);
            scene_free(&s);
            exit_code = EXIT_RUNTIME;
            goto done;
        }
        size_t pixel_count = (size_t)rgb.width * rgb.height;
        for (size_t i = 0; i < pixel_count; i++)
            for (int c = 0; c < 3; c++)
                rgb.pixels[3 * i + c] = result.image.pixels[4 * i + c];
        colour = rgb;
    }
    /* Counters beyond 2^31 would not fit an EXR int attribute: they are written as text. */
    char samples_text[32], segments_text[32], seed_text[16];
    snprintf(seed_text, sizeof seed_text, "%u", s.render.seed);
    snprintf(samples_text, sizeof samples_text, "%llu", (unsigned long long)result.samples);
    snprintf(segments_text, sizeof segments_text, "%.0f", result.path_segments);
    image_attribute attributes[] = {
        {.name = "rtspheres:version", .type = IMAGE_ATTRIBUTE_STRING, .string_value = RTSPHERES_VERSION},
        {.name = "rtspheres:scene", .type = IMAGE_ATTRIBUTE_STRING, .string_value = scene_path},
        {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = s.render.samples_per_pixel},
        {.name = "rtspheres:seed", .type = IMAGE_ATTRIBUTE_STRING, .string_value = seed_text},
        {.name = "rtspheres:max_depth", .type = IMAGE_ATTRIBUTE_INT, .int_value = s.render.max_depth},
        {.name = "rtspheres:sample_start", .type = IMAGE_ATTRIBUTE_INT, .int_value = 0},
        {.name = "rtspheres:samples_finished", .type = IMAGE_ATTRIBUTE_STRING, .string_value = samples_text},
        {.name = "rtspheres:path_segments", .type = IMAGE_ATTRIBUTE_STRING, .string_value = segments_text},
        {.name = "rtspheres:complete", .type = IMAGE_ATTRIBUTE_INT, .int_value = render_status == RT_OK},
        {.name = "rtspheres:render_seconds", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = result.seconds},
    };
    image_write_options write_options = image_write_options_defaults();
    write_options.exposure = (float)exposure;
    write_options.attributes = attributes;
    write_options.attribute_count = (int)(sizeof attributes / sizeof attributes[0]);
    status = image_write(output, &colour, &write_options, &error);
    image_free(&rgb);
    image_free(&result.image);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        scene_free(&s);
        exit_code = exit_code_for_status(status);
        goto done;
    }
    if (render_status == RT_ERROR_INTERRUPTED) {
        fprintf(stderr, "rtspheres render: interrupted: wrote the %llu samples finished so far to %s\n",
                (unsigned long long)result.samples, output);
        exit_code = EXIT_RUNTIME;
    } else if (!quiet) {
        fprintf(stderr, "rtspheres: %s -> %s: %dx%d, %d spp in %.2f s (%.3g samples/s, %.3g path segments/s, %d pass%s)\n",
                scene_path, output, s.render.width, s.render.height, s.render.samples_per_pixel, result.seconds,
                result.samples / result.seconds, result.path_segments / result.seconds, result.passes,
                result.passes == 1 ? "" : "es");
    }
    scene_free(&s);

done:
    for (int i = 0; i < define_count; i++)
        free(define_copies[i]);
    return exit_code;
}
