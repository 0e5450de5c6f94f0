/* command_render.c: `rtspheres render SCENE -o OUTPUT [options]`: turns the options into a
 * render job (render_arguments.c), runs it on one GPU context (core/render_job.h) and maps
 * its status to an exit code (0 ok, 1 runtime or interrupted, 2 bad input). What the user
 * sees while it runs is drawn here: the progress bar on a terminal, the summary lines,
 * warnings and checkpoint notes on stderr. */
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include "clock.h"
#include "commands.h"
#include "gpu.h"
#include "large_pages.h"
#include "display_tev.h"
#include "paths.h"
#include "render_arguments.h"
#include "render_job.h"
#include "render_stats.h"

static volatile sig_atomic_t stop_requested = 0;

/* First SIGINT/SIGTERM: finish the pass in flight and write what is done. Second: the
 * default action (the handler resets itself), so the user can always get out. */
static void on_stop_signal(int signal_number)
{
    stop_requested = 1;
    signal(signal_number, SIG_DFL);
}

/* What the command shows of a running job. */
/* How often --display sends the image so far (and once more when it is done). */
#define DISPLAY_PREVIEW_SECONDS 1.0

typedef struct presentation {
    const render_arguments *arguments;
    bool tty;                    /* draw the bar (--progress bar, or auto on a terminal) */
    bool lines;                  /* write progress lines (--progress lines, or auto elsewhere) */
    double command_start;        /* monotonic seconds when the command started */
    double process_start;        /* ... and when the process did (core/clock.h): the libraries' loading before main */
    render_stats *stats;         /* --stats-json's figures, or NULL */
    /* Of the image being rendered: */
    char label[64];              /* "frame N " with frames, "row N " with a sweep, else "" */
    bool resumed;                /* --skip-existing resumes it */
    double last_line;            /* elapsed seconds of the last progress line */
    double last_draw;
    double first_pass;           /* seconds from the command's start to its first pass's end */
    int compiles;                /* images whose tracer program was compiled (not cached) */
    display_tev *display;        /* --display's viewer, or NULL */
    const char *output;          /* the image being rendered: its name in the viewer */
} presentation;

/* Sends image to the --display viewer as the image being rendered, and says once, as a
 * warning, when the viewer is not there or went away (the render goes on). */
static void show_on_display(presentation *shown, const rt_image *image)
{
    if (shown->display == NULL || shown->output == NULL)
        return;
    display_tev_send(shown->display, shown->output, image);
    char warning[600];
    if (display_tev_take_warning(shown->display, warning, sizeof warning))
        fprintf(stderr, "rtspheres render: warning: %s\n", warning);
}

/* render_options.preview: the image so far, to the viewer. */
static void send_preview(void *user, const rt_image *partial)
{
    show_on_display(user, partial);
}

/* render_job_callbacks.render_started: a new bar for the image. */
static void start_bar(void *user, const render_job_image *image)
{
    presentation *shown = user;
    shown->output = image->output;
    shown->label[0] = '\0';
    if (image->frame >= 0)
        snprintf(shown->label, sizeof shown->label, "frame %d ", image->frame);
    else if (image->sweep_row >= 0)
        snprintf(shown->label, sizeof shown->label, "row %d ", image->sweep_row);
    shown->last_draw = -1;
    shown->last_line = 0;
    shown->first_pass = 0;
}

/* A progress line for logs (--progress lines): how far, how long, how long still, and how
 * noisy the image still is with adaptive sampling. Never a carriage return. */
static void write_progress_line(const presentation *shown, const render_progress *progress)
{
    double fraction = (double)progress->samples_done / (double)progress->samples_total;
    double eta = fraction > 0 ? progress->elapsed_seconds * (1.0 - fraction) / fraction : 0;
    char noise[200] = "";
    if (progress->noise_checks > 0 && progress->pixel_count > 0)
        snprintf(noise, sizeof noise, "; noise: %.1f%% of pixels at or above %g (mean error %.3g), %d still sampling",
                 100.0 * progress->noisy_pixels / progress->pixel_count, progress->noise_threshold,
                 progress->noise_error, progress->going_pixels);
    fprintf(stderr, "rtspheres: %sprogress %.1f%%, %llu of %llu samples, %.1f s elapsed, ETA %.1f s, pass %d%s\n",
            shown->label, 100.0 * fraction, (unsigned long long)progress->samples_done,
            (unsigned long long)progress->samples_total, progress->elapsed_seconds, eta, progress->passes, noise);
    fflush(stderr);
}

