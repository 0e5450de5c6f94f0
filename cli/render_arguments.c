/* render_arguments.c: see render_arguments.h. Every complaint is one line on stderr,
 * "rtspheres render: ..." (exit 2), and names the option and the value it refused. */
#include "render_arguments.h"

#include <ctype.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres render SCENE -o OUTPUT [options]\n"
            "\n"
            "Renders the scene file SCENE (or a glTF file, .gltf or .glb, as a scene by itself)\n"
            "and writes OUTPUT; the format follows the extension:\n"
            ".exr (linear float, with metadata and a per-pixel 'samples' channel), .hdr,\n"
            ".png/.jpg/.tif (8-bit sRGB).\n"
            "\n"
            "options (--spp, --size, --max-depth, --seed override the scene's `render` line):\n"
            "  -o, --output FILE      the image to write (required); a name pattern such as\n"
            "                         frame-%%04d.png gets each frame's number with --frames,\n"
            "                         else the value of -D frame=N, else 0 (%%%% for a '%%')\n"
            "  -s, --spp N            samples per pixel\n"
            "      --size WxH         image size in pixels, e.g. 640x360 (each 1 to 65536)\n"
            "      --memory-budget SIZE  memory an image's render may take, e.g. 512M, 2G (default:\n"
            "                         a quarter of the machine's memory, at most 512M); larger\n"
            "                         images, and any wider than the device, render in tiles\n"
            "      --max-depth N      path segments per sample at most\n"
            "      --seed N           random seed (same seed, same image)\n"
            "      --camera NAME      a glTF scene: render its camera (or camera node) NAME\n"
            "                         (default: the first camera its scene places)\n"
            "  -D NAME=VALUE          set scene variable $NAME (wins over the file's `set`)\n"
            "      --frames LIST      render frames, e.g. 1-60 or 1-10,15,20-30:2; each frame\n"
            "                         sets $frame and $time (= frame / --fps)\n"
            "      --fps F            frames per second for $time (default 24)\n"
            "      --display HOST:PORT  stream the image to the tev viewer as it converges (every\n"
            "                         second, and when done); no viewer there is a warning\n"
            "      --sweep TABLE      one image per row of TABLE (.tsv or .csv: a header of\n"
            "                         variable names, then a row of values each), set as -D;\n"
            "                         the output may use {NAME} and %%d (the row number)\n"
            "      --samples S:C      render only sample indices S .. S+C-1 of each pixel\n"
            "                         (parts merge exactly with `rtspheres merge`)\n"
            "      --crop x0,y0,x1,y1 render only that region (row 0 at the top, x1/y1 exclusive)\n"
            "      --tile I/N         render horizontal band I of N (0-based)\n"
            "      --shard I/N        part I of N of the work (see --shard-by); for job arrays\n"
            "      --shard-by KIND    frames, samples or tiles (default: frames when --frames\n"
            "                         lists several, otherwise samples)\n"
            "      --noise-threshold T  adaptive sampling: a pixel stops once the relative standard\n"
            "                         error of its mean luminance is under T (e.g. 0.05) and its\n"
            "                         3x3 neighbours' is too; --spp is the most it takes\n"
            "      --min-spp N        samples every pixel takes before that check (default 16)\n"
            "      --time-limit SECS  end within about one pass of SECS seconds after the process\n"
            "                         started (per image with --frames), writing what it has\n"
            "                         (continue it with --resume OUTPUT.exr)\n"
            "      --samples-map FILE also write each pixel's sample count as a heat map\n"
            "                         (log scale, black: none, yellow: --spp): where the time went\n"
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
            "      --light-groups     add a layer per light group to the EXR (NAME.R/G/B; `group`\n"
            "                         clauses of the scene, the rest in 'default'): the layers\n"
            "                         sum to the image; rtspheres relight reweighs them\n"
            "      --variance         add layers to the EXR: variance.R/G/B, each pixel's sample\n"
            "                         variance of each colour channel (for `rtspheres diff --test z`\n"
            "                         and `rtspheres check`)\n"
            "      --denoise          edge-aware a-trous denoiser guided by albedo, normal and depth\n"
            "                         (an EXR keeps the noisy image as noisy.R/G/B)\n"
            "      --blur SIGMA[:N]   Gaussian blur of SIGMA pixels, N times (the seed's blurNum);\n"
            "                         off by default\n"
            "      --tonemap OP       for 8-bit outputs: clamp (default), reinhard or aces\n"
            "      --light-sampling on|off  sample lights at diffuse hits (next-event\n"
            "                         estimation with MIS; default on): less noise, same image\n"
            "      --light-tree on|off  with more than 8 lights, choose one per point by the\n"
            "                         light tree (default on) or by power: the same image\n"
            "      --sampler KIND     sobol (default: stratified, Owen-scrambled Sobol points) or\n"
            "                         independent (hashed random numbers): the same image,\n"
            "                         more noise; for comparisons\n"
            "      --roulette-depth N paths may end at random (Russian roulette, unbiased)\n"
            "                         after N segments (default 4)\n"
            "      --full-tracer      compile the whole tracer, also the code this scene cannot\n"
            "                         reach (lights, volumes, textures); the image is the same,\n"
            "                         only slower: for checking exactly that\n"
            "      --pass-budget N    fixed work units per pixel per GPU pass (default: adapted\n"
            "                         so a pass takes about 0.25 s, 2 s on llvmpipe; the image is the same)\n"
            "      --device N         use EGL device N (see `rtspheres info`)\n"
            "      --threads N        CPU threads of the software device (llvmpipe's LP_NUM_THREADS);\n"
            "                         on a GPU a warning that it does nothing\n"
            "      --skip-existing    leave an output that is complete and was rendered from the same\n"
            "                         scene and options alone; resume its partial file; say why\n"
            "      --progress MODE    auto (default: the bar on a terminal, else lines), bar, lines\n"
            "                         (one line every --progress-interval seconds) or none\n"
            "      --progress-interval SECS  seconds between progress lines (default 5; 0: every pass)\n"
            "      --stats-json FILE  write the render's figures as JSON (docs/stats-json.md)\n"
            "  -q, --quiet            no progress and no summary line\n"
            "  -v, --verbose          OpenGL debug messages and set-up details on stderr\n"
            "  -h, --help             this text\n");
}

