/* command_render.c: `rtspheres render SCENE -o OUTPUT [options]`: parses options, loads
 * the scene (once per frame), renders it on one GPU context and writes the images.
 * Turns every failure into a message on stderr and an exit code (0 ok, 1 runtime or
 * interrupted, 2 bad input). */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "batch.h"
#include "clock.h"
#include "commands.h"
#include "gpu.h"
#include "image_io.h"
#include "postprocess.h"
#include "render.h"
#include "scene_assets.h"
#include "scene_parse.h"
#include "version.h"

#define MAX_DEFINES 256
#define DEFAULT_FRAMES_PER_SECOND 24.0

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres render SCENE -o OUTPUT [options]\n"
            "\n"
            "Renders the scene file SCENE and writes OUTPUT; the format follows the extension:\n"
            ".exr (linear float, with metadata and a per-pixel 'samples' channel), .hdr,\n"
            ".png/.jpg/.tif (8-bit sRGB).\n"
            "\n"
            "options (--spp, --size, --max-depth, --seed override the scene's `render` line):\n"
            "  -o, --output FILE      the image to write (required); a name pattern such as\n"
            "                         frame-%%04d.png gets each frame's number with --frames,\n"
            "                         else the value of -D frame=N, else 0 (%%%% for a '%%')\n"
            "  -s, --spp N            samples per pixel\n"
            "      --size WxH         image size in pixels, e.g. 640x360\n"
            "      --max-depth N      path segments per sample at most\n"
            "      --seed N           random seed (same seed, same image)\n"
            "  -D NAME=VALUE          set scene variable $NAME (wins over the file's `set`)\n"
            "      --frames LIST      render frames, e.g. 1-60 or 1-10,15,20-30:2; each frame\n"
            "                         sets $frame and $time (= frame / --fps)\n"
            "      --fps F            frames per second for $time (default 24)\n"
            "      --samples S:C      render only sample indices S .. S+C-1 of each pixel\n"
            "                         (parts merge exactly with `rtspheres merge`)\n"
            "      --crop x0,y0,x1,y1 render only that region (row 0 at the top, x1/y1 exclusive)\n"
            "      --tile I/N         render horizontal band I of N (0-based)\n"
            "      --shard I/N        part I of N of the work (see --shard-by); for job arrays\n"
            "      --shard-by KIND    frames, samples or tiles (default: frames when --frames\n"
            "                         lists several, otherwise samples)\n"
            "      --checkpoint SECS  every SECS seconds, write the image so far to\n"
            "                         OUTPUT-without-extension.partial.exr\n"
            "      --resume PARTIAL   continue a partial render (a checkpoint, or what Ctrl-C\n"
            "                         wrote); the result equals an uninterrupted render\n"
            "      --exposure STOPS   brighten 8-bit outputs by 2^STOPS (default 0)\n"
            "      --integrator path|whitted  path tracing (default), or Whitted recursive ray\n"
            "                         tracing with Phong shading, shadow rays to every light and\n"
            "                         soft shadows from area lights: fast, nearly noise-free\n"
            "      --aovs             add layers to the EXR: albedo, normal, depth (first hit) and\n"
            "                         per-pixel variance of luminance, next to R, G, B, samples\n"
            "      --denoise          edge-aware a-trous denoiser guided by albedo, normal and depth\n"
            "                         (an EXR keeps the noisy image as noisy.R/G/B)\n"
            "      --blur SIGMA[:N]   Gaussian blur of SIGMA pixels, N times (the seed's blurNum);\n"
            "                         off by default\n"
            "      --tonemap OP       for 8-bit outputs: clamp (default), reinhard or aces\n"
            "      --light-sampling on|off  sample lights at diffuse hits (next-event\n"
            "                         estimation with MIS; default on): less noise, same image\n"
            "      --roulette-depth N paths may end at random (Russian roulette, unbiased)\n"
            "                         after N segments (default 4)\n"
            "      --full-tracer      compile the whole tracer, also the code this scene cannot\n"
            "                         reach (lights, volumes, textures); the image is the same,\n"
            "                         only slower: for checking exactly that\n"
            "      --pass-budget N    fixed work units per pixel per GPU pass (default: adapted\n"
            "                         so a pass takes about 0.25 s, 1 s on llvmpipe; the image is the same)\n"
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

/* Everything the command line asked for; zero/negative means "not given". */
typedef struct render_request {
    const char *scene_path;
    const char *output;          /* the -o name; without --frames, its expansion (see batch.h) */
    char output_name[4096];      /* the expanded name without --frames */
    const char *frame_define;    /* VALUE of the last -D frame=VALUE, or NULL */
    const char *time_define;     /* VALUE of the last -D time=VALUE, or NULL */
    long long spp, width, height, max_depth, seed;
    long long pass_budget, device, roulette_depth;
    double exposure;
    double frames_per_second;
    bool quiet, verbose;
    scene_define defines[MAX_DEFINES + 2];
    char *define_copies[MAX_DEFINES];
    int define_count;
    frame_list frames;           /* empty: one image, no $frame */
    bool has_samples;
    long long sample_start, sample_count;
    bool has_crop;
    int crop[4];
    int tile_index, tile_count;  /* tile_count 0: no --tile */
    int shard_index, shard_count;
    const char *shard_by;
    double checkpoint_seconds;   /* 0: no checkpoints */
    bool no_light_sampling;
    bool full_tracer;
    render_integrator integrator;
    bool aovs;
    bool denoise;
    float blur_sigma;            /* 0: no blur */
    int blur_passes;
    postprocess_tonemap_operator tonemap;
    const char *resume_path;     /* NULL: start afresh */
} render_request;

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
    double last_draw;
    const char *label;
    double command_start;        /* monotonic seconds when the command started */
    double first_pass;           /* seconds from the command's start to the first pass's end */
} progress_state;