/* render_job_callbacks.progress: redraws the bar at most every 0.1 s (and at the end). */
static void draw_progress(void *user, const render_progress *progress)
{
    presentation *shown = user;
    if (progress->passes == 1)
        shown->first_pass = clock_seconds() - shown->command_start;
    if (shown->lines && progress->samples_total > 0
        && progress->elapsed_seconds - shown->last_line >= shown->arguments->progress_interval) {
        shown->last_line = progress->elapsed_seconds;
        write_progress_line(shown, progress);
    }
    if (!shown->tty || progress->samples_total == 0)
        return;
    double fraction = (double)progress->samples_done / (double)progress->samples_total;
    if (progress->elapsed_seconds - shown->last_draw < 0.1 && fraction < 1.0)
        return;
    shown->last_draw = progress->elapsed_seconds;
    int width = 30, filled = (int)(fraction * width);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    double eta = fraction > 0 ? progress->elapsed_seconds * (1.0 - fraction) / fraction : 0;
    fprintf(stderr, "\r%s[%s] %5.1f%%  %llu/%llu samples  %.1f s elapsed, ETA %.1f s ", shown->label, bar,
            100.0 * fraction, (unsigned long long)progress->samples_done, (unsigned long long)progress->samples_total,
            progress->elapsed_seconds, eta);
    fflush(stderr);
}

/* render_job_callbacks.tiles_planned: says that (and why) the image is rendered in tiles. */
static void show_tiles(void *user, const render_job_image *image, int columns, int rows, int tile_width,
                       int tile_height, const char *reason)
{
    const presentation *shown = user;
    if (!shown->arguments->quiet)
        fprintf(stderr, "rtspheres: %s: rendering in %d x %d tiles of up to %dx%d pixels (%s)\n", image->output,
                columns, rows, tile_width, tile_height, reason);
}

/* Writes --stats-json as it stands; a failure is a warning (the render goes on). */
static void write_stats(const presentation *shown)
{
    if (shown->stats == NULL)
        return;
    rt_error error = {{0}};
    if (render_stats_write(shown->stats, shown->arguments->stats_json, &error) != RT_OK)
        fprintf(stderr, "rtspheres render: warning: --stats-json: %s\n", error.message);
}

/* render_job_callbacks.render_finished: ends the bar's line; a failed or interrupted
 * image goes into the statistics. */
static void end_bar(void *user, const render_job_image *image, rt_status status)
{
    presentation *shown = user;
    if (shown->tty)
        fprintf(stderr, "\n");
    if (shown->stats != NULL && status != RT_OK) {
        rt_error ignored = {{0}};
        render_stats_add_other(shown->stats, image,
                               status == RT_ERROR_INTERRUPTED ? RENDER_STATS_INTERRUPTED : RENDER_STATS_FAILED, NULL,
                               &ignored);
        write_stats(shown);
    }
}

/* render_job_callbacks.existing_output: what --skip-existing found, one line per image. */
static void show_existing(void *user, const render_job_image *image, const render_job_existing *decision)
{
    presentation *shown = user;
    shown->resumed = decision->kind == RENDER_JOB_EXISTING_RESUME;
    char label[64] = "";
    if (image->frame >= 0)
        snprintf(label, sizeof label, "frame %d: ", image->frame);
    else if (image->sweep_row >= 0)
        snprintf(label, sizeof label, "row %d: ", image->sweep_row);
    const char *verb = decision->kind == RENDER_JOB_EXISTING_SKIP     ? "skipped"
                       : decision->kind == RENDER_JOB_EXISTING_RESUME ? "resuming"
                                                                      : "rendering afresh";
    if (!shown->arguments->quiet)
        fprintf(stderr, "rtspheres: %s%s: %s\n", label, verb, decision->reason);
    if (shown->stats != NULL && decision->kind == RENDER_JOB_EXISTING_SKIP) {
        rt_error ignored = {{0}};
        render_stats_add_other(shown->stats, image, RENDER_STATS_SKIPPED, decision->reason, &ignored);
        write_stats(shown);
    }
}

/* render_job_callbacks.warning. */
static void show_warning(void *user, const char *message)
{
    presentation *shown = user;
    if (!shown->arguments->quiet)
        fprintf(stderr, "rtspheres render: warning: %s\n", message);
}

