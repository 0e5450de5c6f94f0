/* scene_parse.c: see scene_parse.h; the format is documented in docs/scene-format.md.
 *
 * The parser is split along the seam of pbrt-v4's parser and scene builder:
 *   core/scene_lexer.c        files, includes, lines and tokens with their positions
 *   core/scene_values.c       the values of clauses (numbers, colours, names) and variables
 *   core/scene_statements*.c  the statement table: each keyword's clauses, read and passed on
 *   core/scene_builder.c      blocks, transforms, placements, instances, group replay: the scene
 *   core/scene_validate.c     the checks that need the whole file
 *   core/scene_report.c       how every part reports a failure ("FILE:LINE:COLUMN: ...")
 *   core/affine.c             the double-precision maths of transforms and directions
 * This file runs them in that order for one scene_load_* call and owns nothing longer. */
#include "scene_parse.h"

#include <string.h>

#include "scene_statements.h"
#include "scene_validate.h"

#define DEFAULT_MAX_INCLUDE_DEPTH 16

scene_parse_options scene_parse_options_defaults(void)
{
    return (scene_parse_options){0};
}

/* Starts a parse into out (set to scene_defaults()). */
static void parser_init(scene_parser *p, const scene_parse_options *options, scene *out, rt_error *error)
{
    *p = (scene_parser){.report = {.error = error, .status = RT_OK}};
    int max_include_depth = options->max_include_depth > 0 ? options->max_include_depth : DEFAULT_MAX_INCLUDE_DEPTH;
    lexer_init(&p->lexer, &p->report, max_include_depth);
    variables_init(&p->variables, &p->report);
    scene_defaults(out);
    builder_init(&p->builder, out, &p->report);
}

/* Frees what the parser owns (paths, variables, the builder's buffers); never the scene. */
static void parser_free(scene_parser *p)
{
    variables_free(&p->variables);
    builder_free(&p->builder);
    lexer_free(&p->lexer);
}

/* Both entry points: parses the file at path, or else text (named source_name), into
 * out, and frees everything it made, the scene too on failure (leaving *out as
 * scene_defaults()). */
static rt_status load_scene(const char *path, const char *text, const char *source_name,
                            const scene_parse_options *options, scene *out, rt_error *error)
{
    static const scene_parse_options defaults = {0};
    if (options == NULL)
        options = &defaults;
    scene_parser p;
    parser_init(&p, options, out, error);
    source_file top;
    bool opened = path != NULL ? lexer_open_top_file(&p.lexer, path, &top)
                               : lexer_open_string(&p.lexer, text, source_name, &top);
    bool ok = opened && variables_apply_defines(&p.variables, options) && parse_source(&p, &top) &&
              builder_finish(&p.builder) && validate_scene(&p.builder, &p.variables, options, &p.report);
    if (opened)
        source_file_close(&top);
    parser_free(&p);
    if (!ok)
        scene_free(out);
    return ok ? RT_OK : p.report.status;
}

rt_status scene_load_file(const char *path, const scene_parse_options *options, scene *out, rt_error *error)
{
    if (out == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "SCENE: scene_load_file needs an output scene");
    if (path == NULL) {
        scene_defaults(out);
        return rt_error_set(error, RT_ERROR_INPUT, "SCENE: no scene file given");
    }
    return load_scene(path, NULL, NULL, options, out, error);
}

rt_status scene_load_string(const char *text, const char *source_name, const scene_parse_options *options,
                            scene *out, rt_error *error)
{
    if (out == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "SCENE: scene_load_string needs an output scene");
    if (text == NULL) {
        scene_defaults(out);
        return rt_error_set(error, RT_ERROR_INPUT, "SCENE: no scene text given");
    }
    return load_scene(NULL, text, source_name != NULL ? source_name : "<string>", options, out, error);
}