enum {
    OPTION_SIZE = 256, OPTION_MAX_DEPTH, OPTION_SEED, OPTION_EXPOSURE, OPTION_PASS_BUDGET, OPTION_DEVICE,
    OPTION_ROULETTE_DEPTH, OPTION_FRAMES, OPTION_SWEEP, OPTION_DISPLAY, OPTION_FPS, OPTION_SAMPLES, OPTION_CROP, OPTION_TILE, OPTION_SHARD,
    OPTION_SHARD_BY, OPTION_CHECKPOINT, OPTION_RESUME, OPTION_LIGHT_SAMPLING, OPTION_LIGHT_TREE, OPTION_INTEGRATOR, OPTION_AOVS,
    OPTION_LIGHT_GROUPS, OPTION_VARIANCE, OPTION_DENOISE, OPTION_BLUR, OPTION_TONEMAP, OPTION_FULL_TRACER, OPTION_SAMPLER,
    OPTION_CAMERA, OPTION_NOISE_THRESHOLD, OPTION_MIN_SPP, OPTION_TIME_LIMIT, OPTION_SAMPLES_MAP,
    OPTION_PROGRESS, OPTION_PROGRESS_INTERVAL, OPTION_STATS_JSON, OPTION_THREADS, OPTION_SKIP_EXISTING,
    OPTION_MEMORY_BUDGET,
};

/* One word an option takes and the value it stands for. */
typedef struct choice {
    const char *word;
    int value;
} choice;

/* Finds text among choices[0 .. count-1] into *value. Returns false when it is none of them. */
static bool parse_choice(const char *text, const choice *choices, int count, int *value)
{
    for (int i = 0; i < count; i++)
        if (strcmp(text, choices[i].word) == 0) {
            *value = choices[i].value;
            return true;
        }
    return false;
}

/* Parses all of text as a finite number into *value. Returns false when it is not. */
static bool parse_real(const char *text, double *value)
{
    char *end = NULL;
    *value = strtod(text, &end);
    return end != text && *end == '\0' && isfinite(*value);
}

