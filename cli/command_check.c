/* command_check.c: `rtspheres check SUITE [options]`: reads a regression suite
 * (core/suite.h), turns each case's words into a render job (render_arguments.h) and
 * comparison options (compare_arguments.h), runs the suite, prints a line per case and a
 * summary, and writes what was asked: JUnit XML, the HTML report, updated goldens.
 * Exit codes: 0 every case passed (or had its golden rewritten by --update), 1 some case
 * failed or had an error (or the run could not start: no GPU), 2 a bad suite or usage. */
#include <errno.h>
#include <ftw.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "clock.h"
#include "commands.h"
#include "compare_arguments.h"
#include "render_arguments.h"
#include "suite.h"

static volatile sig_atomic_t stop_requested = 0;

/* SIGINT/SIGTERM: stop after the render in flight; a second one ends the process. */
static void on_stop_signal(int signal_number)
{
    stop_requested = 1;
    signal(signal_number, SIG_DFL);
}

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres check SUITE [options]\n"
            "\n"
            "Renders every case of the suite file SUITE, compares each with its golden image\n"
            "(by default with the z test of `rtspheres diff --test z`) and prints a line per\n"
            "case and a summary. A suite line: case NAME SCENE GOLDEN [render options]\n"
            "[compare comparison options]; also render, compare, root and include lines and\n"
            "# comments (docs/regression.md).\n"
            "\n"
            "options:\n"
            "  --junit FILE      write the results as JUnit XML (GitLab, Jenkins, GitHub, Azure)\n"
            "  --report DIR      write DIR/index.html: every case's reference, new image,\n"
            "                    difference and z-test heat map, failures first (relative links,\n"
            "                    nothing from the network); the new renders stay in DIR/cases/\n"
            "  --update          rewrite the goldens of the cases that fail (missing ones too)\n"
            "                    with their new renders, and say which\n"
            "  --update-all      rewrite every case's golden (what `make golden` does)\n"
            "  --jobs N          render in N worker processes, each with its own GPU context\n"
            "                    (default 1: every case on one context in this process)\n"
            "  --device N        use EGL device N (see `rtspheres info`)\n"
            "  -q, --quiet       print only the cases that do not pass and the summary\n"
            "  -v, --verbose     print every case's metrics\n"
            "  -h, --help        show this help\n"
            "\n"
            "exit status: 0 all cases pass, 1 some fail, 2 bad suite or usage\n");
}

/* What the command was asked. */
typedef struct check_request {
    const char *suite_path;
    const char *junit, *report;
    bool update, update_all, quiet, verbose;
    int jobs, device;
} check_request;