/* render_job_callbacks.checkpoint_written: a note where no bar shows the progress. */
static void show_checkpoint(void *user, const render_job_image *image, uint64_t samples)
{
    presentation *shown = user;
    if (!shown->arguments->quiet && !isatty(STDERR_FILENO))
        fprintf(stderr, "rtspheres: checkpoint: %llu samples in %s\n", (unsigned long long)samples, image->partial);
}

/* With --verbose, per image: which set-up steps it redid and which it took from the image
 * before (frames, sweep rows): the BVHs (pack.h's cache), the packed scene on the device
 * (all, none or the changed blocks uploaded), the tracer program. The records are packed
 * again for every image: that is what tells which of them changed. */
static void show_reuse(const render_job_image *image, const render_result *result)
{
    uint32_t trees = result->bvh_built + result->bvh_reused;
    uint64_t packed = result->packed_bytes;
    char upload[160];
    if (result->reused_scene)
        snprintf(upload, sizeof upload, "upload reused (the device held the packed scene)");
    else if (result->uploaded_bytes < packed)
        snprintf(upload, sizeof upload, "upload partial (%llu of %llu bytes: the blocks that changed)",
                 (unsigned long long)result->uploaded_bytes, (unsigned long long)packed);
    else
        snprintf(upload, sizeof upload, "upload whole (%llu bytes)", (unsigned long long)packed);
    fprintf(stderr, "rtspheres: set-up of %s: records packed; BVH %s (%u of %u trees reused); %s; shader %s\n",
            image->output, result->bvh_reused == trees ? "reused" : result->bvh_reused > 0 ? "partly reused" : "built",
            result->bvh_reused, trees, upload, result->compiled_program ? "compiled" : "reused");
}

/* render_job_callbacks.image_written: the set-up details with --verbose, then the
 * summary line unless --quiet. */
static void show_summary(void *user, const render_job_image *image, const render_result *result)
{
    presentation *shown = user;
    shown->compiles += result->compiled_program;
    show_on_display(shown, &result->image);
    if (shown->stats != NULL) {
        rt_error error = {{0}};
        if (render_stats_add_rendered(shown->stats, image, result, shown->resumed, shown->first_pass, &error) != RT_OK)
            fprintf(stderr, "rtspheres render: warning: --stats-json: %s\n", error.message);
        write_stats(shown);
    }
    shown->resumed = false;
    if (shown->arguments->verbose) {
        uint64_t geometry_bytes = result->packed_bytes - result->image_bytes;
        /* How a point's light is picked (docs/sampling.md), where there is a choice. */
        char choice[80] = "";
        if (result->light_choice == RENDER_LIGHTS_NONE && result->light_count > 0)
            snprintf(choice, sizeof choice, " (not sampled)");
        else if (result->light_choice == RENDER_LIGHTS_ALL)
            snprintf(choice, sizeof choice, " (each sampled at every point)");
        else if (result->light_choice == RENDER_LIGHTS_BY_POINT)
            snprintf(choice, sizeof choice, " (chosen by the point)");
        else if (result->light_choice == RENDER_LIGHTS_BY_TREE)
            snprintf(choice, sizeof choice, " (chosen by a light tree %u levels deep)", result->light_tree_depth);
        else if (result->light_choice == RENDER_LIGHTS_BY_POWER)
            snprintf(choice, sizeof choice, " (chosen by power)");
        fprintf(stderr,
                "rtspheres: scene: %u primitives (%u triangles), %u instances, %u lights%s; BVH depth %d%s, "
                "built in %.3f s; packed %llu bytes (%.1f per triangle without images)%s; first pass "
                "done %.3f s after the command's start (context, parse, BVH, upload, compile) and %.3f s after the "
                "process's (with the libraries' loading before main); after it %.3f s for "
                "%llu samples (%.3g us/sample); tracer program %s; %d of its passes skipped finished pixels\n",
                result->primitive_count, result->triangle_count, result->instance_count, result->light_count,
                choice, result->bvh_depth, result->threaded_walk ? " (walked as threaded lists)" : "",
                result->bvh_build_seconds, (unsigned long long)result->packed_bytes,
                result->triangle_count ? (double)geometry_bytes / result->triangle_count : 0.0,
                result->reused_scene ? ", already on the device" : "", shown->first_pass,
                shown->first_pass + (shown->command_start - shown->process_start), result->steady_seconds,
                (unsigned long long)result->steady_samples,
                result->steady_samples ? result->steady_seconds / (double)result->steady_samples * 1e6 : 0.0,
                result->compiled_program ? "compiled" : "from the context's cache", result->culled_passes);
        show_reuse(image, result);
    }
    if (!shown->arguments->quiet)
        fprintf(stderr,
                "rtspheres: %s -> %s: %dx%d, %d spp in %.2f s (%.3g samples/s, %.3g path segments/s, %d pass%s)\n",
                shown->arguments->job.scene_path, image->output, result->image.width, result->image.height,
                image->samples_per_pixel, result->seconds, result->samples / result->seconds,
                result->path_segments / result->seconds, result->passes, result->passes == 1 ? "" : "es");
    if (!shown->arguments->quiet && result->stop_reason != RENDER_STOP_SAMPLES) {
        double pixels = (double)result->image.width * result->image.height;
        fprintf(stderr, "rtspheres: stopped by %s with %.1f samples per pixel on average\n",
                result->stop_reason == RENDER_STOP_NOISE ? "the noise threshold" : "the time limit",
                pixels > 0 ? (double)result->samples / pixels : 0.0);
    }
}