/* Parses "A<separator>B" (each a whole number in its range) into *a and *b. Returns false
 * when it is not that. */
static bool parse_pair(const char *text, char separator, long long minimum_a, long long maximum_a,
                       long long minimum_b, long long maximum_b, long long *a, long long *b)
{
    char copy[64];
    snprintf(copy, sizeof copy, "%s", text);
    char *middle = strchr(copy, separator);
    if (middle)
        *middle = '\0';
    return middle && !command_parse_integer(copy, minimum_a, maximum_a, a)
           && !command_parse_integer(middle + 1, minimum_b, maximum_b, b);
}

/* The options that take a whole number, with their ranges, and the command's own
 * options (threads, progress). Returns the complaint, or NULL when value is good. */
static const char *take_whole_number(int option, const char *value, render_arguments *arguments)
{
    render_job *job = &arguments->job;
    long long number = 0;
    switch (option) {
    case 's':
        if (command_parse_integer(value, 1, 1 << 30, &number))
            return "--spp wants a whole number from 1 to 1073741824";
        job->samples_per_pixel = (int)number;
        return NULL;
    case OPTION_MAX_DEPTH:
        if (command_parse_integer(value, 1, 100000, &number))
            return "--max-depth wants a whole number from 1 to 100000";
        job->max_depth = (int)number;
        return NULL;
    case OPTION_SEED:
        if (command_parse_integer(value, 0, UINT32_MAX, &number))
            return "--seed wants a whole number from 0 to 4294967295";
        job->seed_set = true;
        job->seed = (uint32_t)number;
        return NULL;
    case OPTION_PASS_BUDGET:
        if (command_parse_integer(value, 1, 50000, &number))
            return "--pass-budget wants a whole number from 1 to 50000";
        job->tracer.pass_work_budget = (uint32_t)number;
        return NULL;
    case OPTION_ROULETTE_DEPTH:
        if (command_parse_integer(value, 1, 100000, &number))
            return "--roulette-depth wants a whole number from 1 to 100000";
        job->tracer.russian_roulette_depth = (uint32_t)number;
        return NULL;
    case OPTION_MIN_SPP:
        if (command_parse_integer(value, 2, 1 << 30, &number))
            return "--min-spp wants a whole number from 2 to 1073741824";
        job->tracer.min_spp = (uint32_t)number;
        return NULL;
    case OPTION_DEVICE:
        if (command_parse_integer(value, 0, 255, &number))
            return "--device wants a device number (0, 1, ...)";
        arguments->device = (int)number;
        return NULL;
    case OPTION_THREADS:
        if (command_parse_integer(value, 1, GPU_MAX_THREADS, &number))
            return "--threads wants a whole number from 1 to 1024";
        arguments->threads = (int)number;
        return NULL;
    case OPTION_PROGRESS: {
        static const choice modes[] = {
            {"auto", PROGRESS_AUTO}, {"bar", PROGRESS_BAR}, {"lines", PROGRESS_LINES}, {"none", PROGRESS_NONE}};
        int word = 0;
        if (!parse_choice(value, modes, 4, &word))
            return "--progress wants auto, bar, lines or none";
        arguments->progress = (render_progress_mode)word;
        return NULL;
    }
    case OPTION_PROGRESS_INTERVAL:
        if (!parse_real(value, &arguments->progress_interval) || !(arguments->progress_interval >= 0)
            || arguments->progress_interval > 1e7)
            return "--progress-interval wants a number of seconds (0: a line after every pass)";
        return NULL;
    }
    return NULL;
}

/* The options that take a real number, a pair or a word. Returns the complaint, or NULL
 * when value is good. */
