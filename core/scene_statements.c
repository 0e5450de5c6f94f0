/* scene_statements.c: the statement table and its dispatch over the lines of a file, and
 * the statements of files, variables and settings (see scene_statements.h). */
#include "scene_statements.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expression.h"

/* scene_image.path and scene_mesh.path hold at most this many bytes plus the NUL. */
#define MAX_ASSET_PATH 1023

/* ------------------------------------------------------------------ the table */

/* The statements, by their first word, in the order the "unknown statement" message lists
 * them. Transforms and include do not count as a block's content (transforms must come
 * first; an include's own statements count). */
static const struct {
    const char *keyword;
    statement_parser parse;
    bool is_content;
} statements[] = {
    {"include", statement_include, false},
    {"set", statement_set, true},
    {"camera", statement_camera, true},
    {"render", statement_render, true},
    {"sky", statement_sky, true},
    {"ambient", statement_ambient, true},
    {"light", statement_light, false},          /* top level only: it checks that itself */
    {"texture", statement_texture, true},
    {"material", statement_material, true},
    {"sphere", statement_sphere, true},
    {"moving_sphere", statement_moving_sphere, true},
    {"triangle", statement_triangle, true},
    {"quad", statement_quad, true},
    {"box", statement_box, true},
    {"mesh", statement_mesh, true},
    {"gltf", statement_gltf, true},
    {"group", statement_group, true},
    {"instance", statement_instance, true},
    {"volume", statement_volume, true},
    {"translate", statement_translate, false},
    {"rotate", statement_rotate, false},
    {"scale", statement_scale, false},
    {"matrix", statement_matrix, false},
};

/* Parses one line: checks its bytes, then dispatches on the first word (or brace). */
static bool parse_statement(scene_parser *p, source_line *line)
{
    token keyword = {.kind = TOKEN_END};
    if (!lexer_start_statement(line, &keyword))
        return false;
    if (keyword.kind == TOKEN_END)
        return true;
    if (keyword.kind == TOKEN_CLOSE_BRACE)
        return statement_close(p, line, &keyword);
    if (keyword.kind == TOKEN_OPEN_BRACE)
        return fail_at(line, keyword.offset, "unexpected '{' (only a group, instance or volume line ends with '{')");
    for (size_t i = 0; i < sizeof statements / sizeof statements[0]; i++) {
        if (!token_is(line, &keyword, statements[i].keyword))
            continue;
        source_position where = token_position(line, &keyword);
        if (statements[i].is_content &&
            !builder_begin_content(&p->builder, line->text + keyword.offset, keyword.length, &where))
            return false;
        return statements[i].parse(p, line, &keyword);
    }
    const char *keywords[sizeof statements / sizeof statements[0]];
    for (size_t i = 0; i < sizeof statements / sizeof statements[0]; i++)
        keywords[i] = statements[i].keyword;
    char word[FOUND_BUFFER], expected[2 * DESCRIPTION_BUFFER];
    return fail_at(line, keyword.offset, "unknown statement %s (expected %s)",
                   describe_token(line, &keyword, word, sizeof word),
                   format_word_list(expected, sizeof expected, keywords, (int)(sizeof keywords / sizeof keywords[0])));
}

bool parse_source(scene_parser *p, const source_file *file)
{
    int depth_before = builder_depth(&p->builder);
    source_line line = {0};
    while (source_file_next_line(file, &line))
        if (!parse_statement(p, &line))
            return false;
    return builder_check_file_closed(&p->builder, depth_before, file->path);
}

bool read_clauses(scene_parser *p, source_line *line, const char *statement, const char *const *names, int count,
                  clause_reader read_value, void *target)
{
    size_t first_offsets[MAX_CLAUSES];
    for (int i = 0; i < count; i++)
        first_offsets[i] = SIZE_MAX;
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(line, &t))
            return false;
        if (t.kind == TOKEN_END)
            return true;
        int clause = -1;
        if (!match_clause(line, &t, statement, names, count, first_offsets, &clause) ||
            !read_value(p, line, clause, target))
            return false;
    }
}

/* ------------------------------------------------------------------ asset paths */

