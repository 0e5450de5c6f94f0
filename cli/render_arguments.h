/* render_arguments.h: the options of `rtspheres render` turned into a render job
 * (core/render_job.h) plus what only the command uses (quiet, verbose, the device). The
 * rules between options that are the job's (crop with tile, shards, ...) are checked by
 * render_job_check(); here only what the command line itself can get wrong: a value's
 * syntax and range, the scene and output being there.
 */
#ifndef RT_RENDER_ARGUMENTS_H
#define RT_RENDER_ARGUMENTS_H

#include <stdbool.h>
#include <stdio.h>

#include "batch.h"
#include "render_job.h"

#define RENDER_ARGUMENTS_MAX_DEFINES 256

/* --progress: how a running render shows how far it is. */
typedef enum render_progress_mode {
    PROGRESS_AUTO = 0,           /* the bar on a terminal, else lines */
    PROGRESS_BAR,                /* a bar redrawn with carriage returns */
    PROGRESS_LINES,              /* a line every progress_interval seconds */
    PROGRESS_NONE,
} render_progress_mode;

#define RENDER_ARGUMENTS_DEFAULT_PROGRESS_INTERVAL 5.0

typedef struct render_arguments {
    render_job job;              /* its frames and defines point into this struct */
    bool quiet, verbose;
    render_progress_mode progress;
    double progress_interval;    /* --progress-interval SECONDS (default 5; 0: every pass) */
    const char *stats_json;      /* --stats-json FILE, or NULL */
    int threads;                 /* --threads N, or 0: the device's default */
    int device;                  /* --device N, or -1: let gpu.h choose */
    frame_list frames;
    sweep_table sweep;           /* --sweep's table (job.sweep points here) */
    const char *display;         /* --display HOST:PORT, or NULL */
    scene_define defines[RENDER_ARGUMENTS_MAX_DEFINES];
    char *define_copies[RENDER_ARGUMENTS_MAX_DEFINES];  /* NAME\0VALUE of each -D */
    FILE *messages;              /* where complaints go, after message_prefix */
    const char *message_prefix;
} render_arguments;

/* Parses argv (argv[0] is "render") into *arguments (initialised here; free with
 * render_arguments_free() whatever the result). Returns EXIT_OK, or an exit code after
 * printing why on stderr; *help_shown is set when --help printed the help (then nothing
 * else is to be done). */
int render_arguments_parse(int argc, char **argv, render_arguments *arguments, bool *help_shown);

/* The same, with each complaint written to messages after prefix (one line each) instead
 * of to stderr after "rtspheres render: ", and getopt's messages replaced by such lines
 * ("unknown render option '--x'", "--size needs a value"): how `rtspheres check` reads a
 * suite case's render options. */
int render_arguments_parse_to(int argc, char **argv, render_arguments *arguments, bool *help_shown, FILE *messages,
                              const char *prefix);

/* Frees what parsing allocated and zeroes *arguments. */
void render_arguments_free(render_arguments *arguments);

#endif
