/* scene_parse.h: reads the rtspheres scene text format (version 1) into a scene.
 *
 * The format is documented in docs/scene-format.md (linked from README.md). Every error is reported as
 *   "FILE:LINE:COLUMN: what was found, and what was expected"
 * (1-based line and column, FILE as given or as resolved for an include) and returned
 * as RT_ERROR_INPUT. A file that cannot be read is RT_ERROR_INPUT too. error may be NULL.
 *
 * Variables: `set NAME VALUE` in the file defines $NAME. A define passed in
 * scene_parse_options (from the command line's -D NAME=VALUE) wins over the file's
 * `set`, so scripts can sweep a value. A define that names a variable the scene never
 * sets nor uses is an error (a typo would otherwise silently do nothing).
 *
 * Defaults of scene_parse_options (all zero):
 *   defines NULL / define_count 0: no overrides
 *   max_include_depth 0: 16
 */
#ifndef RT_SCENE_PARSE_H
#define RT_SCENE_PARSE_H

#include <stdbool.h>

#include "scene.h"
#include "status.h"

typedef struct scene_define {
    const char *name;            /* variable name without '$' */
    const char *value;           /* text of a number or expression, e.g. "0.5" or "2*pi" */
    bool optional;               /* true: no error when the scene does not use it
                                  * (the renderer's own $frame and $time) */
} scene_define;

typedef struct scene_parse_options {
    const scene_define *defines;
    int define_count;
    int max_include_depth;
} scene_parse_options;

/* Returns options with every field at its default (all zero). */
scene_parse_options scene_parse_options_defaults(void);

/* Parses the file at path into *out (which it initialises with scene_defaults() first).
 * options may be NULL for defaults. On failure *out is freed and error says why.
 * The caller frees a successful *out with scene_free(). The file is only read. */
rt_status scene_load_file(const char *path, const scene_parse_options *options,
                          scene *out, rt_error *error);

/* The same for text in memory; source_name is used in messages and include paths are
 * resolved relative to the directory part of source_name. */
rt_status scene_load_string(const char *text, const char *source_name,
                            const scene_parse_options *options, scene *out, rt_error *error);

#endif
