/* suite_run.c: running a suite's cases (suite.h, "Running" and "Updating"): each case's
 * render job, its comparison with the golden and its previews, in this process on one
 * GPU context or in worker processes that share the results through an anonymous shared
 * mapping. */
#include "suite.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clock.h"
#include "image_io.h"

const char *suite_verdict_name(suite_verdict verdict)
{
    switch (verdict) {
    case SUITE_PASSED: return "pass";
    case SUITE_FAILED: return "FAIL";
    case SUITE_ERROR: return "ERROR";
    case SUITE_NOT_RUN: break;
    }
    return "not run";
}

/* Makes directory (and its parents) unless it exists. Returns RT_OK or RT_ERROR_INPUT. */
static rt_status make_directories(const char *directory, rt_error *error)
{
    char path[SUITE_PATH_MAX];
    if (snprintf(path, sizeof path, "%s", directory) >= (int)sizeof path)
        return rt_error_set(error, RT_ERROR_INPUT, "SUITE: the path '%s' is too long", directory);
    for (char *slash = path + 1;; slash++) {
        bool end = *slash == '\0';
        if (*slash == '/' || end) {
            char kept = *slash;
            *slash = '\0';
            if (mkdir(path, 0777) != 0 && errno != EEXIST)
                return rt_error_set(error, RT_ERROR_INPUT, "SUITE: cannot make the directory '%s': %s", path,
                                    strerror(errno));
            *slash = kept;
        }
        if (end)
            return RT_OK;
    }
}

/* Writes the R, G, B of image to path (a PNG: 8-bit sRGB, clamped). */
static rt_status write_preview(const char *path, const rt_image *image, rt_error *error)
{
    rt_image colour;
    rt_status status = image_create(&colour, image->width, image->height, 3, error);
    if (status != RT_OK)
        return status;
    size_t pixels = (size_t)image->width * image->height;
    int copied = image->channels < 3 ? image->channels : 3;
    for (size_t p = 0; p < pixels; p++)
        for (int c = 0; c < 3; c++)
            colour.pixels[p * 3 + c] = image->pixels[p * image->channels + (c < copied ? c : 0)];
    status = image_write(path, &colour, NULL, error);
    image_free(&colour);
    return status;
}

/* The previews of one case in folder: new, and what else there is. The first failure is
 * the case's error. */
