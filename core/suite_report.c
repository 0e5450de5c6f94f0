/* suite_report.c: a suite run's reports (suite.h, "Reports"): JUnit XML and the HTML page.
 * Both are written to a temporary file beside the destination and renamed over it. */
#include "suite.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* A report being written: the stream of a temporary file beside its destination. */
typedef struct report_file {
    FILE *stream;
    char temporary[SUITE_PATH_MAX + 16];
    const char *path;
} report_file;

static rt_status report_open(report_file *file, const char *path, rt_error *error)
{
    file->path = path;
    file->stream = NULL;
    snprintf(file->temporary, sizeof file->temporary, "%s.tmpXXXXXX", path);
    int descriptor = mkstemp(file->temporary);
    if (descriptor >= 0 && fchmod(descriptor, 0644) == 0)
        file->stream = fdopen(descriptor, "w");
    if (file->stream == NULL) {
        int saved = errno;
        if (descriptor >= 0) {
            close(descriptor);
            unlink(file->temporary);
        }
        return rt_error_set(error, RT_ERROR_INPUT, "SUITE: cannot write '%s': %s", path, strerror(saved));
    }
    return RT_OK;
}

/* Closes the file and renames it into place, or removes it when writing failed. */
static rt_status report_close(report_file *file, rt_error *error)
{
    bool ok = !ferror(file->stream);
    ok = fclose(file->stream) == 0 && ok;
    if (ok && rename(file->temporary, file->path) == 0)
        return RT_OK;
    int saved = errno;
    unlink(file->temporary);
    return rt_error_set(error, RT_ERROR_RUNTIME, "SUITE: cannot write '%s': %s", file->path,
                        strerror(saved ? saved : EIO));
}

/* Writes text with the five characters XML and HTML reserve escaped (and control bytes,
 * which XML 1.0 forbids, as spaces). */
static void write_escaped(FILE *stream, const char *text)
{
    for (const unsigned char *c = (const unsigned char *)text; *c != '\0'; c++) {
        switch (*c) {
        case '&': fputs("&amp;", stream); break;
        case '<': fputs("&lt;", stream); break;
        case '>': fputs("&gt;", stream); break;
        case '"': fputs("&quot;", stream); break;
        case '\'': fputs("&#39;", stream); break;
        default: fputc(*c < 0x20 && *c != '\n' && *c != '\t' ? ' ' : *c, stream); break;
        }
    }
}

/* The counts of a run. */
typedef struct suite_counts {
    int passed, failed, errors, not_run;
} suite_counts;

static suite_counts count_results(const suite *s, const suite_case_result *results)
{
    suite_counts counts = {0};
    for (int i = 0; i < s->case_count; i++) {
        suite_verdict verdict = results[i].verdict;
        counts.passed += verdict == SUITE_PASSED;
        counts.failed += verdict == SUITE_FAILED;
        counts.errors += verdict == SUITE_ERROR;
        counts.not_run += verdict == SUITE_NOT_RUN;
    }
    return counts;
}

/* The counts as JUnit attributes. */
static void write_count_attributes(FILE *stream, const suite *s, suite_counts counts, double seconds)
{
    fprintf(stream, " tests=\"%d\" failures=\"%d\" errors=\"%d\" skipped=\"%d\" time=\"%.3f\"", s->case_count,
            counts.failed, counts.errors, counts.not_run, seconds);
}

/* A case's metrics as text (the comparison's lines, or nothing). */
static void case_metrics(const suite_case *c, const suite_case_result *result, char *text, size_t size)
{
    text[0] = '\0';
    if (result->compared)
        image_compare_metrics(&result->comparison, &result->options, text, size);
    size_t used = strlen(text);
    snprintf(text + used, size - used, "scene: %s\ngolden: %s\nnew image: %s\nrender: %.3f s\n", c->scene, c->golden,
             result->new_image, result->render_seconds);
}