static double command_start_seconds;

static void draw_progress(void *context, const render_progress *progress)
{
    progress_state *state = context;
    if (progress->passes == 1)
        state->first_pass = clock_seconds() - state->command_start;
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
    fprintf(stderr, "\r%s[%s] %5.1f%%  %llu/%llu samples  %.1f s elapsed, ETA %.1f s ", state->label, bar,
            100.0 * fraction, (unsigned long long)progress->samples_done, (unsigned long long)progress->samples_total,
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

/* True when a file can be created in the directory part of path, so a bad -o is found
 * before the render rather than after it. It creates and removes a probe file instead of
 * asking access(): for root, access() approves directories such as /proc and /sys in
 * which no file can be created. */
static bool output_directory_writable(const char *path)
{
    const char *slash = strrchr(path, '/');
    char probe[4096];
    int length = slash == NULL ? snprintf(probe, sizeof probe, ".rtspheres-probe-XXXXXX")
                               : snprintf(probe, sizeof probe, "%.*s/.rtspheres-probe-XXXXXX",
                                          (int)(slash - path), path);
    if (length < 0 || (size_t)length >= sizeof probe)
        return false;
    int descriptor = mkstemp(probe);
    if (descriptor < 0)
        return false;
    close(descriptor);
    unlink(probe);
    return true;
}

static const char *extension_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot != NULL && strchr(dot, '/') == NULL ? dot : "";
}

static bool keeps_sample_counts(const char *path)
{
    return strcasecmp(extension_of(path), ".exr") == 0;
}

static bool known_output(const char *path)
{
    static const char *const extensions[] = {".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    for (size_t i = 0; i < sizeof extensions / sizeof extensions[0]; i++)
        if (strcasecmp(extension_of(path), extensions[i]) == 0)
            return true;
    return false;
}

/* Parses the options into *request. Returns EXIT_OK, or an exit code after printing why;
 * *help_shown is set when --help was handled. */
static int parse_arguments(int argc, char **argv, render_request *request, bool *help_shown)
{
    enum {
        OPTION_SIZE = 256, OPTION_MAX_DEPTH, OPTION_SEED, OPTION_EXPOSURE, OPTION_PASS_BUDGET, OPTION_DEVICE,
        OPTION_ROULETTE_DEPTH, OPTION_FRAMES, OPTION_FPS, OPTION_SAMPLES, OPTION_CROP, OPTION_TILE, OPTION_SHARD,
        OPTION_SHARD_BY, OPTION_CHECKPOINT, OPTION_RESUME, OPTION_LIGHT_SAMPLING, OPTION_INTEGRATOR, OPTION_AOVS,
        OPTION_DENOISE, OPTION_BLUR, OPTION_TONEMAP, OPTION_FULL_TRACER,
    };
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
        {"frames", required_argument, NULL, OPTION_FRAMES},
        {"fps", required_argument, NULL, OPTION_FPS},
        {"samples", required_argument, NULL, OPTION_SAMPLES},
        {"crop", required_argument, NULL, OPTION_CROP},
        {"tile", required_argument, NULL, OPTION_TILE},
        {"shard", required_argument, NULL, OPTION_SHARD},
        {"shard-by", required_argument, NULL, OPTION_SHARD_BY},
        {"checkpoint", required_argument, NULL, OPTION_CHECKPOINT},
        {"resume", required_argument, NULL, OPTION_RESUME},
        {"light-sampling", required_argument, NULL, OPTION_LIGHT_SAMPLING},
        {"full-tracer", no_argument, NULL, OPTION_FULL_TRACER},
        {"integrator", required_argument, NULL, OPTION_INTEGRATOR},
        {"aovs", no_argument, NULL, OPTION_AOVS},
        {"denoise", no_argument, NULL, OPTION_DENOISE},
        {"blur", required_argument, NULL, OPTION_BLUR},
        {"tonemap", required_argument, NULL, OPTION_TONEMAP},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    rt_error error = {{0}};
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, "o:s:D:qvh", long_options, NULL)) != -1) {
        const char *complaint = NULL;
        switch (option) {
        case 'o':
            request->output = optarg;
            break;
        case 's':
            if (parse_integer(optarg, 1, 1 << 30, &request->spp))
                complaint = "--spp wants a whole number from 1 to 1073741824";
            break;
        case OPTION_SIZE: {
            char copy[64];
            snprintf(copy, sizeof copy, "%s", optarg);
            char *separator = strchr(copy, 'x');
            if (separator)
                *separator = '\0';
            if (!separator || parse_integer(copy, 1, 16384, &request->width)
                || parse_integer(separator + 1, 1, 16384, &request->height))
                complaint = "--size wants WIDTHxHEIGHT, each 1 to 16384, e.g. 640x360";
            break;
        }
        case OPTION_MAX_DEPTH:
            if (parse_integer(optarg, 1, 100000, &request->max_depth))
                complaint = "--max-depth wants a whole number from 1 to 100000";
            break;
        case OPTION_SEED:
            if (parse_integer(optarg, 0, UINT32_MAX, &request->seed))
                complaint = "--seed wants a whole number from 0 to 4294967295";
            break;
        case OPTION_PASS_BUDGET:
            if (parse_integer(optarg, 1, 50000, &request->pass_budget))
                complaint = "--pass-budget wants a whole number from 1 to 50000";
            break;
        case OPTION_ROULETTE_DEPTH:
            if (parse_integer(optarg, 1, 100000, &request->roulette_depth))
                complaint = "--roulette-depth wants a whole number from 1 to 100000";
            break;
        case OPTION_DEVICE:
            if (parse_integer(optarg, 0, 255, &request->device))
                complaint = "--device wants a device number (0, 1, ...)";
            break;
        case OPTION_EXPOSURE: {
            char *end = NULL;
            request->exposure = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !isfinite(request->exposure) || fabs(request->exposure) > 64)
                complaint = "--exposure wants a number of stops (-64 to 64)";
            break;
        }
        case OPTION_FPS: {
            char *end = NULL;
            request->frames_per_second = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !(request->frames_per_second > 0)
                || request->frames_per_second > 1e6)
                complaint = "--fps wants a positive number of frames per second";
            break;
        }
        case OPTION_CHECKPOINT: {
            char *end = NULL;
            request->checkpoint_seconds = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !(request->checkpoint_seconds > 0) || request->checkpoint_seconds > 1e7)
                complaint = "--checkpoint wants a positive number of seconds";
            break;
        }
        case OPTION_RESUME:
            request->resume_path = optarg;
            break;
        case OPTION_AOVS:
            request->aovs = true;
            break;
        case OPTION_DENOISE:
            request->denoise = true;
            break;
        case OPTION_BLUR: {
            char extra;
            float sigma = 0;
            int passes = 1;
            int read = sscanf(optarg, "%f:%d%c", &sigma, &passes, &extra);
            if ((read != 1 && read != 2) || !(sigma > 0) || sigma > POSTPROCESS_MAX_BLUR_SIGMA || passes < 1
                || passes > 100)
                complaint = "--blur wants SIGMA or SIGMA:PASSES, e.g. 1.5 or 1:3 (sigma in pixels, > 0)";
            request->blur_sigma = sigma;
            request->blur_passes = passes;
            break;
        }
        case OPTION_TONEMAP:
            if (strcmp(optarg, "clamp") == 0)
                request->tonemap = TONEMAP_CLAMP;
            else if (strcmp(optarg, "reinhard") == 0)
                request->tonemap = TONEMAP_REINHARD;
            else if (strcmp(optarg, "aces") == 0)
                request->tonemap = TONEMAP_ACES;
            else
                complaint = "--tonemap wants clamp, reinhard or aces";
            break;
        case OPTION_INTEGRATOR:
            if (strcmp(optarg, "path") == 0)
                request->integrator = INTEGRATOR_PATH;
            else if (strcmp(optarg, "whitted") == 0)
                request->integrator = INTEGRATOR_WHITTED;
            else
                complaint = "--integrator wants path or whitted";
            break;
        case OPTION_FULL_TRACER:
            request->full_tracer = true;
            break;
        case OPTION_LIGHT_SAMPLING:
            if (strcmp(optarg, "on") != 0 && strcmp(optarg, "off") != 0)
                complaint = "--light-sampling wants on or off";
            request->no_light_sampling = strcmp(optarg, "off") == 0;
            break;
        case OPTION_FRAMES:
            frame_list_free(&request->frames);
            if (frame_list_parse(optarg, &request->frames, &error) != RT_OK) {
                fprintf(stderr, "rtspheres render: --%s\n", error.message);
                return EXIT_BAD_INPUT;
            }
            break;
        case OPTION_SAMPLES: {
            char copy[64];
            snprintf(copy, sizeof copy, "%s", optarg);
            char *separator = strchr(copy, ':');
            if (separator)
                *separator = '\0';
            if (!separator || parse_integer(copy, 0, UINT32_MAX - 1, &request->sample_start)
                || parse_integer(separator + 1, 1, 1 << 30, &request->sample_count)
                || request->sample_start + request->sample_count > UINT32_MAX)
                complaint = "--samples wants START:COUNT, e.g. 512:512 (COUNT at least 1)";
            request->has_samples = true;
            break;
        }
        case OPTION_CROP: {
            char extra;
            int *c = request->crop;
            if (sscanf(optarg, "%d,%d,%d,%d%c", &c[0], &c[1], &c[2], &c[3], &extra) != 4 || c[0] < 0 || c[1] < 0
                || c[2] <= c[0] || c[3] <= c[1])
                complaint = "--crop wants x0,y0,x1,y1 with x0 < x1 and y0 < y1 (row 0 at the top)";
            request->has_crop = true;
            break;
        }
        case OPTION_TILE:
            if (shard_parse(optarg, &request->tile_index, &request->tile_count, &error) != RT_OK) {
                fprintf(stderr, "rtspheres render: --tile %s\n", error.message);
                return EXIT_BAD_INPUT;
            }
            break;
        case OPTION_SHARD:
            if (shard_parse(optarg, &request->shard_index, &request->shard_count, &error) != RT_OK) {
                fprintf(stderr, "rtspheres render: --shard %s\n", error.message);
                return EXIT_BAD_INPUT;
            }
            break;
        case OPTION_SHARD_BY:
            if (strcmp(optarg, "frames") != 0 && strcmp(optarg, "samples") != 0 && strcmp(optarg, "tiles") != 0)
                complaint = "--shard-by wants frames, samples or tiles";
            request->shard_by = optarg;
            break;
        case 'D': {
            const char *equals = strchr(optarg, '=');
            if (equals == NULL || equals == optarg || equals[1] == '\0') {
                complaint = "-D wants NAME=VALUE, e.g. -D aperture=0.1";
                break;
            }
            if (request->define_count == MAX_DEFINES) {
                complaint = "too many -D options";
                break;
            }
            char *copy = strdup(optarg);
            if (copy == NULL) {
                fprintf(stderr, "rtspheres render: out of memory\n");
                return EXIT_RUNTIME;
            }
            copy[equals - optarg] = '\0';
            request->define_copies[request->define_count] = copy;
            if (strcmp(copy, "frame") == 0)
                request->frame_define = copy + (equals - optarg) + 1;
            else if (strcmp(copy, "time") == 0)
                request->time_define = copy + (equals - optarg) + 1;
            request->defines[request->define_count] =
                (scene_define){.name = copy, .value = copy + (equals - optarg) + 1};
            request->define_count++;
            break;
        }
        case 'q':
            request->quiet = true;
            break;
        case 'v':
            request->verbose = true;
            break;
        case 'h':
            print_help(stdout);
            *help_shown = true;
            return EXIT_OK;
        default:
            return EXIT_BAD_INPUT;
        }
        if (complaint != NULL) {
            fprintf(stderr, "rtspheres render: %s, not '%s'\n", complaint, optarg);
            return EXIT_BAD_INPUT;
        }
    }
    if (optind >= argc) {
        fprintf(stderr, "rtspheres render: which scene? usage: rtspheres render SCENE -o OUTPUT\n");
        return EXIT_BAD_INPUT;
    }
    if (optind + 1 < argc) {
        fprintf(stderr, "rtspheres render: one scene at a time; unexpected '%s'\n", argv[optind + 1]);
        return EXIT_BAD_INPUT;
    }
    request->scene_path = argv[optind];
    const char *output = request->output;
    if (output == NULL) {
        fprintf(stderr, "rtspheres render: no output file; add -o OUTPUT (.exr, .png, .jpg, .hdr, .tif)\n");
        return EXIT_BAD_INPUT;
    }
    /* Every output name is a pattern (batch.h): with --frames each frame formats it; without
     * them it is formatted once, with the value of -D frame=N or with 0. */
    if (request->frames.count > 0) {
        if (request->frame_define != NULL || request->time_define != NULL) {
            fprintf(stderr, "rtspheres render: -D %s and --frames both set $%s (--frames sets $frame and $time); "
                            "give one\n", request->frame_define != NULL ? "frame" : "time",
                    request->frame_define != NULL ? "frame" : "time");
            return EXIT_BAD_INPUT;
        }
        /* The checks below look at the first frame's name. */
        if (output_pattern_format(output, request->frames.frames[0], request->output_name,
                                  sizeof request->output_name, &error) != RT_OK) {
            fprintf(stderr, "rtspheres render: %s\n", error.message);
            return EXIT_BAD_INPUT;
        }
        if (request->frames.count > 1 && !output_pattern_has_frame(output)) {
            fprintf(stderr, "rtspheres render: %d frames would all write '%s'; put a frame number pattern in the "
                            "output, e.g. frame-%%04d.png\n", request->frames.count, output);
            return EXIT_BAD_INPUT;
        }
    } else {
        if (output_name_without_frames(output, request->frame_define, request->output_name,
                                       sizeof request->output_name, &error) != RT_OK) {
            fprintf(stderr, "rtspheres render: %s\n", error.message);
            return EXIT_BAD_INPUT;
        }
        request->output = request->output_name;
    }
    output = request->output_name;
    if (!known_output(output)) {
        fprintf(stderr, "rtspheres render: cannot tell the format of '%s'; use .exr, .hdr, .png, .jpg or .tif\n",
                output);
        return EXIT_BAD_INPUT;
    }
    if (!output_directory_writable(output)) {
        fprintf(stderr, "rtspheres render: cannot write '%s': its directory does not exist or is not writable\n",
                output);
        return EXIT_BAD_INPUT;
    }
    if (same_file(output, request->scene_path)) {
        fprintf(stderr, "rtspheres render: the output '%s' is the scene file; refusing to overwrite it\n", output);
        return EXIT_BAD_INPUT;
    }
    if (request->has_crop && request->tile_count) {
        fprintf(stderr, "rtspheres render: --crop and --tile both choose the region; give one\n");
        return EXIT_BAD_INPUT;
    }
    if (request->aovs && strcasecmp(extension_of(output), ".exr") != 0) {
        fprintf(stderr, "rtspheres render: --aovs writes extra layers, which only .exr keeps; not '%s'\n", output);
        return EXIT_BAD_INPUT;
    }
    if (request->resume_path != NULL && request->frames.count > 1) {
        fprintf(stderr, "rtspheres render: --resume continues one image; render the frames one at a time\n");
        return EXIT_BAD_INPUT;
    }
    if (request->shard_by != NULL && request->shard_count == 0) {
        fprintf(stderr, "rtspheres render: --shard-by %s does nothing without --shard I/N\n", request->shard_by);
        return EXIT_BAD_INPUT;
    }
    if (request->shard_count) {
        const char *by = request->shard_by ? request->shard_by : request->frames.count > 1 ? "frames" : "samples";
        request->shard_by = by;
        if (strcmp(by, "frames") == 0 && request->frames.count == 0) {
            fprintf(stderr, "rtspheres render: --shard-by frames needs --frames\n");
            return EXIT_BAD_INPUT;
        }
        /* As with an empty sample shard or tile: a part with nothing to render is an error,
         * not a silent success that writes nothing. */
        if (strcmp(by, "frames") == 0 && request->shard_index >= request->frames.count) {
            fprintf(stderr, "rtspheres render: shard %d/%d of %d frame%s is empty; use fewer shards\n",
                    request->shard_index, request->shard_count, request->frames.count,
                    request->frames.count == 1 ? "" : "s");
            return EXIT_BAD_INPUT;
        }
        if (strcmp(by, "samples") == 0 && request->has_samples) {
            fprintf(stderr, "rtspheres render: --shard by samples and --samples both choose the samples; give one\n");
            return EXIT_BAD_INPUT;
        }
        if (strcmp(by, "tiles") == 0 && (request->has_crop || request->tile_count)) {
            fprintf(stderr, "rtspheres render: --shard by tiles and --crop/--tile both choose the region; give one\n");
            return EXIT_BAD_INPUT;
        }
        if (strcmp(by, "tiles") == 0) {
            request->tile_index = request->shard_index;
            request->tile_count = request->shard_count;
        }
    }
    return EXIT_OK;
}