static const char *take_value(int option, const char *value, render_job *job)
{
    static const choice tonemaps[] = {{"clamp", TONEMAP_CLAMP}, {"reinhard", TONEMAP_REINHARD}, {"aces", TONEMAP_ACES}};
    static const choice integrators[] = {{"path", INTEGRATOR_PATH}, {"whitted", INTEGRATOR_WHITTED}};
    static const choice switches[] = {{"on", 0}, {"off", 1}};
    static const choice samplers[] = {{"sobol", SAMPLER_SOBOL}, {"independent", SAMPLER_INDEPENDENT}};
    static const choice shard_kinds[] = {
        {"frames", RENDER_SHARD_FRAMES}, {"samples", RENDER_SHARD_SAMPLES}, {"tiles", RENDER_SHARD_TILES}};
    long long a = 0, b = 0;
    int word = 0;
    switch (option) {
    case OPTION_SIZE:
        if (!parse_pair(value, 'x', 1, SCENE_MAX_IMAGE_SIDE, 1, SCENE_MAX_IMAGE_SIDE, &a, &b))
            return "--size wants WIDTHxHEIGHT, each 1 to 65536, e.g. 640x360";
        job->width = (int)a;
        job->height = (int)b;
        return NULL;
    case OPTION_SAMPLES:
        if (!parse_pair(value, ':', 0, UINT32_MAX - 1, 1, 1 << 30, &a, &b) || a + b > UINT32_MAX)
            return "--samples wants START:COUNT, e.g. 512:512 (COUNT at least 1)";
        job->sample_start = (uint32_t)a;
        job->sample_count = (uint32_t)b;
        return NULL;
    case OPTION_EXPOSURE:
        if (!parse_real(value, &job->exposure) || fabs(job->exposure) > 64)
            return "--exposure wants a number of stops (-64 to 64)";
        return NULL;
    case OPTION_FPS:
        if (!parse_real(value, &job->frames_per_second) || !(job->frames_per_second > 0)
            || job->frames_per_second > 1e6)
            return "--fps wants a positive number of frames per second";
        return NULL;
    case OPTION_CHECKPOINT:
        if (!parse_real(value, &job->checkpoint_seconds) || !(job->checkpoint_seconds > 0)
            || job->checkpoint_seconds > 1e7)
            return "--checkpoint wants a positive number of seconds";
        return NULL;
    case OPTION_NOISE_THRESHOLD: {
        double threshold = 0;
        if (!parse_real(value, &threshold) || !(threshold > 0) || threshold > 1e6)
            return "--noise-threshold wants a positive number, e.g. 0.05 (a relative standard error)";
        job->tracer.noise_threshold = (float)threshold;
        return NULL;
    }
    case OPTION_MEMORY_BUDGET: {
        /* A size as Slurm's --mem spells one: K, M, G or T (powers of 1024), else bytes. */
        char *end = NULL;
        double amount = strtod(value, &end);
        const char *units = "KMGT";
        const char *unit = end != NULL && *end != '\0' ? strchr(units, toupper((unsigned char)*end)) : NULL;
        if (unit != NULL && end[1] == 'i' && end[2] == 'B' && end[3] == '\0')
            end += 2;
        else if (unit != NULL && (end[1] == 'B' || end[1] == 'b') && end[2] == '\0')
            end += 1;
        double scale = unit != NULL ? pow(1024.0, (double)(unit - units + 1)) : 1.0;
        if (end == value || !(amount > 0) || (unit == NULL && *end != '\0') || (unit != NULL && end[1] != '\0')
            || amount * scale < 65536.0 || amount * scale > 1e18)
            return "--memory-budget wants a size of at least 64K, e.g. 512M or 2G (K, M, G, T: powers of 1024)";
        job->memory_budget = (uint64_t)(amount * scale);
        return NULL;
    }
    case OPTION_TIME_LIMIT:
        if (!parse_real(value, &job->time_limit_seconds) || !(job->time_limit_seconds > 0)
            || job->time_limit_seconds > 1e7)
            return "--time-limit wants a positive number of seconds";
        return NULL;
    case OPTION_BLUR: {
        char extra;
        float sigma = 0;
        int passes = 1;
        int read = sscanf(value, "%f:%d%c", &sigma, &passes, &extra);
        if ((read != 1 && read != 2) || !(sigma > 0) || sigma > POSTPROCESS_MAX_BLUR_SIGMA || passes < 1
            || passes > 100)
            return "--blur wants SIGMA or SIGMA:PASSES, e.g. 1.5 or 1:3 (sigma in pixels, > 0)";
        job->blur_sigma = sigma;
        job->blur_passes = passes;
        return NULL;
    }
    case OPTION_CROP: {
        char extra;
        int *c = job->crop;
        if (sscanf(value, "%d,%d,%d,%d%c", &c[0], &c[1], &c[2], &c[3], &extra) != 4 || c[0] < 0 || c[1] < 0
            || c[2] <= c[0] || c[3] <= c[1])
            return "--crop wants x0,y0,x1,y1 with x0 < x1 and y0 < y1 (row 0 at the top)";
        return NULL;
    }
    case OPTION_TONEMAP:
        if (!parse_choice(value, tonemaps, 3, &word))
            return "--tonemap wants clamp, reinhard or aces";
        job->tonemap = (postprocess_tonemap_operator)word;
        return NULL;
    case OPTION_INTEGRATOR:
        if (!parse_choice(value, integrators, 2, &word))
            return "--integrator wants path or whitted";
        job->tracer.integrator = (render_integrator)word;
        return NULL;
    case OPTION_LIGHT_SAMPLING:
        if (!parse_choice(value, switches, 2, &word))
            return "--light-sampling wants on or off";
        job->tracer.no_light_sampling = word == 1;
        return NULL;
    case OPTION_LIGHT_TREE:
        if (!parse_choice(value, switches, 2, &word))
            return "--light-tree wants on or off";
        job->tracer.no_light_tree = word == 1;
        return NULL;
    case OPTION_SAMPLER:
        if (!parse_choice(value, samplers, 2, &word))
            return "--sampler wants sobol or independent";
        job->tracer.sampler = word;
        return NULL;
    case OPTION_SHARD_BY:
        if (!parse_choice(value, shard_kinds, 3, &word))
            return "--shard-by wants frames, samples or tiles";
        job->shard_by = (render_job_shard_kind)word;
        return NULL;
    }
    return NULL;
}