/* gpu_options.log: the GPU's set-up details and debug messages (--verbose). */
static void log_to_stderr(void *context, const char *message)
{
    (void)context;
    fprintf(stderr, "rtspheres: %s\n", message);
}

/* Creates the GPU context the options ask for. Returns EXIT_OK with *context set, or an
 * exit code after printing why (also when a stop was requested during the set-up). */
static int open_gpu(const render_arguments *arguments, gpu_context **context)
{
    gpu_options gpu = gpu_options_defaults();
    gpu.device = arguments->device >= 0 ? arguments->device + 1 : 0;
    gpu.debug_output = arguments->verbose;
    gpu.log = log_to_stderr;
    gpu.threads = arguments->threads;
    rt_error error = {{0}};
    rt_status status = gpu_create(&gpu, context, &error);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres render: %s\n", error.message);
        return exit_code_for_status(status);
    }
    if (stop_requested) {
        fprintf(stderr, "rtspheres render: interrupted before the render started; nothing written\n");
        gpu_destroy(*context);
        *context = NULL;
        return EXIT_RUNTIME;
    }
    gpu_info info;
    gpu_get_info(*context, &info);
    if (info.threads_ignored)
        fprintf(stderr, "rtspheres render: warning: --threads %d does nothing on %s, a hardware device\n",
                arguments->threads, info.gl_renderer);
    if (arguments->verbose)
        fprintf(stderr, "rtspheres: rendering on %s (%s, %s)\n", info.gl_renderer, info.platform, info.gl_version);
    if (arguments->verbose && info.software)
        fprintf(stderr, "rtspheres: %d llvmpipe rasteriser thread%s\n", info.software_threads,
                info.software_threads == 1 ? "" : "s");
    if (arguments->verbose)
        fprintf(stderr, "rtspheres: large blocks on huge pages: %s (a 4 KiB page's first touch %.1f us; core/large_pages.h)\n",
                large_pages_advising() ? "yes" : "no", large_pages_fault_microseconds());
    return EXIT_OK;
}