/* What an output file records about the render that made it. */
typedef struct render_job {
    const render_request *request;
    const scene *scene;
    int frame;
    long long sample_start;
} render_job;

/* The partial file of an output: the name without its extension + ".partial.exr". */
static void partial_path_for(const char *output, char *path, size_t size)
{
    const char *extension = extension_of(output);
    snprintf(path, size, "%.*s.partial.exr", (int)(strlen(output) - strlen(extension)), output);
}

/* Writes image (R, G, B means, samples) to path with the rtspheres metadata; 8-bit and
 * HDR formats get the colour channels only. complete says whether every sample ran. */
static rt_status write_render(const render_job *job, const rt_image *image, const char *path, uint64_t samples,
                              bool complete, const render_result *result, rt_error *error)
{
    const scene *s = job->scene;
    rt_image colour = *image;
    rt_image rgb = {0};
    if (keeps_sample_counts(path) && result->aovs.pixels != NULL) {
        /* EXR with AOVs: the colour and sample count, then the AOV layers. */
        rt_status status = image_append_channels(image, &result->aovs, &rgb, error);
        if (status != RT_OK)
            return status;
        colour = rgb;
    } else if (!keeps_sample_counts(path)) {
        rt_status status = image_create(&rgb, image->width, image->height, 3, error);
        if (status != RT_OK)
            return status;
        size_t pixel_count = (size_t)rgb.width * rgb.height;
        for (size_t i = 0; i < pixel_count; i++)
            for (int c = 0; c < 3; c++)
                rgb.pixels[3 * i + c] = image->pixels[4 * i + c];
        colour = rgb;
    }
    colour.x = result->region[0];
    colour.y = result->region[1];
    colour.full_width = s->render.width;
    colour.full_height = s->render.height;

    /* Counters beyond 2^31 would not fit an EXR int attribute: they are written as text. */
    char samples_text[32], segments_text[32], seed_text[16], sample_start_text[16], hash_text[24];
    snprintf(seed_text, sizeof seed_text, "%u", s->render.seed);
    snprintf(samples_text, sizeof samples_text, "%llu", (unsigned long long)samples);
    snprintf(segments_text, sizeof segments_text, "%.0f", result->path_segments);
    snprintf(sample_start_text, sizeof sample_start_text, "%llu", (unsigned long long)job->sample_start);
    snprintf(hash_text, sizeof hash_text, "%016llx", (unsigned long long)result->scene_hash);
    image_attribute attributes[] = {
        {.name = "rtspheres:version", .type = IMAGE_ATTRIBUTE_STRING, .string_value = RTSPHERES_VERSION},
        {.name = "rtspheres:scene", .type = IMAGE_ATTRIBUTE_STRING, .string_value = job->request->scene_path},
        {.name = "rtspheres:scene_hash", .type = IMAGE_ATTRIBUTE_STRING, .string_value = hash_text},
        {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = s->render.samples_per_pixel},
        {.name = "rtspheres:sample_start", .type = IMAGE_ATTRIBUTE_STRING, .string_value = sample_start_text},
        {.name = "rtspheres:seed", .type = IMAGE_ATTRIBUTE_STRING, .string_value = seed_text},
        {.name = "rtspheres:max_depth", .type = IMAGE_ATTRIBUTE_INT, .int_value = s->render.max_depth},
        {.name = "rtspheres:frame", .type = IMAGE_ATTRIBUTE_INT, .int_value = job->frame},
        {.name = "rtspheres:samples_finished", .type = IMAGE_ATTRIBUTE_STRING, .string_value = samples_text},
        {.name = "rtspheres:path_segments", .type = IMAGE_ATTRIBUTE_STRING, .string_value = segments_text},
        {.name = "rtspheres:complete", .type = IMAGE_ATTRIBUTE_INT, .int_value = complete},
        {.name = "rtspheres:render_seconds", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = result->seconds},
    };
    image_write_options write_options = image_write_options_defaults();
    /* With a tone-mapping operator the exposure was applied before it. */
    write_options.exposure = job->request->tonemap != TONEMAP_CLAMP ? 0.0f : (float)job->request->exposure;
    write_options.attributes = attributes;
    write_options.attribute_count = (int)(sizeof attributes / sizeof attributes[0]);
    rt_status status = image_write(path, &colour, &write_options, error);
    image_free(&rgb);
    return status;
}

