/* render_stats.c: see render_stats.h; the schema is docs/stats-json.md. */
#include "render_stats.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "version.h"

void render_stats_init(render_stats *stats, const gpu_info *device, int threads_requested, double context_seconds,
                       double before_command_seconds, const char *scene, const char *output)
{
    memset(stats, 0, sizeof *stats);
    if (device != NULL)
        stats->device = *device;
    stats->threads_requested = threads_requested;
    stats->context_seconds = context_seconds;
    stats->before_command_seconds = before_command_seconds;
    stats->scene = scene;
    stats->output = output;
}

void render_stats_free(render_stats *stats)
{
    free(stats->images);
    memset(stats, 0, sizeof *stats);
}

const char *render_stats_outcome_name(render_stats_outcome outcome)
{
    switch (outcome) {
    case RENDER_STATS_SKIPPED: return "skipped";
    case RENDER_STATS_FAILED: return "failed";
    case RENDER_STATS_INTERRUPTED: return "interrupted";
    default: return "rendered";
    }
}

/* The process's peak resident set so far in bytes (getrusage: kibibytes on Linux), -1
 * when it cannot be read. */
static long long peak_rss_bytes(void)
{
    struct rusage usage;
    if (getrusage(RUSAGE_SELF, &usage) != 0)
        return -1;
    return (long long)usage.ru_maxrss * 1024;
}

/* Appends an entry for image to stats and returns it (its plan and output copied), or
 * NULL when memory ran out. */
static render_stats_image *add_entry(render_stats *stats, const render_job_image *image, rt_error *error)
{
    if (stats->image_count == stats->image_capacity) {
        int capacity = stats->image_capacity ? 2 * stats->image_capacity : 16;
        render_stats_image *grown = realloc(stats->images, (size_t)capacity * sizeof *grown);
        if (grown == NULL) {
            rt_error_set(error, RT_ERROR_RUNTIME, "STATS: out of memory");
            return NULL;
        }
        stats->images = grown;
        stats->image_capacity = capacity;
    }
    render_stats_image *entry = &stats->images[stats->image_count++];
    memset(entry, 0, sizeof *entry);
    entry->plan = *image;
    snprintf(entry->output, sizeof entry->output, "%s", image->output ? image->output : "");
    entry->plan.output = entry->output;
    entry->peak_rss_bytes = peak_rss_bytes();
    entry->first_pass_after_start = -1;
    return entry;
}

rt_status render_stats_add_rendered(render_stats *stats, const render_job_image *image, const render_result *result,
                                    bool resumed, double first_pass_after_start, rt_error *error)
{
    render_stats_image *entry = add_entry(stats, image, error);
    if (entry == NULL)
        return RT_ERROR_RUNTIME;
    entry->outcome = RENDER_STATS_RENDERED;
    entry->resumed = resumed;
    entry->has_result = true;
    entry->result = *result;
    entry->result.image = (rt_image){0};
    entry->result.aovs = (rt_image){0};
    entry->result.light_groups = (rt_image){0};
    entry->first_pass_after_start = first_pass_after_start;
    /* Per-pixel samples: the samples channel (the fourth) of the result. */
    const rt_image *pixels = &result->image;
    size_t count = (size_t)pixels->width * pixels->height;
    double sum = 0;
    uint32_t lowest = UINT32_MAX, highest = 0;
    for (size_t i = 0; i < count && pixels->channels >= 4; i++) {
        uint32_t samples = (uint32_t)pixels->pixels[i * pixels->channels + 3];
        lowest = samples < lowest ? samples : lowest;
        highest = samples > highest ? samples : highest;
        sum += samples;
    }
    entry->spp_min = count > 0 && pixels->channels >= 4 ? lowest : 0;
    entry->spp_max = highest;
    entry->spp_mean = count > 0 ? sum / (double)count : 0;
    /* A tiled image (render_job.h "Tiles") comes without pixels: its tiles' figures. */
    if (pixels->pixels == NULL && count > 0) {
        entry->spp_min = result->samples_min;
        entry->spp_max = result->samples_max;
        entry->spp_mean = (double)result->samples / (double)count;
    }
    return RT_OK;
}

rt_status render_stats_add_other(render_stats *stats, const render_job_image *image, render_stats_outcome outcome,
                                 const char *note, rt_error *error)
{
    render_stats_image *entry = add_entry(stats, image, error);
    if (entry == NULL)
        return RT_ERROR_RUNTIME;
    entry->outcome = outcome;
    snprintf(entry->note, sizeof entry->note, "%s", note ? note : "");
    return RT_OK;
}

/* Writes text as a JSON string (quotes, backslash and control characters escaped). */
static void write_string(FILE *out, const char *text)
{
    fputc('"', out);
    for (const unsigned char *c = (const unsigned char *)(text ? text : ""); *c != '\0'; c++) {
        if (*c == '"' || *c == '\\')
            fprintf(out, "\\%c", *c);
        else if (*c == '\n')
            fputs("\\n", out);
        else if (*c < 0x20)
            fprintf(out, "\\u%04x", *c);
        else
            fputc(*c, out);
    }
    fputc('"', out);
}

