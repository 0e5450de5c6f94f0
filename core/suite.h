/* suite.h: image regression suites, what `rtspheres check SUITE` runs: a text file of cases
 * (a name, a scene, a golden image, render options, comparison options), each rendered,
 * compared with its golden (image_compare.h), and reported as JUnit XML and as an HTML
 * page. docs/regression.md is the user's guide; this header is the manual.
 *
 * ## The suite file (suite_load)
 * One statement a line; `#` starts a comment (at the start of a word); words are separated
 * by blanks, and "double quotes" make one word of text with blanks. Statements:
 *   case NAME SCENE GOLDEN [RENDER-OPTIONS...] [compare COMPARE-OPTIONS...]
 *       a case. NAME: letters, digits, '.', '_', '-' (it names files), unique in the
 *       suite. SCENE and GOLDEN are paths, relative ones taken from the root. The render
 *       options are `rtspheres render`'s (the suite's runner sets the output), the
 *       comparison options `rtspheres diff`'s (compare_arguments.h in cli/).
 *   render OPTIONS...     the render options every later case starts with (this file and
 *                         the files it includes later), before its own; replaces the
 *                         previous render line's
 *   compare OPTIONS...    the same for the comparison options
 *   root DIR              relative SCENE and GOLDEN paths of later cases in this file are
 *                         taken from DIR (itself relative to this file's directory); the
 *                         default root is this file's directory
 *   include FILE          the cases of FILE (relative to this file's directory), which
 *                         starts with the render and compare lines in force here and its
 *                         own directory as root; what it sets stays in it. At most
 *                         SUITE_MAX_INCLUDE_DEPTH deep; a file including itself is an error
 * Errors are RT_ERROR_INPUT "FILE:LINE:COLUMN: what is wrong": an unknown statement, a
 * missing or bad name, a duplicate name (naming the first), a missing word, an
 * unterminated quote, an include that cannot be read or that cycles. A suite with no case
 * is an error. Whether the options are right is the caller's to check (their words keep
 * their positions for its messages).
 *
 * ## Running (suite_run)
 * Each case is rendered as a render job (render_job.h) with the caller's job (made from
 * the case's render options), its scene, the output work_directory/cases/NAME/new.exr and
 * variance layers (render --variance, so that an update writes goldens the z test can
 * use), then read back and compared with its golden. The verdicts:
 *   SUITE_PASSED   the comparison passed
 *   SUITE_FAILED   it failed, or the golden is missing (a failure of that case, not of the
 *                  run: --update writes it)
 *   SUITE_ERROR    the render failed (a scene error, a GPU failure), or the golden cannot
 *                  be read or compared (not an image, no samples channel for the z test)
 *   SUITE_NOT_RUN  a stop was requested before the case began
 * With jobs <= 1 every case is rendered in this process on one GPU context, in order (the
 * context keeps the compiled tracer variants and the last scene between cases). With jobs
 * N > 1, N worker processes are forked, each with a context of its own, taking the next
 * case as they finish one (the caller must not have created a GPU context or read images
 * before: a fork keeps neither Mesa's nor OpenImageIO's threads); a worker that dies
 * leaves its case SUITE_ERROR. On a CPU rasteriser each render already uses every core,
 * so there more jobs only overlap the CPU work between renders (docs/regression.md has the
 * measurements).
 * With previews, each case's folder also gets new.png, reference.png (when the golden
 * could be read), difference.png (|new - golden| * the comparison's scale) and, for the z
 * test, significance.png (image_stat_heat_map), 8-bit sRGB, for the HTML report.
 *
 * ## Updating (suite_update)
 * Copies the new image over the golden of each case that failed (mode SUITE_UPDATE_FAILED;
 * missing goldens included) or of every case that was rendered (SUITE_UPDATE_ALL: `make
 * golden`, which also replaces goldens that could not be read or compared, e.g. ones
 * without the variance layers the z test needs), atomically (a temporary file beside the
 * golden, then a rename), and marks them updated. SUITE_UPDATE_FAILED never touches a case
 * with an error, and no mode touches a case whose render failed.
 *
 * ## Reports
 * suite_write_junit() writes JUnit XML, the format GitLab, Jenkins, GitHub and Azure test
 * reports read: <testsuites name tests failures errors skipped time> holding one
 * <testsuite> (the same counts, the suite's name, a timestamp) with one <testcase name
 * classname file line time> per case; a failed case has <failure message type> (the
 * one-line reason; its text the comparison's metrics), an error <error message type>, a
 * case not run <skipped/>. suite_write_report() writes DIR/index.html: a self-contained
 * page (inline style and script, relative links to the previews, nothing from the
 * network) with the failures and errors first, then the passes; for every case its
 * reason, metrics and the four previews side by side. Its script writes the count of
 * images that loaded into the element #image-check and to the console, for a browser
 * test.
 */
#ifndef RT_SUITE_H
#define RT_SUITE_H