/* --tile and --shard: I/N (batch.h shard_parse(), whose message says what is wrong)
 * into *index and *count. Returns EXIT_OK, or EXIT_BAD_INPUT after printing why. */
static int take_split(const render_arguments *arguments, const char *option_name, const char *value, int *index,
                      int *count)
{
    rt_error error = {{0}};
    if (shard_parse(value, index, count, &error) == RT_OK)
        return EXIT_OK;
    fprintf(arguments->messages, "%s%s %s\n", arguments->message_prefix, option_name, error.message);
    return EXIT_BAD_INPUT;
}

/* The options that choose a part of the work and have their own parsers (batch.h), whose
 * messages say what is wrong. Returns EXIT_OK, or EXIT_BAD_INPUT after printing why. */
static int take_part(int option, const char *value, render_arguments *arguments)
{
    render_job *job = &arguments->job;
    rt_error error = {{0}};
    switch (option) {
    case OPTION_FRAMES:
        frame_list_free(&arguments->frames);
        job->frames = NULL;
        job->frame_count = 0;
        if (frame_list_parse(value, &arguments->frames, &error) != RT_OK) {
            fprintf(arguments->messages, "%s--%s\n", arguments->message_prefix, error.message);
            return EXIT_BAD_INPUT;
        }
        job->frames = arguments->frames.frames;
        job->frame_count = arguments->frames.count;
        return EXIT_OK;
    case OPTION_SWEEP:
        sweep_table_free(&arguments->sweep);
        job->sweep = NULL;
        if (sweep_table_load(value, &arguments->sweep, &error) != RT_OK) {
            fprintf(arguments->messages, "%s--sweep: %s\n", arguments->message_prefix, error.message);
            return EXIT_BAD_INPUT;
        }
        job->sweep = &arguments->sweep;
        return EXIT_OK;
    case OPTION_TILE: return take_split(arguments, "--tile", value, &job->tile_index, &job->tile_count);
    case OPTION_SHARD: return take_split(arguments, "--shard", value, &job->shard_index, &job->shard_count);
    }
    return EXIT_OK;
}

/* -D NAME=VALUE: keeps a copy of the text and adds the define to the job. Returns the
 * complaint, or NULL; *out_of_memory is set when the copy failed. */