/* Writes a number JSON can hold (a non-finite one as null). */
static void write_number(FILE *out, double value)
{
    if (isfinite(value))
        fprintf(out, "%.9g", value);
    else
        fputs("null", out);
}

/* "key": value pairs, with the separator before all but the first of an object. */
typedef struct json_object {
    FILE *out;
    int fields;
    int indent;
} json_object;

static void key(json_object *object, const char *name)
{
    fprintf(object->out, "%s\n%*s\"%s\": ", object->fields++ ? "," : "", object->indent, "", name);
}

static void field_string(json_object *object, const char *name, const char *value)
{
    key(object, name);
    write_string(object->out, value);
}

static void field_number(json_object *object, const char *name, double value)
{
    key(object, name);
    write_number(object->out, value);
}

static void field_integer(json_object *object, const char *name, long long value)
{
    key(object, name);
    fprintf(object->out, "%lld", value);
}

static void field_bool(json_object *object, const char *name, bool value)
{
    key(object, name);
    fputs(value ? "true" : "false", object->out);
}

/* Opens a nested object as the value of name; close it with end_object(). */
static json_object begin_object(json_object *parent, const char *name)
{
    key(parent, name);
    fputc('{', parent->out);
    return (json_object){.out = parent->out, .indent = parent->indent + 2};
}

static void end_object(json_object *object)
{
    fprintf(object->out, "\n%*s}", object->indent - 2, "");
}

/* Writes a rendered image's figures into object; before_command_seconds as in render_stats. */
static void write_result(json_object *object, const render_stats_image *entry, double before_command_seconds)
{
    const render_result *r = &entry->result;
    double seconds = r->seconds > 0 ? r->seconds : 0;
    int width = r->region[2] - r->region[0], height = r->region[3] - r->region[1];
    field_integer(object, "width", width);
    field_integer(object, "height", height);
    field_integer(object, "passes", r->passes);
    field_string(object, "stop_reason", render_stop_reason_name(r->stop_reason));
    field_bool(object, "resumed", entry->resumed);
    field_integer(object, "samples", (long long)r->samples);
    json_object spp = begin_object(object, "spp_per_pixel");
    field_integer(&spp, "min", entry->spp_min);
    field_number(&spp, "mean", entry->spp_mean);
    field_integer(&spp, "max", entry->spp_max);
    end_object(&spp);
    field_number(object, "path_segments", r->path_segments);
    field_number(object, "samples_per_second", seconds > 0 ? (double)r->samples / seconds : 0);
    field_number(object, "path_segments_per_second", seconds > 0 ? r->path_segments / seconds : 0);
    field_number(object, "steady_seconds_per_sample",
                 r->steady_samples > 0 ? r->steady_seconds / (double)r->steady_samples : 0);
    json_object times = begin_object(object, "seconds");
    field_number(&times, "total", r->seconds);
    field_number(&times, "packing", r->pack_seconds);
    field_number(&times, "bvh_build", r->bvh_build_seconds);
    field_number(&times, "upload", r->upload_seconds);
    field_number(&times, "compile", r->compile_seconds);
    field_number(&times, "first_pass", r->first_pass_seconds);
    field_number(&times, "first_pass_after_command_start", entry->first_pass_after_start);
    field_number(&times, "first_pass_after_process_start",
                 entry->first_pass_after_start < 0 ? -1 : entry->first_pass_after_start + before_command_seconds);
    field_number(&times, "after_first_pass", r->steady_seconds);
    end_object(&times);
    json_object scene = begin_object(object, "scene");
    field_integer(&scene, "primitives", r->primitive_count);
    field_integer(&scene, "triangles", r->triangle_count);
    field_integer(&scene, "instances", r->instance_count);
    field_integer(&scene, "lights", r->light_count);
    field_string(&scene, "light_choice", render_light_choice_name(r->light_choice));
    field_integer(&scene, "light_tree_depth", r->light_tree_depth);
    field_integer(&scene, "bvh_depth", r->bvh_depth);
    field_integer(&scene, "packed_bytes", (long long)r->packed_bytes);
    field_integer(&scene, "image_bytes", (long long)r->image_bytes);
    field_bool(&scene, "already_on_device", r->reused_scene);
    field_bool(&scene, "program_compiled", r->compiled_program);
    end_object(&scene);
    char hash[24];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)r->scene_hash);
    field_string(object, "scene_hash", hash);
}