typedef struct checkpoint_state {
    const render_job *job;
    const char *path;
    int region[4];
    bool quiet;
} checkpoint_state;

/* render_options.checkpoint: writes the image so far to the partial file. */
static rt_status write_checkpoint(void *context, const rt_image *partial, uint64_t samples, uint64_t scene_hash,
                                  rt_error *error)
{
    checkpoint_state *state = context;
    render_result result = {.scene_hash = scene_hash};
    memcpy(result.region, state->region, sizeof result.region);
    rt_status status = write_render(state->job, partial, state->path, samples, false, &result, error);
    if (status == RT_OK && !state->quiet && !isatty(STDERR_FILENO))
        fprintf(stderr, "rtspheres: checkpoint: %llu samples in %s\n", (unsigned long long)samples, state->path);
    return status;
}

/* Reads a partial render for --resume and checks it belongs to this render (seed, first
 * sample, samples per pixel, region). Returns an exit code after printing why. */
static int load_resume(const char *path, const scene *s, long long sample_start, const int region[4],
                       rt_image *image, uint64_t *scene_hash)
{
    rt_error error = {{0}};
    if (image_read(path, image, &error) != RT_OK) {
        fprintf(stderr, "rtspheres render: --resume: %s\n", error.message);
        return EXIT_BAD_INPUT;
    }
    char seed[32] = "", start[32] = "", spp[32] = "", hash[32] = "";
    image_read_attribute(path, "rtspheres:seed", seed, sizeof seed, NULL);
    image_read_attribute(path, "rtspheres:sample_start", start, sizeof start, NULL);
    image_read_attribute(path, "rtspheres:spp", spp, sizeof spp, NULL);
    image_read_attribute(path, "rtspheres:scene_hash", hash, sizeof hash, NULL);
    const char *problem = NULL;
    char expected[64];
    if (hash[0] == '\0')
        problem = "it has no rtspheres metadata (was it written by rtspheres render to .exr?)";
    else if (strtoull(seed, NULL, 10) != s->render.seed)
        snprintf(expected, sizeof expected, "seed %s, this render %u", seed, s->render.seed), problem = expected;
    else if (strtoll(start, NULL, 10) != sample_start)
        snprintf(expected, sizeof expected, "first sample %s, this render %lld", start, sample_start),
            problem = expected;
    else if (strtoll(spp, NULL, 10) != s->render.samples_per_pixel)
        snprintf(expected, sizeof expected, "%s spp, this render %d", spp, s->render.samples_per_pixel),
            problem = expected;
    else if (image->x != region[0] || image->y != region[1] || image->width != region[2] - region[0]
             || image->height != region[3] - region[1])
        problem = "it covers another region of the image (size or crop differ)";
    if (problem != NULL) {
        fprintf(stderr, "rtspheres render: --resume %s does not belong to this render: %s\n", path, problem);
        image_free(image);
        return EXIT_BAD_INPUT;
    }
    *scene_hash = strtoull(hash, NULL, 16);
    return EXIT_OK;
}