bool read_asset_path(source_line *line, const char *what, char **resolved, size_t *offset)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    char found[FOUND_BUFFER];
    if (t.kind != TOKEN_STRING)
        return fail_at(line, t.offset, "expected a quoted path for %s (e.g. \"file.png\"), found %s", what,
                       describe_token(line, &t, found, sizeof found));
    if (t.length == 2)
        return fail_at(line, t.offset, "expected a path inside the quotes of %s, found an empty string", what);
    char *path = resolve_relative_path(line->file->path, line->text + t.offset + 1, t.length - 2);
    if (path == NULL)
        return fail_out_of_memory(line->file->report);
    size_t length = strlen(path);
    if (length > MAX_ASSET_PATH) {
        free(path);
        return fail_at(line, t.offset, "the path of %s is %zu bytes long once resolved; the limit is %d", what,
                       length, MAX_ASSET_PATH);
    }
    *resolved = path;
    *offset = t.offset;
    return true;
}

bool read_image(scene_parser *p, source_line *line, const char *what, int *image)
{
    char *path = NULL;
    size_t offset = 0;
    if (!read_asset_path(line, what, &path, &offset))
        return false;
    bool added = builder_add_image(&p->builder, path, position_in(line, offset), image);
    free(path);
    return added;
}

bool read_light_group(scene_parser *p, source_line *line, const char *owner, int *group)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    char kind[DESCRIPTION_BUFFER], name[SCENE_NAME_MAX];
    snprintf(kind, sizeof kind, "light group (of %s)", owner);
    if (t.kind == TOKEN_END)
        return fail_at(line, t.offset, "expected a %s name, found end of line", kind);
    if (!name_from_token(line, &t, kind, name))
        return false;
    if (strlen(name) > SCENE_LIGHT_GROUP_NAME_MAX)
        return fail_at(line, t.offset, "light group name '%s' is %zu bytes long; the limit is %d", name,
                       strlen(name), SCENE_LIGHT_GROUP_NAME_MAX);
    if (strchr(name, '.') != NULL)
        return fail_at(line, t.offset, "light group name '%s' has a '.', which EXR layer names keep for "
                       "their channels (use letters, digits, '_' and '-')", name);
    *group = builder_light_group(&p->builder, name);
    if (*group < 0)
        return fail_at(line, t.offset, "light group '%s' is one more than the %d a scene may have", name,
                       SCENE_LIGHT_GROUP_MAX);
    return true;
}

/* ------------------------------------------------------------------ files and variables */

/* include "PATH": parses the file at PATH (relative to the including file's directory)
 * as if its lines stood here, after checking for cycles and the depth limit. */
bool statement_include(scene_parser *p, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    char found[FOUND_BUFFER];
    if (t.kind != TOKEN_STRING)
        return fail_at(line, t.offset, "expected a quoted path after include (e.g. include \"common.txt\"), found %s",
                       describe_token(line, &t, found, sizeof found));
    if (t.length == 2)
        return fail_at(line, t.offset, "expected a path inside the quotes of include, found an empty string");
    if (!expect_end_of_line(line, "the included path"))
        return false;
    source_file included;
    if (!lexer_open_include(&p->lexer, line, keyword->offset, &t, &included))
        return false;
    bool ok = parse_source(p, &included);
    source_file_close(&included);
    return ok;
}

/* set NAME EXPRESSION: defines $NAME, unless a -D define already fixed it. */
bool statement_set(scene_parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    token name = {.kind = TOKEN_END};
    if (!next_token(line, &name))
        return false;
    char found[FOUND_BUFFER];
    if (name.kind == TOKEN_END)
        return fail_at(line, name.offset, "expected a variable name after set, found end of line");
    const char *text = line->text + name.offset;
    if (name.kind != TOKEN_WORD || !expression_is_variable_name(text, name.length))
        return fail_at(line, name.offset, "expected a variable name after set (letters, digits and '_', not "
                       "starting with a digit%s), found %s", name.kind == TOKEN_WORD && text[0] == '$' ?
                       "; write it without '$'" : "", describe_token(line, &name, found, sizeof found));

    /* The rest of the line, up to a comment, is one expression: no parentheses needed. */
    size_t start = 0, end = 0;
    take_rest_of_line(line, &start, &end);
    if (start == end)
        return fail_at(line, name.offset + name.length, "expected an expression for $%.*s, found end of line",
                       quoted_length(text, name.length), text);

    scene_variable *target = variables_find_or_add(&p->variables, text, name.length);
    if (target == NULL)
        return false;
    target->mentioned = true;
    if (target->from_define) {
        variables_mention_names_in(&p->variables, line->text + start, end - start);
        return true;
    }
    double value = 0;
    if (!evaluate_expression(&p->variables, line, start, end - start, &value))
        return false;
    target->value = value;
    target->has_value = true;
    return true;
}