static const char *take_define(const char *value, render_arguments *arguments, bool *out_of_memory)
{
    render_job *job = &arguments->job;
    const char *equals = strchr(value, '=');
    if (equals == NULL || equals == value || equals[1] == '\0')
        return "-D wants NAME=VALUE, e.g. -D aperture=0.1";
    if (job->define_count == RENDER_ARGUMENTS_MAX_DEFINES)
        return "too many -D options";
    char *copy = strdup(value);
    if (copy == NULL) {
        *out_of_memory = true;
        return NULL;
    }
    copy[equals - value] = '\0';
    arguments->define_copies[job->define_count] = copy;
    arguments->defines[job->define_count] = (scene_define){.name = copy, .value = copy + (equals - value) + 1};
    job->defines = arguments->defines;
    job->define_count++;
    return NULL;
}

/* Takes one option with its value (NULL for a flag) into arguments. Returns EXIT_OK, or
 * an exit code after printing why. */
static int take_option(int option, const char *value, render_arguments *arguments)
{
    render_job *job = &arguments->job;
    const char *complaint = NULL;
    bool out_of_memory = false;
    switch (option) {
    case 'o': job->output = value; break;
    case OPTION_RESUME: job->resume_path = value; break;
    case OPTION_SAMPLES_MAP: job->samples_map = value; break;
    case OPTION_DISPLAY: arguments->display = value; break;
    case OPTION_CAMERA: job->camera = value; break;
    case OPTION_AOVS: job->aovs = true; break;
    case OPTION_LIGHT_GROUPS: job->light_groups = true; break;
    case OPTION_VARIANCE: job->variance = true; break;
    case OPTION_DENOISE: job->denoise = true; break;
    case OPTION_FULL_TRACER: job->tracer.full_tracer = true; break;
    case OPTION_STATS_JSON: arguments->stats_json = value; break;
    case OPTION_SKIP_EXISTING: job->skip_existing = true; break;
    case 'q': arguments->quiet = true; break;
    case 'v': arguments->verbose = true; break;
    case 's':
    case OPTION_MAX_DEPTH:
    case OPTION_SEED:
    case OPTION_PASS_BUDGET:
    case OPTION_ROULETTE_DEPTH:
    case OPTION_MIN_SPP:
    case OPTION_DEVICE:
    case OPTION_THREADS:
    case OPTION_PROGRESS:
    case OPTION_PROGRESS_INTERVAL:
        complaint = take_whole_number(option, value, arguments);
        break;
    case OPTION_FRAMES:
    case OPTION_SWEEP:
    case OPTION_TILE:
    case OPTION_SHARD:
        return take_part(option, value, arguments);
    case 'D':
        complaint = take_define(value, arguments, &out_of_memory);
        break;
    default:
        complaint = take_value(option, value, job);
        break;
    }
    if (out_of_memory) {
        fprintf(arguments->messages, "%sout of memory\n", arguments->message_prefix);
        return EXIT_RUNTIME;
    }
    if (complaint != NULL) {
        fprintf(arguments->messages, "%s%s, not '%s'\n", arguments->message_prefix, complaint, value);
        return EXIT_BAD_INPUT;
    }
    return EXIT_OK;
}

int render_arguments_parse(int argc, char **argv, render_arguments *arguments, bool *help_shown)
{
    return render_arguments_parse_to(argc, argv, arguments, help_shown, stderr, "rtspheres render: ");
}