/* Copies channels [first, first + count) of image into a new image (*out; the caller
 * frees it). */
static rt_status copy_channels(const rt_image *image, int first, int count, rt_image *out, rt_error *error)
{
    rt_status status = image_create(out, image->width, image->height, count, error);
    if (status != RT_OK)
        return status;
    size_t pixels = (size_t)image->width * image->height;
    for (size_t i = 0; i < pixels; i++)
        for (int c = 0; c < count; c++)
            out->pixels[i * count + c] = image->pixels[i * image->channels + first + c];
    return RT_OK;
}

/* Applies --denoise, --blur and --tonemap to the result's colour (R, G, B of a
 * 4-channel image), in that order. With --denoise the noisy colour joins the AOVs as
 * noisy.R/G/B, so an EXR keeps it. Tone mapping applies to 8-bit outputs only. */
static rt_status postprocess_result(const render_request *request, const char *output, render_result *result,
                                    rt_error *error)
{
    bool eight_bit = strcasecmp(extension_of(output), ".exr") != 0 && strcasecmp(extension_of(output), ".hdr") != 0;
    bool tonemap = eight_bit && request->tonemap != TONEMAP_CLAMP;
    if (!request->denoise && request->blur_sigma <= 0 && !tonemap)
        return RT_OK;
    rt_image colour, albedo = {0}, normal = {0}, depth = {0}, noisy = {0}, joined = {0};
    rt_status status = copy_channels(&result->image, 0, 3, &colour, error);
    if (status == RT_OK && request->denoise) {
        status = copy_channels(&result->image, 0, 3, &noisy, error);
        if (status == RT_OK)
            status = copy_channels(&result->aovs, 0, 3, &albedo, error);
        if (status == RT_OK)
            status = copy_channels(&result->aovs, 3, 3, &normal, error);
        if (status == RT_OK)
            status = copy_channels(&result->aovs, 6, 1, &depth, error);
        if (status == RT_OK)
            status = postprocess_denoise(&colour, &albedo, &normal, &depth, NULL, error);
        if (status == RT_OK) {
            static const char *const names[3] = {"noisy.R", "noisy.G", "noisy.B"};
            for (int c = 0; c < 3; c++)
                snprintf(noisy.channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
            status = image_append_channels(&result->aovs, &noisy, &joined, error);
        }
        if (status == RT_OK) {
            image_free(&result->aovs);
            result->aovs = joined;
            joined = (rt_image){0};
        }
    }
    if (status == RT_OK && request->blur_sigma > 0)
        status = postprocess_gaussian_blur(&colour, request->blur_sigma, request->blur_passes, error);
    /* The writer's exposure would apply a second time after tone mapping: done here. */
    if (status == RT_OK && tonemap)
        status = postprocess_tonemap(&colour, request->tonemap, (float)request->exposure, error);
    if (status == RT_OK) {
        size_t pixels = (size_t)colour.width * colour.height;
        for (size_t i = 0; i < pixels; i++)
            for (int c = 0; c < 3; c++)
                result->image.pixels[4 * i + c] = colour.pixels[3 * i + c];
    }
    image_free(&colour);
    image_free(&albedo);
    image_free(&normal);
    image_free(&depth);
    image_free(&noisy);
    image_free(&joined);
    return status;
}

/* Renders one image (one frame, or the only image) on context and writes it to output.
 * frame < 0: no --frames. Returns an exit code, after printing why on failure. */
static int render_frame(gpu_context *context, const render_request *request, int frame, const char *output)
{
    scene_define defines[MAX_DEFINES + 2];
    memcpy(defines, request->defines, (size_t)request->define_count * sizeof defines[0]);
    int define_count = request->define_count;
    char frame_text[32], time_text[64];
    if (frame >= 0) {
        double fps = request->frames_per_second > 0 ? request->frames_per_second : DEFAULT_FRAMES_PER_SECOND;
        snprintf(frame_text, sizeof frame_text, "%d", frame);
        snprintf(time_text, sizeof time_text, "%.17g", frame / fps);
        defines[define_count++] = (scene_define){.name = "frame", .value = frame_text, .optional = true};
        defines[define_count++] = (scene_define){.name = "time", .value = time_text, .optional = true};
    }
    scene_parse_options parse_options = scene_parse_options_defaults();
    parse_options.defines = defines;
    parse_options.define_count = define_count;
    scene s;
    rt_error error = {{0}};
    rt_status status = scene_load_file(request->scene_path, &parse_options, &s, &error);
    if (status == RT_OK) {
        status = scene_load_assets(&s, &error);
        if (status != RT_OK)
            scene_free(&s);
    }
    if (status != RT_OK) {
        fprintf(stderr, "%s\n", error.message);
        return exit_code_for_status(status);
    }
    /* Asset warnings (a missing MTL file, ...): once, with the first frame. */
    bool first_frame = frame < 0 || frame == request->frames.frames[0];
    for (int i = 0; i < s.warning_count && first_frame && !request->quiet; i++)
        fprintf(stderr, "rtspheres render: warning: %s\n", s.warnings[i].message);
    if (request->spp) s.render.samples_per_pixel = (int)request->spp;
    if (request->width) { s.render.width = (int)request->width; s.render.height = (int)request->height; }
    if (request->max_depth) s.render.max_depth = (int)request->max_depth;
    if (request->seed >= 0) s.render.seed = (uint32_t)request->seed;

    render_options options = render_options_defaults();
    long long sample_start = 0, sample_count = s.render.samples_per_pixel;
    if (request->has_samples) {
        sample_start = request->sample_start;
        sample_count = request->sample_count;
    } else if (request->shard_count && strcmp(request->shard_by, "samples") == 0) {
        shard_range(request->shard_index, request->shard_count, s.render.samples_per_pixel, &sample_start,
                    &sample_count);
        if (sample_count == 0) {
            fprintf(stderr, "rtspheres render: shard %d/%d of %d samples per pixel is empty; use fewer shards\n",
                    request->shard_index, request->shard_count, s.render.samples_per_pixel);
            scene_free(&s);
            return EXIT_BAD_INPUT;
        }
    }
    options.sample_start = (uint32_t)sample_start;
    s.render.samples_per_pixel = (int)sample_count;
    if (request->has_crop) {
        memcpy(options.region, request->crop, sizeof options.region);
    } else if (request->tile_count) {
        long long row, rows;
        shard_range(request->tile_index, request->tile_count, s.render.height, &row, &rows);
        if (rows == 0) {
            fprintf(stderr, "rtspheres render: tile %d/%d of a %d-row image is empty; use fewer tiles\n",
                    request->tile_index, request->tile_count, s.render.height);
            scene_free(&s);
            return EXIT_BAD_INPUT;
        }
        int band[4] = {0, (int)row, s.render.width, (int)(row + rows)};
        memcpy(options.region, band, sizeof band);
    }
    options.pass_work_budget = (uint32_t)request->pass_budget;
    options.russian_roulette_depth = (uint32_t)request->roulette_depth;
    options.no_light_sampling = request->no_light_sampling;
    options.full_tracer = request->full_tracer;
    options.integrator = request->integrator;
    options.aovs = request->aovs || request->denoise;

    int region[4] = {0, 0, s.render.width, s.render.height};
    if (options.region[2] > 0)
        memcpy(region, options.region, sizeof region);
    render_job job = {.request = request, .scene = &s, .frame = frame, .sample_start = sample_start};
    char partial_path[4096];
    partial_path_for(output, partial_path, sizeof partial_path);
    rt_image resume_image = {0};
    if (request->resume_path != NULL) {
        int code = load_resume(request->resume_path, &s, sample_start, region, &resume_image,
                               &options.resume_scene_hash);
        if (code != EXIT_OK) {
            scene_free(&s);
            return code;
        }
        options.resume = &resume_image;
    }
    checkpoint_state checkpoint = {.job = &job, .path = partial_path, .quiet = request->quiet};
    memcpy(checkpoint.region, region, sizeof region);
    if (request->checkpoint_seconds > 0) {
        options.checkpoint_seconds = request->checkpoint_seconds;
        options.checkpoint = write_checkpoint;
        options.checkpoint_context = &checkpoint;
    }

    char label[64] = "";
    if (frame >= 0)
        snprintf(label, sizeof label, "frame %d ", frame);
    progress_state progress = {.tty = !request->quiet && isatty(STDERR_FILENO), .last_draw = -1, .label = label,
                               .command_start = command_start_seconds};
    options.progress = draw_progress;
    options.progress_context = &progress;
    options.stop_requested = &stop_requested;
    render_result result;
    status = render_scene(context, &s, &options, &result, &error);
    if (progress.tty)
        fprintf(stderr, "\n");
    if (status != RT_OK && status != RT_ERROR_INTERRUPTED) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        image_free(&resume_image);
        scene_free(&s);
        return exit_code_for_status(status);
    }
    rt_status render_status = status;
    status = postprocess_result(request, output, &result, &error);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        image_free(&result.image);
        image_free(&result.aovs);
        image_free(&resume_image);
        scene_free(&s);
        return exit_code_for_status(status);
    }

    int exit_code = EXIT_OK;
    if (render_status == RT_ERROR_INTERRUPTED) {
        /* The partial goes next to the output, never over it: the user's last good image
         * stays, and --resume continues from the partial. */
        status = write_render(&job, &result.image, partial_path, result.samples, false, &result, &error);
        if (status == RT_OK)
            fprintf(stderr, "rtspheres render: interrupted: wrote the %llu samples finished so far to %s; "
                            "continue with --resume %s\n", (unsigned long long)result.samples, partial_path, partial_path);
        else
            fprintf(stderr, "rtspheres render: interrupted, and the partial could not be written: %s\n", error.message);
        exit_code = EXIT_RUNTIME;
    } else {
        status = write_render(&job, &result.image, output, result.samples, true, &result, &error);
        if (status != RT_OK) {
            fprintf(stderr, "rtspheres render: %s\n", error.message);
            exit_code = exit_code_for_status(status);
        } else {
            /* The checkpoint is ours and now superseded by the complete image. */
            unlink(partial_path);
            if (request->verbose) {
                uint64_t geometry_bytes = result.packed_bytes - result.image_bytes;
                fprintf(stderr,
                        "rtspheres: scene: %u primitives (%u triangles), %u instances, %u lights; BVH depth %d, "
                        "built in %.3f s; packed %llu bytes (%.1f per triangle without images)%s; first pass "
                        "done %.3f s after start (context, parse, BVH, upload, compile); after it %.3f s for "
                        "%llu samples (%.3g us/sample)\n",
                        result.primitive_count, result.triangle_count, result.instance_count, result.light_count,
                        result.bvh_depth, result.bvh_build_seconds, (unsigned long long)result.packed_bytes,
                        result.triangle_count ? (double)geometry_bytes / result.triangle_count : 0.0,
                        result.reused_scene ? ", already on the device" : "", progress.first_pass,
                        result.steady_seconds, (unsigned long long)result.steady_samples,
                        result.steady_samples ? result.steady_seconds / (double)result.steady_samples * 1e6 : 0.0);
            }
            if (!request->quiet)
                fprintf(stderr,
                        "rtspheres: %s -> %s: %dx%d, %d spp in %.2f s (%.3g samples/s, %.3g path segments/s, %d pass%s)\n",
                        request->scene_path, output, result.image.width, result.image.height,
                        s.render.samples_per_pixel, result.seconds, result.samples / result.seconds,
                        result.path_segments / result.seconds, result.passes, result.passes == 1 ? "" : "es");
        }
    }
    image_free(&result.image);
    image_free(&result.aovs);
    image_free(&resume_image);
    scene_free(&s);
    return exit_code;
}