static rt_status write_previews(const char *folder, const rt_image *fresh, const rt_image *golden,
                                const rt_image *difference, const rt_image *maps, suite_case_result *result,
                                rt_error *error)
{
    char path[SUITE_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/new.png", folder);
    rt_status status = write_preview(path, fresh, error);
    if (status == RT_OK && golden != NULL && golden->pixels != NULL) {
        snprintf(path, sizeof path, "%s/reference.png", folder);
        status = write_preview(path, golden, error);
        result->reference_preview = status == RT_OK;
    }
    if (status == RT_OK && difference->pixels != NULL) {
        snprintf(path, sizeof path, "%s/difference.png", folder);
        status = write_preview(path, difference, error);
        result->difference_preview = status == RT_OK;
    }
    if (status == RT_OK && maps->pixels != NULL) {
        rt_image heat;
        status = image_stat_heat_map(maps, &heat, error);
        snprintf(path, sizeof path, "%s/significance.png", folder);
        if (status == RT_OK)
            status = image_write(path, &heat, NULL, error);
        image_free(&heat);
        result->significance_preview = status == RT_OK;
    }
    result->previews = status == RT_OK;
    return status;
}

/* Sets the result's verdict and message (printf-style); returns nothing. */
__attribute__((format(printf, 3, 4))) static void conclude(suite_case_result *result, suite_verdict verdict,
                                                           const char *format, ...)
{
    result->verdict = verdict;
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(result->message, sizeof result->message, format, arguments);
    va_end(arguments);
}

/* Reads the new image and the golden and compares them; previews when asked. */
static void compare_case(const suite_case *c, const suite_case_plan *plan, const suite_run_options *options,
                         const char *folder, suite_case_result *result)
{
    rt_error error = {{0}};
    rt_image fresh = {0}, golden = {0}, difference = {0}, maps = {0};
    if (image_read(result->new_image, &fresh, &error) != RT_OK) {
        conclude(result, SUITE_ERROR, "cannot read the new image back: %s", error.message);
        return;
    }
    result->rendered = true;
    if (access(c->golden, F_OK) != 0 && errno == ENOENT) {
        result->golden_missing = true;
        conclude(result, SUITE_FAILED, "the golden '%s' is missing (`rtspheres check --update` writes it)",
                 c->golden);
    } else if (image_read(c->golden, &golden, &error) != RT_OK) {
        conclude(result, SUITE_ERROR, "cannot read the golden: %s", error.message);
    } else if (image_compare(&fresh, &golden, &plan->comparison, &result->comparison, &difference,
                             plan->comparison.test == IMAGE_COMPARE_Z ? &maps : NULL, &error)
               != RT_OK) {
        conclude(result, SUITE_ERROR, "cannot compare with the golden '%s': %s", c->golden, error.message);
    } else {
        result->compared = true;
        char reason[SUITE_MESSAGE_MAX];
        image_compare_describe(&result->comparison, &plan->comparison, reason, sizeof reason);
        conclude(result, result->comparison.passed ? SUITE_PASSED : SUITE_FAILED, "%s", reason);
    }
    if (options->previews && write_previews(folder, &fresh, &golden, &difference, &maps, result, &error) != RT_OK)
        conclude(result, SUITE_ERROR, "cannot write the previews: %s", error.message);
    image_free(&fresh);
    image_free(&golden);
    image_free(&difference);
    image_free(&maps);
}

/* Renders case index on context, compares it and fills *result. */
static void run_case(gpu_context *context, const suite *s, int index, const suite_case_plan *plan,
                     const suite_run_options *options, suite_case_result *result)
{
    double start = clock_seconds();
    const suite_case *c = &s->cases[index];
    memset(result, 0, sizeof *result);
    result->options = plan->comparison;
    char folder[SUITE_PATH_MAX];
    rt_error error = {{0}};
    snprintf(folder, sizeof folder, "%s/cases/%s", options->work_directory, c->name);
    if (snprintf(result->new_image, sizeof result->new_image, "%s/new.exr", folder) >= (int)sizeof result->new_image
        || make_directories(folder, &error) != RT_OK) {
        conclude(result, SUITE_ERROR, "%s", error.message[0] ? error.message : "SUITE: the work path is too long");
        result->seconds = clock_seconds() - start;
        return;
    }
    render_job job = plan->job;
    job.scene_path = c->scene;
    job.output = result->new_image;
    job.variance = true;
    job.stop_requested = options->stop_requested;
    render_job_summary summary;
    rt_status status = render_job_run(context, &job, NULL, &summary, &error);
    result->render_seconds = summary.seconds;
    if (status == RT_ERROR_INTERRUPTED)
        conclude(result, SUITE_ERROR, "interrupted: the run was stopped during this render");
    else if (status != RT_OK)
        conclude(result, SUITE_ERROR, "the render failed: %s", error.message);
    else
        compare_case(c, plan, options, folder, result);
    result->seconds = clock_seconds() - start;
}

static bool stop_requested(const suite_run_options *options)
{
    return options->stop_requested != NULL && *options->stop_requested;
}

/* Every case in order on one context in this process. */
static rt_status run_here(const suite *s, const suite_case_plan *plans, const suite_run_options *options,
                          suite_case_result *results, rt_error *error)
{
    gpu_context *context = NULL;
    rt_status status = gpu_create(&options->gpu, &context, error);
    if (status != RT_OK)
        return status;
    for (int i = 0; i < s->case_count && !stop_requested(options); i++) {
        run_case(context, s, i, &plans[i], options, &results[i]);
        if (options->callbacks.case_finished != NULL)
            options->callbacks.case_finished(options->callbacks.user, i, &results[i]);
    }
    gpu_destroy(context);
    return RT_OK;
}

/* What the workers and the parent share: the next case to take, who took each case, and
 * the results. */
typedef struct shared_run {
    int next_case;
    rt_status context_status;    /* a worker that could not make a context says why here */
    char context_message[sizeof ((rt_error *)NULL)->message];
    int claimed_by[];            /* worker number + 1, 0: not taken; then the results */
} shared_run;

/* A worker: takes cases until none is left (or a stop), announcing each finished index on
 * the pipe. Never returns. */
static void work(int worker, const suite *s, const suite_case_plan *plans, const suite_run_options *options,
                 shared_run *shared, suite_case_result *results, int announce)
{
    gpu_context *context = NULL;
    rt_error error = {{0}};
    if (gpu_create(&options->gpu, &context, &error) != RT_OK) {
        if (__atomic_exchange_n(&shared->context_status, RT_ERROR_RUNTIME, __ATOMIC_SEQ_CST) == RT_OK)
            snprintf(shared->context_message, sizeof shared->context_message, "%s", error.message);
        _exit(1);
    }
    while (!stop_requested(options)) {
        int index = __atomic_fetch_add(&shared->next_case, 1, __ATOMIC_SEQ_CST);
        if (index >= s->case_count)
            break;
        shared->claimed_by[index] = worker + 1;
        run_case(context, s, index, &plans[index], options, &results[index]);
        ssize_t written;
        do
            written = write(announce, &index, sizeof index);
        while (written < 0 && errno == EINTR);
    }
    gpu_destroy(context);
    _exit(0);
}

/* The cases in jobs worker processes (see suite.h). */
static rt_status run_workers(const suite *s, const suite_case_plan *plans, const suite_run_options *options,
                             suite_case_result *results, rt_error *error)
{
    int count = s->case_count, jobs = options->jobs < count ? options->jobs : count;
    size_t header = sizeof(shared_run) + (size_t)count * sizeof(int);
    header = (header + 63) / 64 * 64;
    size_t size = header + (size_t)count * sizeof(suite_case_result);
    shared_run *shared = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared == MAP_FAILED)
        return rt_error_set(error, RT_ERROR_RUNTIME, "SUITE: cannot share memory with the workers: %s",
                            strerror(errno));
    suite_case_result *shared_results = (suite_case_result *)((char *)shared + header);
    int announce[2];
    if (pipe2(announce, O_CLOEXEC) != 0) {
        munmap(shared, size);
        return rt_error_set(error, RT_ERROR_RUNTIME, "SUITE: cannot make a pipe: %s", strerror(errno));
    }
    pid_t workers[64];
    int started = 0;
    rt_status status = RT_OK;
    for (int w = 0; w < jobs && w < 64; w++) {
        pid_t pid = fork();
        if (pid == 0) {
            close(announce[0]);
            work(w, s, plans, options, shared, shared_results, announce[1]);
        }
        if (pid < 0) {
            status = rt_error_set(error, RT_ERROR_RUNTIME, "SUITE: cannot start a worker process: %s",
                                  strerror(errno));
            break;
        }
        workers[started++] = pid;
    }
    close(announce[1]);
    int index;
    ssize_t got;
    while ((got = read(announce[0], &index, sizeof index)) != 0) {
        if (got < 0 && errno == EINTR)
            continue;
        if (got != (ssize_t)sizeof index || index < 0 || index >= count)
            break;
        results[index] = shared_results[index];
        if (options->callbacks.case_finished != NULL)
            options->callbacks.case_finished(options->callbacks.user, index, &results[index]);
    }
    close(announce[0]);
    int exit_status[64] = {0};
    for (int w = 0; w < started; w++)
        while (waitpid(workers[w], &exit_status[w], 0) < 0 && errno == EINTR) {
        }
    /* A case a worker took but did not finish: that worker died rendering it. */
    for (int i = 0; i < count; i++) {
        int worker = shared->claimed_by[i] - 1;
        if (worker < 0 || results[i].verdict != SUITE_NOT_RUN)
            continue;
        int how = exit_status[worker];
        conclude(&results[i], SUITE_ERROR, "the worker process rendering it ended (%s %d)",
                 WIFSIGNALED(how) ? "signal" : "exit status", WIFSIGNALED(how) ? WTERMSIG(how) : WEXITSTATUS(how));
    }
    bool any_run = false;
    for (int i = 0; i < count; i++)
        any_run = any_run || shared->claimed_by[i] != 0;
    if (status == RT_OK && !any_run && shared->context_status != RT_OK)
        status = rt_error_set(error, shared->context_status, "%s", shared->context_message);
    munmap(shared, size);
    return status;
}