/* Parses argv. Returns EXIT_OK, -1 after --help, or an exit code after printing why. */
static int parse_request(int argc, char **argv, check_request *request)
{
    enum { OPTION_JUNIT = 256, OPTION_REPORT, OPTION_UPDATE, OPTION_UPDATE_ALL, OPTION_JOBS, OPTION_DEVICE };
    static const struct option long_options[] = {
        {"junit", required_argument, NULL, OPTION_JUNIT},
        {"report", required_argument, NULL, OPTION_REPORT},
        {"update", no_argument, NULL, OPTION_UPDATE},
        {"update-all", no_argument, NULL, OPTION_UPDATE_ALL},
        {"jobs", required_argument, NULL, OPTION_JOBS},
        {"device", required_argument, NULL, OPTION_DEVICE},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    *request = (check_request){.jobs = 1, .device = -1};
    opterr = 0;
    optind = 1;
    int option;
    long long number = 0;
    while ((option = getopt_long(argc, argv, ":qvh", long_options, NULL)) != -1) {
        switch (option) {
        case OPTION_JUNIT: request->junit = optarg; break;
        case OPTION_REPORT: request->report = optarg; break;
        case OPTION_UPDATE: request->update = true; break;
        case OPTION_UPDATE_ALL: request->update_all = true; break;
        case OPTION_JOBS:
            if (command_parse_integer(optarg, 1, 64, &number)) {
                fprintf(stderr, "rtspheres check: --jobs wants a whole number from 1 to 64, not '%s'\n", optarg);
                return EXIT_BAD_INPUT;
            }
            request->jobs = (int)number;
            break;
        case OPTION_DEVICE:
            if (command_parse_integer(optarg, 0, 255, &number)) {
                fprintf(stderr, "rtspheres check: --device wants a device number (0, 1, ...), not '%s'\n", optarg);
                return EXIT_BAD_INPUT;
            }
            request->device = (int)number;
            break;
        case 'q': request->quiet = true; break;
        case 'v': request->verbose = true; break;
        case 'h':
            print_help(stdout);
            return -1;
        case ':':
            fprintf(stderr, "rtspheres check: %s needs a value (see 'rtspheres check --help')\n", argv[optind - 1]);
            return EXIT_BAD_INPUT;
        default:
            fprintf(stderr, "rtspheres check: unknown option '%s' (see 'rtspheres check --help')\n",
                    argv[optind - 1]);
            return EXIT_BAD_INPUT;
        }
    }
    if (argc - optind != 1) {
        fprintf(stderr, "rtspheres check: expected one suite file, got %d; usage: rtspheres check SUITE [options]\n",
                argc - optind);
        return EXIT_BAD_INPUT;
    }
    if (request->update && request->update_all) {
        fprintf(stderr, "rtspheres check: --update and --update-all both choose what to rewrite; give one\n");
        return EXIT_BAD_INPUT;
    }
    request->suite_path = argv[optind];
    return EXIT_OK;
}

/* The word of words[0 .. count-1] a complaint is about: the one it quotes ('WORD'), else
 * the option it starts with, else the first. NULL when there are none. */
static const suite_word *word_of_complaint(const suite_word *words, int count, const char *complaint)
{
    for (int i = 0; i < count; i++) {
        char quoted[SUITE_PATH_MAX + 4];
        snprintf(quoted, sizeof quoted, "'%s'", words[i].text);
        if (strstr(complaint, quoted) != NULL)
            return &words[i];
    }
    for (int i = 0; i < count; i++) {
        size_t length = strcspn(words[i].text, "=");
        if (length > 1 && strncmp(complaint, words[i].text, length) == 0)
            return &words[i];
    }
    return count > 0 ? &words[0] : NULL;
}

/* Prints a complaint about a case's words at the word it is about (or the case's line). */
static void complain(const suite_case *c, const suite_word *words, int count, const char *complaint)
{
    const suite_word *word = word_of_complaint(words, count, complaint);
    if (word != NULL)
        fprintf(stderr, "%s:%d:%d: %s\n", word->file, word->line, word->column, complaint);
    else
        fprintf(stderr, "%s:%d: case '%s': %s\n", c->file, c->line, c->name, complaint);
}

/* Options a case may not give: the runner chooses the output and renders one image. */
static const char *refused_render_option(const render_arguments *arguments, const suite_word *words, int count)
{
    for (int i = 0; i < count; i++) {
        const char *word = words[i].text;
        size_t length = strcspn(word, "=");
        if (strncmp(word, "-o", 2) == 0 || (length >= 3 && strncmp(word, "--output", length) == 0))
            return "-o: a case's output is chosen by check (DIR/cases/NAME/new.exr)";
    }
    const render_job *job = &arguments->job;
    if (job->frame_count > 0)
        return "--frames: a case renders one image (use -D time=... for a frame)";
    if (job->resume_path != NULL || job->checkpoint_seconds > 0)
        return "--resume and --checkpoint are not for suite cases";
    if (job->shard_count > 0 || job->tile_count > 0)
        return "--shard and --tile render part of an image; a case renders all of it (--crop is fine)";
    if (arguments->device >= 0)
        return "--device is check's own option, for every case";
    return NULL;
}

/* Turns case c's render words into arguments (parsed with the case's scene and a stand-in
 * output, which the runner replaces). Returns EXIT_OK or EXIT_BAD_INPUT after printing why. */
static int plan_render(const suite_case *c, render_arguments *arguments)
{
    char **argv = calloc((size_t)c->render_count + 5, sizeof *argv);
    char *messages = NULL;
    size_t messages_size = 0;
    FILE *stream = open_memstream(&messages, &messages_size);
    if (argv == NULL || stream == NULL) {
        free(argv);
        if (stream != NULL)
            fclose(stream);
        free(messages);
        fprintf(stderr, "rtspheres check: out of memory\n");
        return EXIT_RUNTIME;
    }
    /* The case's words between the stand-in output and "--", so that no word of theirs
     * can take the scene as its value. */
    int argc = 0;
    argv[argc++] = "render";
    argv[argc++] = "-o";
    argv[argc++] = "case.exr";
    for (int i = 0; i < c->render_count; i++)
        argv[argc++] = c->render[i].text;
    argv[argc++] = "--";
    argv[argc++] = c->scene;
    bool help_shown = false;
    int code = render_arguments_parse_to(argc, argv, arguments, &help_shown, stream, "");
    fclose(stream);
    const char *refused = code == EXIT_OK && !help_shown ? refused_render_option(arguments, c->render, c->render_count)
                                                         : NULL;
    if (help_shown) {
        complain(c, c->render, c->render_count, "-h/--help is not a render option of a case");
        code = EXIT_BAD_INPUT;
    } else if (code != EXIT_OK) {
        messages[strcspn(messages, "\n")] = '\0';
        static const char took_the_end[] = ", not '--'";
        size_t length = strlen(messages), end_length = sizeof took_the_end - 1;
        char stray[SUITE_PATH_MAX + 64];
        if (length > end_length && strcmp(messages + length - end_length, took_the_end) == 0 && c->render_count > 0) {
            /* The last word wanted a value and took the "--" after it. */
            const suite_word *last = &c->render[c->render_count - 1];
            fprintf(stderr, "%s:%d:%d: %s needs a value\n", last->file, last->line, last->column, last->text);
        } else if (strncmp(messages, "one scene at a time", 19) == 0 && optind < argc) {
            /* getopt moved the words that are no option behind the options: the first is
             * the case's stray word, the scene comes after it. */
            snprintf(stray, sizeof stray, "unexpected '%s' (a render option starts with '-')", argv[optind]);
            complain(c, c->render, c->render_count, stray);
        } else {
            complain(c, c->render, c->render_count, messages);
        }
    } else if (refused != NULL) {
        complain(c, c->render, c->render_count, refused);
        code = EXIT_BAD_INPUT;
    }
    free(messages);
    free(argv);
    return code;
}

/* Turns case c's compare words into *comparison. Returns EXIT_OK or EXIT_BAD_INPUT. */
static int plan_comparison(const suite_case *c, const render_job *job, image_compare_options *comparison)
{
    char **argv = calloc((size_t)c->compare_count + 1, sizeof *argv);
    if (argv == NULL) {
        fprintf(stderr, "rtspheres check: out of memory\n");
        return EXIT_RUNTIME;
    }
    for (int i = 0; i < c->compare_count; i++)
        argv[i] = c->compare[i].text;
    compare_arguments arguments;
    compare_arguments_init(&arguments, IMAGE_COMPARE_Z);
    char text[512];
    int at = -1;
    const char *complaint = compare_arguments_parse(c->compare_count, argv, &arguments, text, sizeof text, &at);
    free(argv);
    if (complaint != NULL) {
        complain(c, at >= 0 ? &c->compare[at] : c->compare, at >= 0 ? 1 : c->compare_count, complaint);
        return EXIT_BAD_INPUT;
    }
    if (arguments.options.test == IMAGE_COMPARE_Z && (job->denoise || job->blur_sigma > 0)) {
        fprintf(stderr, "%s:%d: case '%s': --denoise and --blur change the noise that the z test measures; "
                        "compare it with --test idiff\n", c->file, c->line, c->name);
        return EXIT_BAD_INPUT;
    }
    *comparison = arguments.options;
    return EXIT_OK;
}

/* Checks each plan's job as a render would, with the output it will have. */
static int check_jobs(const suite *s, suite_case_plan *plans, const char *work_directory)
{
    char output[SUITE_PATH_MAX + 32];
    snprintf(output, sizeof output, "%s/check.exr", work_directory);
    for (int i = 0; i < s->case_count; i++) {
        render_job job = plans[i].job;
        job.output = output;
        job.variance = true;
        render_job_plan plan;
        rt_error error = {{0}};
        if (render_job_check(&job, &plan, &error) != RT_OK) {
            fprintf(stderr, "%s:%d: case '%s': %s\n", s->cases[i].file, s->cases[i].line, s->cases[i].name,
                    error.message);
            return EXIT_BAD_INPUT;
        }
    }
    return EXIT_OK;
}

/* What the case lines need. */
typedef struct check_run {
    const check_request *request;
    const suite *suite;
    int finished;
} check_run;

/* suite_run_callbacks.case_finished: the case's line (and metrics with --verbose). */
static void show_case(void *user, int index, const suite_case_result *result)
{
    check_run *run = user;
    run->finished++;
    if (run->request->quiet && result->verdict == SUITE_PASSED)
        return;
    printf("%-5s %s (%.2f s): %s\n", suite_verdict_name(result->verdict), run->suite->cases[index].name,
           result->seconds, result->message);
    if (run->request->verbose && result->compared) {
        char metrics[4096];
        image_compare_metrics(&result->comparison, &result->options, metrics, sizeof metrics);
        for (char *line = strtok(metrics, "\n"); line != NULL; line = strtok(NULL, "\n"))
            printf("      %s\n", line);
    }
    fflush(stdout);
}

/* nftw callback: removes one entry of the temporary work directory. */
static int remove_entry(const char *path, const struct stat *info, int type, struct FTW *walk)
{
    (void)info;
    (void)type;
    (void)walk;
    return remove(path);
}

/* Rewrites goldens as asked and says which. Returns false when a copy failed. */
static bool update_goldens(const check_request *request, const suite *s, suite_case_result *results)
{
    if (!request->update && !request->update_all)
        return true;
    rt_error error = {{0}};
    rt_status status = suite_update(s, results, request->update_all ? SUITE_UPDATE_ALL : SUITE_UPDATE_FAILED, &error);
    int updated = 0;
    for (int i = 0; i < s->case_count; i++)
        if (results[i].updated) {
            printf("updated %s: %s\n", s->cases[i].name, s->cases[i].golden);
            updated++;
        }
    printf("check: rewrote %d golden%s\n", updated, updated == 1 ? "" : "s");
    if (status != RT_OK)
        fprintf(stderr, "rtspheres check: %s\n", error.message);
    return status == RT_OK;
}

/* Writes the JUnit file and the report asked for. Returns false when one failed. */
static bool write_reports(const check_request *request, const suite *s, const suite_case_result *results,
                          double seconds)
{
    rt_error error = {{0}};
    bool ok = true;
    if (request->junit != NULL && suite_write_junit(request->junit, s, results, seconds, &error) != RT_OK) {
        fprintf(stderr, "rtspheres check: %s\n", error.message);
        ok = false;
    }
    if (request->report != NULL && suite_write_report(request->report, s, results, seconds, &error) != RT_OK) {
        fprintf(stderr, "rtspheres check: %s\n", error.message);
        ok = false;
    }
    return ok;
}

/* Runs the planned suite in work_directory and reports. Returns the exit code. */
static int run_suite(const check_request *request, const suite *s, const suite_case_plan *plans,
                     const char *work_directory)
{
    double start = clock_seconds();
    suite_case_result *results = calloc((size_t)s->case_count, sizeof *results);
    if (results == NULL) {
        fprintf(stderr, "rtspheres check: out of memory\n");
        return EXIT_RUNTIME;
    }
    check_run run = {.request = request, .suite = s};
    suite_run_options options = {
        .work_directory = work_directory,
        .previews = request->report != NULL,
        .jobs = request->jobs,
        .gpu = {.device = request->device >= 0 ? request->device + 1 : 0},
        .stop_requested = &stop_requested,
        .callbacks = {.user = &run, .case_finished = show_case},
    };
    if (!request->quiet)
        printf("check: %s: %d case%s, %d job%s\n", s->path, s->case_count, s->case_count == 1 ? "" : "s",
               request->jobs, request->jobs == 1 ? "" : "s");
    fflush(stdout);
    rt_error error = {{0}};
    rt_status status = suite_run(s, plans, &options, results, &error);
    int exit_code = EXIT_OK;
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres check: %s\n", error.message);
        exit_code = exit_code_for_status(status);
    } else {
        double seconds = clock_seconds() - start;
        bool updated = update_goldens(request, s, results);
        bool written = write_reports(request, s, results, seconds);
        int counts[4] = {0};
        bool all_good = true;
        for (int i = 0; i < s->case_count; i++) {
            counts[results[i].verdict]++;
            all_good = all_good && (results[i].verdict == SUITE_PASSED || results[i].updated);
        }
        printf("check: %d passed, %d failed, %d errors, %d not run of %d cases in %.2f s\n", counts[SUITE_PASSED],
               counts[SUITE_FAILED], counts[SUITE_ERROR], counts[SUITE_NOT_RUN], s->case_count, seconds);
        if (request->report != NULL)
            printf("check: report: %s/index.html\n", request->report);
        exit_code = all_good && updated && written ? EXIT_OK : EXIT_RUNTIME;
    }
    free(results);
    return exit_code;
}