/* ------------------------------------------------------------------ settings */

/* Reads the value of camera clause (an index into statement_camera's clauses) into the
 * scene_camera target. */
static bool read_camera_clause(scene_parser *p, source_line *line, int clause, void *target)
{
    scene_camera *camera = target;
    scene_variables *variables = &p->variables;
    double value = 0, close = 0;
    size_t offset = 0, close_offset = 0;
    char number[NUMBER_BUFFER], close_number[NUMBER_BUFFER];
    switch (clause) {
    case 0:
        return read_vector(variables, line, "the camera's from", camera->look_from, NULL);
    case 1:
        return read_vector(variables, line, "the camera's at", camera->look_at, NULL);
    case 2:
        return read_vector(variables, line, "the camera's up", camera->up, NULL);
    case 3:
        if (!read_number(variables, line, "the camera's fov", &value, &offset))
            return false;
        if (!(value > 0 && value < 180))
            return fail_at(line, offset, "the camera's fov must be between 0 and 180 degrees (both excluded), "
                           "found %s", format_number(number, sizeof number, value));
        camera->vertical_fov_degrees = (float)value;
        return true;
    case 4:
        return read_non_negative_float(variables, line, "the camera's aperture", &camera->aperture);
    case 5:
        if (!read_number(variables, line, "the camera's focus distance", &value, &offset))
            return false;
        if (value < 0)
            return fail_at(line, offset, "the camera's focus distance must be >= 0 (0 means the distance to 'at'), "
                           "found %s", format_number(number, sizeof number, value));
        return to_float(line, offset, "the camera's focus distance", value, &camera->focus_distance);
    default:
        if (!read_number(variables, line, "the camera's shutter open time", &value, &offset) ||
            !read_number(variables, line, "the camera's shutter close time", &close, &close_offset))
            return false;
        if (!(value >= 0 && value <= 1) || !(close >= value && close <= 1))
            return fail_at(line, value >= 0 && value <= 1 ? close_offset : offset, "the camera's shutter must have "
                           "0 <= open <= close <= 1, found open %s and close %s",
                           format_number(number, sizeof number, value),
                           format_number(close_number, sizeof close_number, close));
        camera->shutter_open = (float)value;
        camera->shutter_close = (float)close;
        return true;
    }
}

/* camera [from X Y Z] [at X Y Z] [up X Y Z] [fov D] [aperture A] [focus D]
 * [shutter OPEN CLOSE]; what it leaves out keeps its value; the frame is checked once
 * the whole scene is read (core/scene_validate.c). */
bool statement_camera(scene_parser *p, source_line *line, const token *keyword)
{
    static const char *const clauses[] = {"from", "at", "up", "fov", "aperture", "focus", "shutter"};
    scene_camera camera = builder_scene(&p->builder)->camera;
    if (!read_clauses(p, line, "camera", clauses, 7, read_camera_clause, &camera))
        return false;
    builder_set_camera(&p->builder, &camera, token_position(line, keyword));
    return true;
}

/* Reads the value of render clause (an index into statement_render's clauses) into the
 * scene_render_settings target. */
static bool read_render_clause(scene_parser *p, source_line *line, int clause, void *target)
{
    scene_render_settings *render = target;
    scene_variables *variables = &p->variables;
    long long width, height, value;
    switch (clause) {
    case 0:
        if (!read_integer(variables, line, "the render width", 1, SCENE_MAX_IMAGE_SIDE, &width) ||
            !read_integer(variables, line, "the render height", 1, SCENE_MAX_IMAGE_SIDE, &height))
            return false;
        render->width = (int)width;
        render->height = (int)height;
        return true;
    case 1:
        if (!read_integer(variables, line, "the samples per pixel (spp)", 1, 1073741824, &value))
            return false;
        render->samples_per_pixel = (int)value;
        return true;
    case 2:
        if (!read_integer(variables, line, "the render depth", 1, 100000, &value))
            return false;
        render->max_depth = (int)value;
        return true;
    default:
        if (!read_integer(variables, line, "the render seed", 0, 4294967295LL, &value))
            return false;
        render->seed = (uint32_t)value;
        return true;
    }
}