rt_status suite_run(const suite *s, const suite_case_plan *plans, const suite_run_options *options,
                    suite_case_result *results, rt_error *error)
{
    for (int i = 0; i < s->case_count; i++)
        memset(&results[i], 0, sizeof results[i]);
    if (options->work_directory == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "SUITE: no work directory");
    char cases[SUITE_PATH_MAX];
    snprintf(cases, sizeof cases, "%s/cases", options->work_directory);
    rt_status status = make_directories(cases, error);
    if (status != RT_OK)
        return status;
    if (options->jobs > 1 && s->case_count > 1)
        return run_workers(s, plans, options, results, error);
    return run_here(s, plans, options, results, error);
}

/* Copies the file at from over to, atomically (a temporary file beside to, renamed). */
static rt_status copy_file(const char *from, const char *to, rt_error *error)
{
    char temporary[SUITE_PATH_MAX + 16];
    snprintf(temporary, sizeof temporary, "%s.tmpXXXXXX", to);
    int in = open(from, O_RDONLY | O_CLOEXEC);
    int out = in >= 0 ? mkstemp(temporary) : -1;
    bool ok = in >= 0 && out >= 0;
    char buffer[65536];
    ssize_t got = 0;
    while (ok && (got = read(in, buffer, sizeof buffer)) != 0) {
        if (got < 0 && errno == EINTR)
            continue;
        ok = got > 0 && write(out, buffer, (size_t)got) == got;
    }
    int saved = errno;
    if (out >= 0 && (fchmod(out, 0644) != 0 || close(out) != 0))
        ok = false;
    if (in >= 0)
        close(in);
    if (ok && rename(temporary, to) != 0) {
        saved = errno;
        ok = false;
    }
    if (!ok) {
        if (out >= 0)
            unlink(temporary);
        return rt_error_set(error, RT_ERROR_RUNTIME, "SUITE: cannot copy '%s' to '%s': %s", from, to,
                            strerror(saved ? saved : EIO));
    }
    return RT_OK;
}

rt_status suite_update(const suite *s, suite_case_result *results, suite_update_mode mode, rt_error *error)
{
    for (int i = 0; i < s->case_count; i++) {
        suite_case_result *result = &results[i];
        bool wanted = mode == SUITE_UPDATE_ALL ? result->rendered : result->verdict == SUITE_FAILED;
        if (!wanted)
            continue;
        rt_status status = copy_file(result->new_image, s->cases[i].golden, error);
        if (status != RT_OK)
            return status;
        result->updated = true;
    }
    return RT_OK;
}