/* Writes one image's object; before_command_seconds as in render_stats. */
static void write_image(FILE *out, const render_stats_image *entry, double before_command_seconds)
{
    json_object object = {.out = out, .indent = 6};
    fputs("    {", out);
    field_string(&object, "output", entry->output);
    field_string(&object, "outcome", render_stats_outcome_name(entry->outcome));
    if (entry->note[0] != '\0')
        field_string(&object, "note", entry->note);
    field_integer(&object, "frame", entry->plan.frame);
    field_integer(&object, "sweep_row", entry->plan.sweep_row);
    const int *window = entry->plan.window;
    key(&object, "window");
    fprintf(out, "[%d, %d, %d, %d]", window[0], window[1], window[2], window[3]);
    field_integer(&object, "spp", entry->plan.samples_per_pixel);
    field_integer(&object, "sample_start", entry->plan.sample_start);
    char hash[24];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)entry->plan.options_hash);
    field_string(&object, "options_hash", hash);
    if (entry->has_result)
        write_result(&object, entry, before_command_seconds);
    field_number(&object, "peak_rss_bytes", (double)entry->peak_rss_bytes);
    fputs("\n    }", out);
}

/* Writes the whole document to out. */
static void write_document(FILE *out, const render_stats *stats)
{
    json_object top = {.out = out, .indent = 2};
    fputc('{', out);
    field_string(&top, "schema", "rtspheres-render-stats");
    field_integer(&top, "version", RENDER_STATS_SCHEMA_VERSION);
    field_string(&top, "rtspheres_version", RTSPHERES_VERSION);
    field_string(&top, "scene", stats->scene);
    field_string(&top, "output", stats->output);
    const gpu_info *d = &stats->device;
    json_object device = begin_object(&top, "device");
    field_string(&device, "platform", d->platform);
    field_integer(&device, "egl_device", d->device_index);
    field_string(&device, "gl_vendor", d->gl_vendor);
    field_string(&device, "gl_renderer", d->gl_renderer);
    field_string(&device, "gl_version", d->gl_version);
    field_bool(&device, "software", d->software);
    field_integer(&device, "threads", d->software ? d->software_threads : 0);
    field_integer(&device, "threads_requested", stats->threads_requested);
    field_integer(&device, "max_texture_size", d->max_texture_size);
    field_integer(&device, "max_texture_buffer_size", d->max_texture_buffer_size);
    field_integer(&device, "work_cap", d->work_cap);
    field_number(&device, "context_seconds", stats->context_seconds);
    end_object(&device);
    key(&top, "images");
    fputc('[', out);
    int rendered = 0, skipped = 0, failed = 0;
    double samples = 0, segments = 0;
    for (int i = 0; i < stats->image_count; i++) {
        const render_stats_image *entry = &stats->images[i];
        fputs(i > 0 ? ",\n" : "\n", out);
        write_image(out, entry, stats->before_command_seconds);
        rendered += entry->outcome == RENDER_STATS_RENDERED;
        skipped += entry->outcome == RENDER_STATS_SKIPPED;
        failed += entry->outcome == RENDER_STATS_FAILED || entry->outcome == RENDER_STATS_INTERRUPTED;
        if (entry->has_result) {
            samples += (double)entry->result.samples;
            segments += entry->result.path_segments;
        }
    }
    fputs(stats->image_count > 0 ? "\n  ]" : "]", out);
    json_object summary = begin_object(&top, "summary");
    field_bool(&summary, "finished", stats->job_finished);
    if (stats->job_error != NULL)
        field_string(&summary, "error", stats->job_error);
    field_integer(&summary, "rendered", rendered);
    field_integer(&summary, "skipped", skipped);
    field_integer(&summary, "failed", failed);
    field_number(&summary, "samples", samples);
    field_number(&summary, "path_segments", segments);
    field_number(&summary, "seconds", stats->job_seconds);
    field_number(&summary, "peak_rss_bytes", (double)peak_rss_bytes());
    end_object(&summary);
    fputs("\n}\n", out);
}

rt_status render_stats_write(const render_stats *stats, const char *path, rt_error *error)
{
    char temporary[RENDER_JOB_PATH_MAX + 16];
    snprintf(temporary, sizeof temporary, "%s.tmpXXXXXX", path);
    int descriptor = mkstemp(temporary);
    FILE *out = NULL;
    if (descriptor >= 0 && fchmod(descriptor, 0644) == 0)
        out = fdopen(descriptor, "w");
    if (out == NULL) {
        int saved = errno;
        if (descriptor >= 0) {
            close(descriptor);
            unlink(temporary);
        }
        return rt_error_set(error, RT_ERROR_RUNTIME, "STATS: cannot write '%s': %s", path, strerror(saved));
    }
    write_document(out, stats);
    bool ok = !ferror(out);
    ok = fclose(out) == 0 && ok;
    if (ok && rename(temporary, path) == 0)
        return RT_OK;
    int saved = errno ? errno : EIO;
    unlink(temporary);
    return rt_error_set(error, RT_ERROR_RUNTIME, "STATS: cannot write '%s': %s", path, strerror(saved));
}