/* render [size W H] [spp N] [depth N] [seed N]. */
bool statement_render(scene_parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    static const char *const clauses[] = {"size", "spp", "depth", "seed"};
    scene_render_settings render = builder_scene(&p->builder)->render;
    if (!read_clauses(p, line, "render", clauses, 4, read_render_clause, &render))
        return false;
    builder_set_render(&p->builder, &render);
    return true;
}

/* Reads the sky type word and what it takes (colours or images) into *sky; *has_image
 * tells whether it takes the rotate clause. */
static bool read_sky_type(scene_parser *p, source_line *line, scene_sky *sky, bool *has_image)
{
    static const char *const face_names[SKY_FACE_COUNT] = {
        "the sky box's +X face", "the sky box's -X face", "the sky box's +Y face",
        "the sky box's -Y face", "the sky box's +Z face", "the sky box's -Z face",
    };
    token type = {.kind = TOKEN_END};
    if (!next_token(line, &type))
        return false;
    *has_image = false;
    if (token_is(line, &type, "gradient")) {
        sky->type = SKY_GRADIENT;
        return read_colour(&p->variables, line, "the sky's bottom colour", sky->bottom) &&
               read_colour(&p->variables, line, "the sky's top colour", sky->top);
    }
    if (token_is(line, &type, "constant")) {
        sky->type = SKY_CONSTANT;
        if (!read_colour(&p->variables, line, "the sky colour", sky->bottom))
            return false;
        memcpy(sky->top, sky->bottom, sizeof sky->top);
        return true;
    }
    if (token_is(line, &type, "box")) {
        sky->type = SKY_BOX;
        *has_image = true;
        for (int face = 0; face < SKY_FACE_COUNT; face++)
            if (!read_image(p, line, face_names[face], &sky->faces[face]))
                return false;
        return true;
    }
    if (token_is(line, &type, "environment")) {
        sky->type = SKY_ENVIRONMENT;
        *has_image = true;
        return read_image(p, line, "the sky environment", &sky->environment);
    }
    char found[FOUND_BUFFER];
    return fail_at(line, type.offset, "expected a sky type (gradient, constant, box or environment), found %s",
                   describe_token(line, &type, found, sizeof found));
}

/* Reads the value of sky clause (intensity, group or rotate) into the scene_sky target. */
static bool read_sky_clause(scene_parser *p, source_line *line, int clause, void *target)
{
    scene_sky *sky = target;
    if (clause == 0)
        return read_non_negative_float(&p->variables, line, "the sky's intensity", &sky->intensity);
    if (clause == 1)
        return read_light_group(p, line, "the sky", &sky->light_group);
    double value = 0;
    size_t offset = 0;
    return read_number(&p->variables, line, "the sky's rotation in degrees", &value, &offset) &&
           to_float(line, offset, "the sky's rotation", value, &sky->rotation_degrees);
}

/* sky gradient R G B  R G B | constant R G B | box "+X" "-X" "+Y" "-Y" "+Z" "-Z" |
 * environment "FILE", then [intensity I] [group NAME] (and [rotate DEGREES] for box and
 * environment).
 * The last sky statement wins, wholly: what it leaves out is back at the default. */
bool statement_sky(scene_parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    scene defaults;
    scene_defaults(&defaults);
    scene_sky sky = defaults.sky;
    bool has_image = false;
    if (!read_sky_type(p, line, &sky, &has_image))
        return false;
    static const char *const clauses[] = {"intensity", "group", "rotate"};
    if (!read_clauses(p, line, "sky", clauses, has_image ? 3 : 2, read_sky_clause, &sky))
        return false;
    builder_set_sky(&p->builder, &sky);
    return true;
}

/* ambient R G B: the Whitted integrator's ambient term (each >= 0); the last one wins. */
bool statement_ambient(scene_parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    float ambient[3];
    if (!read_colour(&p->variables, line, "the ambient colour", ambient) ||
        !expect_end_of_line(line, "the ambient colour"))
        return false;
    builder_set_ambient(&p->builder, ambient);
    return true;
}