/* Runs the job on context and says how it ended. Returns the exit code. */
static int run_job(gpu_context *context, const render_arguments *arguments, display_tev *display,
                   double process_start, double command_start, double context_seconds)
{
    bool terminal = isatty(STDERR_FILENO);
    render_progress_mode mode = arguments->progress;
    if (mode == PROGRESS_AUTO)
        mode = terminal ? PROGRESS_BAR : PROGRESS_LINES;
    presentation shown = {.arguments = arguments, .tty = !arguments->quiet && mode == PROGRESS_BAR,
                          .lines = !arguments->quiet && mode == PROGRESS_LINES,
                          .command_start = command_start, .process_start = process_start, .last_draw = -1,
                          .display = display};
    render_stats stats;
    if (arguments->stats_json != NULL) {
        gpu_info info;
        gpu_get_info(context, &info);
        render_stats_init(&stats, &info, arguments->threads, context_seconds, command_start - process_start,
                          arguments->job.scene_path, arguments->job.output);
        shown.stats = &stats;
    }
    render_job job = arguments->job;
    if (display != NULL) {
        job.tracer.preview = send_preview;
        job.tracer.preview_context = &shown;
        job.tracer.preview_seconds = DISPLAY_PREVIEW_SECONDS;
    }
    render_job_callbacks callbacks = {
        .user = &shown,
        .warning = show_warning,
        .tiles_planned = show_tiles,
        .render_started = start_bar,
        .progress = draw_progress,
        .render_finished = end_bar,
        .checkpoint_written = show_checkpoint,
        .existing_output = show_existing,
        .image_written = show_summary,
    };
    render_job_summary summary;
    rt_error error = {{0}};
    rt_status status = render_job_run(context, &job, &callbacks, &summary, &error);
    if (shown.stats != NULL) {
        stats.job_finished = true;
        stats.job_seconds = summary.seconds;
        stats.job_error = status != RT_OK ? error.message : NULL;
        write_stats(&shown);
        render_stats_free(&stats);
    }
    if (status != RT_OK && summary.failure == RENDER_JOB_FAILURE_SCENE)
        fprintf(stderr, "%s\n", error.message);  /* the parser's message names the file already */
    else if (status != RT_OK && summary.failure != RENDER_JOB_FAILURE_STOPPED)
        fprintf(stderr, "rtspheres render: %s\n", error.message);
    int rendered = summary.images_started;
    bool list = arguments->job.frame_count > 0 || arguments->job.sweep != NULL;
    const char *unit = arguments->job.sweep != NULL ? "sweep row" : "frame";
    if (list && !arguments->quiet && rendered > 0 && summary.images_skipped > 0)
        fprintf(stderr, "rtspheres: %d %s%s in %.2f s, %d of them skipped as complete\n", rendered, unit,
                rendered == 1 ? "" : "s", summary.seconds, summary.images_skipped);
    else if (list && !arguments->quiet && rendered > 0)
        fprintf(stderr, "rtspheres: %d %s%s in %.2f s (%.3g %ss/s)\n", rendered, unit, rendered == 1 ? "" : "s",
                summary.seconds, rendered / summary.seconds, unit);
    if (list && arguments->verbose)
        fprintf(stderr, "rtspheres: the tracer program was compiled %d time%s for %d image%s\n", shown.compiles,
                shown.compiles == 1 ? "" : "s", rendered, rendered == 1 ? "" : "s");
    return exit_code_for_status(status);
}

int command_render(int argc, char **argv)
{
    double process_start = clock_process_start();
    double command_start = clock_seconds();
    render_arguments arguments;
    bool help_shown = false;
    int exit_code = render_arguments_parse(argc, argv, &arguments, &help_shown);
    if (exit_code == EXIT_OK && !help_shown) {
        /* The job's own rules, before the (possibly slow, cold) GPU set-up. */
        render_job_plan plan;
        rt_error error = {{0}};
        if (render_job_check(&arguments.job, &plan, &error) != RT_OK) {
            fprintf(stderr, "rtspheres render: %s\n", error.message);
            exit_code = EXIT_BAD_INPUT;
        }
    }
    if (exit_code == EXIT_OK && !help_shown && arguments.stats_json != NULL
        && !path_directory_writable(arguments.stats_json)) {
        fprintf(stderr, "rtspheres render: --stats-json: cannot create a file in the directory of '%s'\n",
                arguments.stats_json);
        exit_code = EXIT_BAD_INPUT;
    }
    display_tev *display = NULL;
    if (exit_code == EXIT_OK && !help_shown && arguments.display != NULL) {
        rt_error error = {{0}};
        if (display_tev_create(arguments.display, &display, &error) != RT_OK) {
            fprintf(stderr, "rtspheres render: --display: %s\n", error.message);
            exit_code = exit_code_for_status(RT_ERROR_INPUT);
        }
    }
    if (exit_code != EXIT_OK || help_shown) {
        render_arguments_free(&arguments);
        return exit_code;
    }

    /* Handlers go in before the GPU set-up: a signal then must not kill the process
     * without a word, and one that arrives before the first pass simply ends the render
     * early (nothing is written when no sample finished). */
    stop_requested = 0;
    signal(SIGINT, on_stop_signal);
    signal(SIGTERM, on_stop_signal);
    arguments.job.stop_requested = &stop_requested;
    /* --time-limit counts from the process's start: a scheduler's wall time sees the
     * libraries' loading before main too (about 0.2 s, docs/performance.md "Ideas"). */
    arguments.job.time_limit_start = process_start;
    gpu_context *context = NULL;
    double context_start = clock_seconds();
    exit_code = open_gpu(&arguments, &context);
    if (exit_code == EXIT_OK) {
        exit_code = run_job(context, &arguments, display, process_start, command_start,
                            clock_seconds() - context_start);
        gpu_destroy(context);
    }
    display_tev_destroy(display);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    render_arguments_free(&arguments);
    return exit_code;
}