rt_status suite_write_junit(const char *path, const suite *s, const suite_case_result *results, double seconds,
                            rt_error *error)
{
    report_file file;
    rt_status status = report_open(&file, path, error);
    if (status != RT_OK)
        return status;
    FILE *out = file.stream;
    suite_counts counts = count_results(s, results);
    char timestamp[32] = "";
    time_t now = time(NULL);
    struct tm utc;
    if (gmtime_r(&now, &utc) != NULL)
        strftime(timestamp, sizeof timestamp, "%Y-%m-%dT%H:%M:%S", &utc);
    char host[256] = "";
    gethostname(host, sizeof host - 1);
    fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"rtspheres check\"", out);
    write_count_attributes(out, s, counts, seconds);
    fputs(">\n  <testsuite name=\"", out);
    write_escaped(out, s->name);
    fputs("\"", out);
    write_count_attributes(out, s, counts, seconds);
    fprintf(out, " timestamp=\"%s\" hostname=\"", timestamp);
    write_escaped(out, host);
    fputs("\">\n    <properties>\n      <property name=\"suite\" value=\"", out);
    write_escaped(out, s->path);
    fputs("\"/>\n    </properties>\n", out);
    for (int i = 0; i < s->case_count; i++) {
        const suite_case *c = &s->cases[i];
        const suite_case_result *result = &results[i];
        fputs("    <testcase name=\"", out);
        write_escaped(out, c->name);
        fputs("\" classname=\"rtspheres.", out);
        write_escaped(out, s->name);
        fputs("\" file=\"", out);
        write_escaped(out, c->file);
        fprintf(out, "\" line=\"%d\" time=\"%.3f\">\n", c->line, result->seconds);
        const char *element = result->verdict == SUITE_FAILED ? "failure"
                              : result->verdict == SUITE_ERROR ? "error"
                                                               : NULL;
        char metrics[4096];
        case_metrics(c, result, metrics, sizeof metrics);
        if (element != NULL) {
            fprintf(out, "      <%s message=\"", element);
            write_escaped(out, result->message);
            fprintf(out, "\" type=\"%s\">",
                    result->golden_missing ? "missing golden"
                    : result->compared     ? image_compare_test_name(result->comparison.test)
                                           : "render");
            write_escaped(out, metrics);
            fprintf(out, "</%s>\n", element);
        } else if (result->verdict == SUITE_NOT_RUN) {
            fputs("      <skipped message=\"the run was stopped before this case\"/>\n", out);
        }
        fputs("      <system-out>", out);
        if (result->verdict == SUITE_PASSED) {
            write_escaped(out, result->message);
            fputs("\n", out);
        }
        write_escaped(out, metrics);
        fputs("</system-out>\n    </testcase>\n", out);
    }
    fputs("  </testsuite>\n</testsuites>\n", out);
    return report_close(&file, error);
}

/* The page's style and its image check (the browser test reads #image-check). */
static const char report_head[] =
    "<style>\n"
    "body { font: 14px/1.4 sans-serif; margin: 1.5em; color: #222; background: #fafafa; }\n"
    "h1 { font-size: 1.5em; margin: 0 0 0.3em; }\n"
    "section.case { background: #fff; border: 1px solid #ccc; border-left: 6px solid #4a4; padding: 0.6em 1em;"
    " margin: 1em 0; }\n"
    "section.FAIL, section.ERROR { border-left-color: #c22; }\n"
    "section.not-run { border-left-color: #999; }\n"
    "h2 { font-size: 1.15em; margin: 0.2em 0; } .verdict { font-weight: bold; margin-right: 0.5em; }\n"
    ".FAIL .verdict, .ERROR .verdict { color: #c22; } .pass .verdict { color: #282; }\n"
    ".reason { font-family: monospace; margin: 0.3em 0; } .files { color: #666; font-size: 0.9em; margin: 0.2em 0; }\n"
    ".images { display: flex; flex-wrap: wrap; gap: 0.8em; }\n"
    "figure { margin: 0; } figcaption { font-size: 0.85em; color: #444; }\n"
    "img { width: 320px; image-rendering: pixelated; background: #000; display: block; }\n"
    ".legend { height: 10px; width: 320px; background: linear-gradient(to right, #fff 0%, #0ef 12.5%,"
    " #0d4cff 25%, #0a1a6e 37.5%, #000 50%, #6e0a0a 62.5%, #ff1a0a 75%, #ffec00 87.5%, #fff 100%); }\n"
    ".ticks { width: 320px; display: flex; justify-content: space-between; font-size: 0.75em; color: #666; }\n"
    "pre { background: #f3f3f3; padding: 0.5em; overflow-x: auto; font-size: 0.85em; }\n"
    "</style>\n";

static const char report_script[] =
    "<script>\n"
    "window.addEventListener('load', function () {\n"
    "  var images = document.images, loaded = 0;\n"
    "  for (var i = 0; i < images.length; i++)\n"
    "    if (images[i].complete && images[i].naturalWidth > 0) loaded++;\n"
    "  var check = document.getElementById('image-check');\n"
    "  var text = 'images loaded: ' + loaded + ' of ' + images.length;\n"
    "  check.textContent = text;\n"
    "  check.setAttribute('data-loaded', loaded);\n"
    "  check.setAttribute('data-total', images.length);\n"
    "  console.log('rtspheres report: ' + text);\n"
    "});\n"
    "</script>\n";