int command_render(int argc, char **argv)
{
    command_start_seconds = clock_seconds();
    render_request request = {.seed = -1, .device = -1};
    bool help_shown = false;
    int exit_code = parse_arguments(argc, argv, &request, &help_shown);
    if (exit_code != EXIT_OK || help_shown)
        goto done;

    /* Handlers go in before the (possibly slow, cold) GPU set-up: a signal then must not
     * kill the process without a word, and one that arrives before the first pass simply
     * ends the render early (nothing is written when no sample finished). */
    stop_requested = 0;
    signal(SIGINT, on_stop_signal);
    signal(SIGTERM, on_stop_signal);

    gpu_options gpu = gpu_options_defaults();
    gpu.device = request.device >= 0 ? (int)request.device + 1 : 0;
    gpu.debug_output = request.verbose;
    gpu.log = log_to_stderr;
    gpu_context *context = NULL;
    rt_error error = {{0}};
    rt_status status = gpu_create(&gpu, &context, &error);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        exit_code = exit_code_for_status(status);
        goto done;
    }
    if (stop_requested) {
        fprintf(stderr, "rtspheres render: interrupted before the render started; nothing written\n");
        gpu_destroy(context);
        exit_code = EXIT_RUNTIME;
        goto done;
    }
    if (request.verbose) {
        gpu_info info;
        gpu_get_info(context, &info);
        fprintf(stderr, "rtspheres: rendering on %s (%s, %s)\n", info.gl_renderer, info.platform, info.gl_version);
    }

    if (request.frames.count == 0) {
        exit_code = render_frame(context, &request, -1, request.output);
    } else {
        double start = clock_seconds();
        int rendered = 0;
        for (int i = 0; i < request.frames.count && exit_code == EXIT_OK && !stop_requested; i++) {
            if (request.shard_count && strcmp(request.shard_by, "frames") == 0 && i % request.shard_count != request.shard_index)
                continue;
            char name[4096];
            rt_error name_error = {{0}};
            if (output_pattern_format(request.output, request.frames.frames[i], name, sizeof name, &name_error)
                != RT_OK) {
                fprintf(stderr, "rtspheres render: %s\n", name_error.message);
                exit_code = EXIT_BAD_INPUT;
                break;
            }
            if (same_file(name, request.scene_path)) {
                fprintf(stderr, "rtspheres render: frame %d's output '%s' is the scene file; refusing to overwrite "
                                "it\n", request.frames.frames[i], name);
                exit_code = EXIT_BAD_INPUT;
                break;
            }
            exit_code = render_frame(context, &request, request.frames.frames[i], name);
            rendered++;
        }
        double seconds = clock_seconds() - start;
        if (stop_requested && exit_code == EXIT_OK)
            exit_code = EXIT_RUNTIME;
        if (!request.quiet && rendered > 0)
            fprintf(stderr, "rtspheres: %d frame%s in %.2f s (%.3g frames/s)\n", rendered, rendered == 1 ? "" : "s",
                    seconds, rendered / seconds);
    }
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    gpu_destroy(context);

done:
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    for (int i = 0; i < request.define_count; i++)
        free(request.define_copies[i]);
    frame_list_free(&request.frames);
    return exit_code;
}