int render_arguments_parse_to(int argc, char **argv, render_arguments *arguments, bool *help_shown, FILE *messages,
                              const char *prefix)
{
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
        {"sweep", required_argument, NULL, OPTION_SWEEP},
        {"display", required_argument, NULL, OPTION_DISPLAY},
        {"fps", required_argument, NULL, OPTION_FPS},
        {"samples", required_argument, NULL, OPTION_SAMPLES},
        {"crop", required_argument, NULL, OPTION_CROP},
        {"tile", required_argument, NULL, OPTION_TILE},
        {"shard", required_argument, NULL, OPTION_SHARD},
        {"shard-by", required_argument, NULL, OPTION_SHARD_BY},
        {"checkpoint", required_argument, NULL, OPTION_CHECKPOINT},
        {"noise-threshold", required_argument, NULL, OPTION_NOISE_THRESHOLD},
        {"min-spp", required_argument, NULL, OPTION_MIN_SPP},
        {"time-limit", required_argument, NULL, OPTION_TIME_LIMIT},
        {"memory-budget", required_argument, NULL, OPTION_MEMORY_BUDGET},
        {"samples-map", required_argument, NULL, OPTION_SAMPLES_MAP},
        {"resume", required_argument, NULL, OPTION_RESUME},
        {"camera", required_argument, NULL, OPTION_CAMERA},
        {"light-sampling", required_argument, NULL, OPTION_LIGHT_SAMPLING},
        {"light-tree", required_argument, NULL, OPTION_LIGHT_TREE},
        {"sampler", required_argument, NULL, OPTION_SAMPLER},
        {"full-tracer", no_argument, NULL, OPTION_FULL_TRACER},
        {"integrator", required_argument, NULL, OPTION_INTEGRATOR},
        {"aovs", no_argument, NULL, OPTION_AOVS},
        {"light-groups", no_argument, NULL, OPTION_LIGHT_GROUPS},
        {"variance", no_argument, NULL, OPTION_VARIANCE},
        {"denoise", no_argument, NULL, OPTION_DENOISE},
        {"blur", required_argument, NULL, OPTION_BLUR},
        {"tonemap", required_argument, NULL, OPTION_TONEMAP},
        {"threads", required_argument, NULL, OPTION_THREADS},
        {"skip-existing", no_argument, NULL, OPTION_SKIP_EXISTING},
        {"progress", required_argument, NULL, OPTION_PROGRESS},
        {"progress-interval", required_argument, NULL, OPTION_PROGRESS_INTERVAL},
        {"stats-json", required_argument, NULL, OPTION_STATS_JSON},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    memset(arguments, 0, sizeof *arguments);
    arguments->job = render_job_defaults();
    arguments->device = -1;
    arguments->progress_interval = RENDER_ARGUMENTS_DEFAULT_PROGRESS_INTERVAL;
    arguments->messages = messages;
    arguments->message_prefix = prefix;
    *help_shown = false;
    /* getopt's own messages go to stderr: elsewhere ours say the same. */
    bool own_messages = messages != stderr;
    opterr = !own_messages;
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, own_messages ? ":o:s:D:qvh" : "o:s:D:qvh", long_options, NULL)) != -1) {
        if (option == 'h') {
            print_help(stdout);
            *help_shown = true;
            return EXIT_OK;
        }
        if (own_messages && (option == '?' || option == ':')) {
            fprintf(messages, option == '?' ? "%sunknown render option '%s'\n" : "%s%s needs a value\n", prefix,
                    argv[optind - 1]);
            return EXIT_BAD_INPUT;
        }
        if (option == '?' || option == ':')
            return EXIT_BAD_INPUT;  /* getopt has said what is wrong */
        int code = take_option(option, optarg, arguments);
        if (code != EXIT_OK)
            return code;
    }
    if (optind >= argc) {
        fprintf(arguments->messages, "%swhich scene? usage: rtspheres render SCENE -o OUTPUT\n", arguments->message_prefix);
        return EXIT_BAD_INPUT;
    }
    if (optind + 1 < argc) {
        fprintf(arguments->messages, "%sone scene at a time; unexpected '%s'\n", arguments->message_prefix, argv[optind + 1]);
        return EXIT_BAD_INPUT;
    }
    arguments->job.scene_path = argv[optind];
    if (arguments->job.output == NULL) {
        fprintf(arguments->messages, "%sno output file; add -o OUTPUT (.exr, .png, .jpg, .hdr, .tif)\n",
                arguments->message_prefix);
        return EXIT_BAD_INPUT;
    }
    return EXIT_OK;
}

void render_arguments_free(render_arguments *arguments)
{
    for (int i = 0; i < arguments->job.define_count; i++)
        free(arguments->define_copies[i]);
    frame_list_free(&arguments->frames);
    sweep_table_free(&arguments->sweep);
    memset(arguments, 0, sizeof *arguments);
}