/* Plans every case of s into plans (arguments keeps what their jobs point into). */
static int plan_cases(const suite *s, render_arguments *arguments, suite_case_plan *plans)
{
    for (int i = 0; i < s->case_count; i++) {
        int code = plan_render(&s->cases[i], &arguments[i]);
        if (code == EXIT_OK) {
            plans[i].job = arguments[i].job;
            code = plan_comparison(&s->cases[i], &plans[i].job, &plans[i].comparison);
        }
        if (code != EXIT_OK)
            return code;
    }
    return EXIT_OK;
}

int command_check(int argc, char **argv)
{
    check_request request;
    int code = parse_request(argc, argv, &request);
    if (code != EXIT_OK)
        return code < 0 ? EXIT_OK : code;
    suite s;
    rt_error error = {{0}};
    rt_status status = suite_load(request.suite_path, &s, &error);
    if (status != RT_OK) {
        fprintf(stderr, "%s%s\n", strncmp(error.message, "SUITE: ", 7) == 0 ? "rtspheres check: " : "",
                error.message);
        suite_free(&s);
        return exit_code_for_status(status);
    }
    render_arguments *arguments = calloc((size_t)s.case_count, sizeof *arguments);
    suite_case_plan *plans = calloc((size_t)s.case_count, sizeof *plans);
    code = arguments && plans ? plan_cases(&s, arguments, plans) : EXIT_RUNTIME;

    /* The new renders go to the report's folder, else to a temporary one removed at the end. */
    char temporary[SUITE_PATH_MAX] = "";
    const char *work_directory = request.report;
    if (code == EXIT_OK && work_directory == NULL) {
        const char *base = getenv("TMPDIR");
        snprintf(temporary, sizeof temporary, "%s/rtspheres-check.XXXXXX", base && *base ? base : "/tmp");
        work_directory = mkdtemp(temporary);
        if (work_directory == NULL) {
            fprintf(stderr, "rtspheres check: cannot make a temporary directory in %s\n", base ? base : "/tmp");
            code = EXIT_RUNTIME;
            temporary[0] = '\0';
        }
    } else if (code == EXIT_OK) {
        if (mkdir(work_directory, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "rtspheres check: cannot make the report directory '%s': %s\n", work_directory,
                    strerror(errno));
            code = EXIT_BAD_INPUT;
        }
    }
    if (code == EXIT_OK)
        code = check_jobs(&s, plans, work_directory);
    if (code == EXIT_OK) {
        stop_requested = 0;
        signal(SIGINT, on_stop_signal);
        signal(SIGTERM, on_stop_signal);
        code = run_suite(&request, &s, plans, work_directory);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
    }
    if (temporary[0] != '\0')
        nftw(temporary, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    for (int i = 0; arguments != NULL && i < s.case_count; i++)
        render_arguments_free(&arguments[i]);
    free(arguments);
    free(plans);
    suite_free(&s);
    return code;
}