/* One figure of a case: its preview file (relative to the page) and caption. */
static void write_figure(FILE *out, const char *name, const char *file, const char *caption, bool legend)
{
    fprintf(out, "<figure><img src=\"cases/%s/%s\" alt=\"", name, file);
    write_escaped(out, caption);
    fputs("\"><figcaption>", out);
    write_escaped(out, caption);
    fputs("</figcaption>", out);
    if (legend)
        fputs("<div class=\"legend\"></div><div class=\"ticks\"><span>-2</span><span>-1</span><span>0</span>"
              "<span>1</span><span>2</span></div>", out);
    fputs("</figure>\n", out);
}

/* One case's section. */
static void write_case(FILE *out, const suite_case *c, const suite_case_result *result)
{
    const char *verdict = suite_verdict_name(result->verdict);
    fprintf(out, "<section class=\"case %s\" id=\"case-%s\">\n<h2><span class=\"verdict\">%s</span>",
            result->verdict == SUITE_NOT_RUN ? "not-run" : verdict, c->name, verdict);
    write_escaped(out, c->name);
    fputs("</h2>\n<p class=\"reason\">", out);
    write_escaped(out, result->verdict == SUITE_NOT_RUN ? "the run was stopped before this case" : result->message);
    fputs("</p>\n<p class=\"files\">", out);
    write_escaped(out, c->file);
    fprintf(out, ":%d &middot; scene ", c->line);
    write_escaped(out, c->scene);
    fputs(" &middot; golden ", out);
    write_escaped(out, c->golden);
    fprintf(out, " &middot; %.2f s%s</p>\n", result->seconds, result->updated ? " &middot; golden updated" : "");
    if (result->previews) {
        fputs("<div class=\"images\">\n", out);
        if (result->reference_preview)
            write_figure(out, c->name, "reference.png", "reference (golden)", false);
        write_figure(out, c->name, "new.png", "new render", false);
        if (result->difference_preview) {
            double scale = result->options.idiff.diff_scale;
            char caption[64];
            snprintf(caption, sizeof caption, "|new - reference| x %g", scale > 0 ? scale : IMAGE_DIFF_DEFAULT_SCALE);
            write_figure(out, c->name, "difference.png", caption, false);
        }
        if (result->significance_preview) {
            const image_stat_result *stat = &result->comparison.stat;
            char scale[32], caption[160];
            image_compare_scale_name(stat->scales[stat->map_scale].block_size, scale, sizeof scale);
            snprintf(caption, sizeof caption, "z / threshold of %s (red: new brighter, blue: darker; beyond 1 fails)",
                     scale);
            write_figure(out, c->name, "significance.png", caption, true);
        }
        fputs("</div>\n", out);
    }
    char metrics[4096];
    case_metrics(c, result, metrics, sizeof metrics);
    fprintf(out, "<details%s><summary>metrics</summary><pre>", result->verdict == SUITE_PASSED ? "" : " open");
    write_escaped(out, metrics);
    fputs("</pre></details>\n</section>\n", out);
}

rt_status suite_write_report(const char *directory, const suite *s, const suite_case_result *results,
                             double seconds, rt_error *error)
{
    char path[SUITE_PATH_MAX + 16];
    snprintf(path, sizeof path, "%s/index.html", directory);
    report_file file;
    rt_status status = report_open(&file, path, error);
    if (status != RT_OK)
        return status;
    FILE *out = file.stream;
    suite_counts counts = count_results(s, results);
    fputs("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>rtspheres check: ", out);
    write_escaped(out, s->name);
    fprintf(out, "</title>\n%s</head>\n<body>\n<h1>rtspheres check: ", report_head);
    write_escaped(out, s->name);
    fprintf(out, "</h1>\n<p class=\"summary\">%d cases: %d passed, %d failed, %d errors, %d not run, in %.1f s. "
                 "Suite: ", s->case_count, counts.passed, counts.failed, counts.errors, counts.not_run, seconds);
    write_escaped(out, s->path);
    fputs(".</p>\n<p id=\"image-check\">images: not checked (the page's script did not run)</p>\n", out);
    /* Failures and errors first, then passes, then the cases not run; each in suite order. */
    static const suite_verdict order[3][2] = {{SUITE_FAILED, SUITE_ERROR}, {SUITE_PASSED, SUITE_PASSED},
                                              {SUITE_NOT_RUN, SUITE_NOT_RUN}};
    for (int group = 0; group < 3; group++)
        for (int i = 0; i < s->case_count; i++)
            if (results[i].verdict == order[group][0] || results[i].verdict == order[group][1])
                write_case(out, &s->cases[i], &results[i]);
    fprintf(out, "%s</body>\n</html>\n", report_script);
    return report_close(&file, error);
}