#include <signal.h>
#include <stdbool.h>

#include "gpu.h"
#include "image_compare.h"
#include "render_job.h"
#include "status.h"

#define SUITE_MAX_INCLUDE_DEPTH 16
#define SUITE_NAME_MAX 128
#define SUITE_PATH_MAX 4096
#define SUITE_MESSAGE_MAX 1024

/* A word of an option list, with where it was written. */
typedef struct suite_word {
    char *text;
    const char *file;            /* one of suite.files */
    int line, column;
} suite_word;

typedef struct suite_case {
    char *name;
    char *scene;                 /* resolved against the root (absolute paths as written) */
    char *golden;
    const char *file;            /* where the case is (one of suite.files) */
    int line;
    suite_word *render;          /* the render line's words in force, then the case's own */
    int render_count;
    suite_word *compare;         /* the compare line's words in force, then the case's own */
    int compare_count;
} suite_case;

typedef struct suite {
    char *name;                  /* the file's name without directory and extension */
    char *path;                  /* as given */
    suite_case *cases;
    int case_count;
    char **files;                /* the files read, the suite first */
    int file_count;
} suite;

/* Reads the suite at path (see "The suite file") into *out (free with suite_free()
 * whatever the result). */
rt_status suite_load(const char *path, suite *out, rt_error *error);

/* Frees what suite_load() allocated and zeroes *s. */
void suite_free(suite *s);

/* What the caller made of a case's words. */
typedef struct suite_case_plan {
    render_job job;              /* from the render options; the runner sets scene_path,
                                  * output, variance and stop_requested */
    image_compare_options comparison;
} suite_case_plan;

typedef enum suite_verdict {
    SUITE_NOT_RUN = 0,
    SUITE_PASSED,
    SUITE_FAILED,
    SUITE_ERROR,
} suite_verdict;

/* Returns "not run", "pass", "FAIL" or "ERROR". */
const char *suite_verdict_name(suite_verdict verdict);

/* One case's outcome; plain data (it crosses from a worker process). */
typedef struct suite_case_result {
    suite_verdict verdict;
    char message[SUITE_MESSAGE_MAX];   /* one line: the comparison's reason, or what failed */
    image_compare_options options;   /* the case's comparison options */
    bool compared;               /* comparison holds a result */
    image_compare_result comparison;
    bool golden_missing;
    bool rendered;               /* the new image was rendered and read back */
    bool previews;               /* the previews were written (reference only with a golden) */
    bool reference_preview, difference_preview, significance_preview;
    bool updated;                /* suite_update() rewrote its golden */
    double render_seconds;       /* the render job, scene loading to writing */
    double seconds;              /* the whole case: render, reading, comparing, previews */
    char new_image[SUITE_PATH_MAX];   /* the rendered EXR */
} suite_case_result;

typedef struct suite_run_callbacks {
    void *user;
    /* A case is done (in the order cases finish; with jobs > 1 not the suite's order). */
    void (*case_finished)(void *user, int index, const suite_case_result *result);
} suite_run_callbacks;

/* How suite_run works. Zero means default: */
typedef struct suite_run_options {
    const char *work_directory;  /* required: the cases' folders go in DIR/cases/ */
    bool previews;               /* also write the PNG previews of the report */
    int jobs;                    /* 0 or 1: in this process; N: N worker processes */
    gpu_options gpu;             /* for every context */
    const volatile sig_atomic_t *stop_requested;   /* NULL: never; else non-zero stops the
                                  * render in flight (its case is an error) and leaves the
                                  * cases not begun SUITE_NOT_RUN */
    suite_run_callbacks callbacks;
} suite_run_options;

/* Runs every case of s with plans[i] for case i into results[i] (see "Running"). Returns
 * RT_OK when every case has a verdict (whatever it is), or an error that stopped the whole
 * run: the work directory cannot be made, no GPU context, fork failed. */
rt_status suite_run(const suite *s, const suite_case_plan *plans, const suite_run_options *options,
                    suite_case_result *results, rt_error *error);

typedef enum suite_update_mode {
    SUITE_UPDATE_FAILED = 0,
    SUITE_UPDATE_ALL,
} suite_update_mode;

/* Rewrites goldens (see "Updating"). Returns RT_OK, or the first copy that failed
 * (RT_ERROR_RUNTIME naming it; the cases before it are updated). */
rt_status suite_update(const suite *s, suite_case_result *results, suite_update_mode mode, rt_error *error);

/* Writes the JUnit XML of the results to path, atomically; seconds is the run's wall
 * time. */
rt_status suite_write_junit(const char *path, const suite *s, const suite_case_result *results, double seconds,
                            rt_error *error);

/* Writes directory/index.html for the results of a run whose work_directory was
 * directory (with previews); seconds as suite_write_junit(). */
rt_status suite_write_report(const char *directory, const suite *s, const suite_case_result *results,
                             double seconds, rt_error *error);

#endif
