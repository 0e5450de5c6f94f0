/* scene_parse.c: see scene_parse.h; the format is documented in docs/scene-format.md.
 *
 * The whole file is read into memory and cut into lines; each line is one statement,
 * lexed on demand (so that `set` can take the raw rest of its line as an expression).
 * Every failure formats its message once, at the place that finds it, and then every
 * caller just returns false up to scene_load_*, which frees everything.
 *
 * Blocks (group, instance, volume) live on a stack whose bottom entry is the top level.
 * Each block keeps its own transform (composed in double from its transform statements)
 * and buffers its direct shapes, which become one contiguous object when it closes. A
 * placement of an object walks up the stack once: every block's transform applies in
 * turn, the innermost explicit material and the nearest volume fill in what is still
 * open, every open named group records the placement relative to its parent's frame (so
 * `instance NAME` can replay it), and the result becomes one scene instance. */
#include "scene_parse.h"

#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "expression.h"

#define DEFAULT_MAX_INCLUDE_DEPTH 16

/* The largest scene file read: far more than any real scene, and a clean error (EFBIG)
 * for a mistake such as include "/dev/zero", which would otherwise be read until memory
 * runs out. */
#define MAX_SCENE_FILE_BYTES ((size_t)256 << 20)

/* How much of a bad token a message quotes; enough to recognise it, not a whole line. */
#define QUOTE_LIMIT 40
#define QUOTE_BUFFER (QUOTE_LIMIT + 8)
#define DESCRIPTION_BUFFER 160
#define OWNER_BUFFER 96

/* Blocks nest at most this deep (the top level does not count). */
#define MAX_BLOCK_DEPTH 64
/* Instances plus the placements named groups remember, together: flattening instances of
 * instances multiplies, and a short hostile file must not exhaust memory. */
#define MAX_PLACEMENTS (1 << 22)
/* scene_image.path and scene_mesh.path hold at most this many bytes plus the NUL. */
#define MAX_ASSET_PATH 1023

typedef struct source_file {
    const char *path;                /* as shown in messages; owned by parser.paths */
    const char *text;
    size_t length;
    bool has_identity;               /* false for the text of scene_load_string */
    dev_t device;
    ino_t inode;
    int depth;                       /* 0 for the top file */
    const struct source_file *includer;
} source_file;

typedef struct source_line {
    const source_file *file;
    const char *text;
    size_t length;                   /* without the '\n' */
    int number;
    size_t cursor;                   /* next byte the lexer looks at */
    size_t last_token_end;           /* where a missing token ("end of line") is reported */
} source_line;

typedef enum token_kind {
    TOKEN_END,
    TOKEN_WORD,
    TOKEN_STRING,
    TOKEN_OPEN_BRACE,                /* only where a block may open or close */
    TOKEN_CLOSE_BRACE,
} token_kind;

typedef struct token {
    token_kind kind;
    size_t offset;                   /* in the line; for TOKEN_END just after the last token */
    size_t length;                   /* for TOKEN_STRING including both quotes */
} token;

typedef struct source_position {
    const char *path;                /* owned by parser.paths */
    int line;
    size_t column;
} source_position;

typedef struct variable {
    char *name;
    double value;
    bool has_value;
    bool from_define;                /* a -D define: the file's `set` of it is skipped */
    bool mentioned;                  /* set or used by the scene, for the unused -D check */
} variable;

/* An affine map in double: p' = m[:, 0..2] p + m[:, 3], rows x, y, z. */
typedef struct affine {
    double m[3][4];
} affine;

/* One placement of an object, relative to some frame, with what is still open: material
 * -1 is filled by an enclosing material, volume false by an enclosing volume. */
typedef struct placement {
    int object;
    affine transform;
    int material;
    bool volume;
    float density;
    float volume_albedo[3];
} placement;

typedef enum block_kind {
    BLOCK_TOP_LEVEL,
    BLOCK_GROUP,
    BLOCK_INSTANCE,
    BLOCK_VOLUME,
} block_kind;

/* A shape of a block, kept until the block closes so that its object's shapes are
 * contiguous in the scene even when nested blocks add theirs in between. */
typedef struct pending_shape {
    scene_shape shape;
    source_position position;        /* of its statement */
} pending_shape;

/* One open block, or the top level (blocks[0]). */
typedef struct block {
    block_kind kind;
    source_position opened;          /* the keyword of its opening line */
    const source_file *file;         /* the file that must close it; NULL for the top level */
    affine transform;                /* its own transform statements, composed */
    bool content_seen;               /* anything but a transform or include came */
    int material;                    /* its explicit `material`, or -1 */
    float density, albedo[3];        /* volume */
    int group;                       /* named group: index into parser.groups, else -1 */
    int instance_of;                 /* instance block: the group it places, else -1 */
    int object;                      /* object of its direct shapes, -1 until the first */
    pending_shape *shapes;           /* its direct shapes, added to the scene when it closes */
    int shape_count, shape_capacity;
} block;

/* A named group: what it placed, relative to its parent's frame, for `instance NAME`. */
typedef struct named_group {
    char name[SCENE_NAME_MAX];
    source_position position;
    bool open;                       /* an instance of an open group would be recursion */
    placement *placements;
    int placement_count, placement_capacity;
} named_group;

typedef struct parser {
    scene *scene;
    const scene_parse_options *options;
    rt_error *error;
    rt_status status;                /* of the first failure */
    int max_include_depth;
    variable *variables;
    int variable_count, variable_capacity;
    char **paths;                    /* every path shown in a message, freed at the end */
    int path_count, path_capacity;
    source_position *material_positions;   /* parallel to scene->materials */
    int material_position_capacity;
    bool camera_seen;
    source_position last_camera;
    source_position *texture_positions;    /* parallel to scene->textures */
    int texture_position_capacity;
    source_position *shape_positions;      /* parallel to scene->shapes */
    int shape_position_capacity;
    int *mesh_objects;                     /* parallel to scene->meshes: each mesh's object */
    int mesh_object_capacity;
    named_group *groups;
    int group_count, group_capacity;
    int placement_total;                   /* instances and group records, for MAX_PLACEMENTS */
    /* blocks[0] is the top level; one spare entry above MAX_BLOCK_DEPTH holds the implicit
     * block of an `instance` without braces. */
    block blocks[MAX_BLOCK_DEPTH + 2];
    int block_count;
} parser;

/* ------------------------------------------------------------------ errors */

/* Writes "PATH:LINE:COLUMN: message" into the caller's error (when there is one) and
 * records the failure; returns false. */
static bool fail_va(parser *p, const char *path, int line, size_t column, const char *format,
                    va_list arguments)
{
    p->status = RT_ERROR_INPUT;
    if (p->error == NULL)
        return false;
    char *message = p->error->message;
    size_t size = sizeof p->error->message;
    int prefix = snprintf(message, size, "%s:%d:%zu: ", path, line, column);
    if (prefix >= 0 && (size_t)prefix < size)
        vsnprintf(message + prefix, size - (size_t)prefix, format, arguments);
    return false;
}

/* Reports an input error at byte offset of line; returns false for `return fail_at(...)`. */
__attribute__((format(printf, 4, 5)))
static bool fail_at(parser *p, const source_line *line, size_t offset, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    fail_va(p, line->file->path, line->number, offset + 1, format, arguments);
    va_end(arguments);
    return false;
}

/* The same at a remembered position (a statement of an earlier line or file). */
__attribute__((format(printf, 3, 4)))
static bool fail_at_position(parser *p, const source_position *position, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    fail_va(p, position->path, position->line, position->column, format, arguments);
    va_end(arguments);
    return false;
}

/* Reports an error that has no position in a file (a -D define, an unreadable top file). */
__attribute__((format(printf, 2, 3)))
static bool fail_without_position(parser *p, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    rt_error_set_va(p->error, RT_ERROR_INPUT, format, arguments);
    va_end(arguments);
    p->status = RT_ERROR_INPUT;
    return false;
}

/* Records an allocation failure, the one error that is not the user's input. */
static bool fail_out_of_memory(parser *p)
{
    p->status = rt_error_set(p->error, RT_ERROR_RUNTIME, "SCENE: out of memory while reading the scene");
    return false;
}

/* Returns how many bytes of a token a message shows: all of it, or QUOTE_LIMIT bytes cut
 * before a UTF-8 continuation byte so that the message stays valid UTF-8. */
static int quoted_length(const char *text, size_t length)
{
    if (length <= QUOTE_LIMIT)
        return (int)length;
    size_t shown = QUOTE_LIMIT;
    while (shown > 0 && ((unsigned char)text[shown] & 0xC0) == 0x80)
        shown--;
    return (int)shown;
}

/* Writes 'text' (cut to QUOTE_LIMIT bytes with "...") into buffer and returns buffer. */
static const char *quote(char *buffer, size_t size, const char *text, size_t length)
{
    snprintf(buffer, size, "'%.*s%s'", quoted_length(text, length), text, length > QUOTE_LIMIT ? "..." : "");
    return buffer;
}

/* Describes a token for "found ..." in messages: 'word', "string" or end of line. */
static const char *describe_token(const source_line *line, const token *t, char *buffer, size_t size)
{
    if (t->kind == TOKEN_END)
        return "end of line";
    if (t->kind == TOKEN_OPEN_BRACE)
        return "'{'";
    if (t->kind == TOKEN_CLOSE_BRACE)
        return "'}'";
    if (t->kind == TOKEN_STRING) {
        snprintf(buffer, size, "the string %.*s%s", quoted_length(line->text + t->offset, t->length),
                 line->text + t->offset, t->length > QUOTE_LIMIT ? "...\"" : "");
        return buffer;
    }
    return quote(buffer, size, line->text + t->offset, t->length);
}

/* Formats value for a message: 15 significant digits show 0.1 as 0.1 and 1/3 as
 * 0.333333333333333, and every whole number of the integer ranges exactly. */
static const char *format_number(char *buffer, size_t size, double value)
{
    snprintf(buffer, size, "%.15g", value);
    return buffer;
}

/* ------------------------------------------------------------------ bookkeeping */

/* Takes ownership of path (malloc'd) so it can be shown in messages until the end. */
static const char *keep_path(parser *p, char *path)
{
    if (path == NULL)
        return NULL;
    if (p->path_count == p->path_capacity) {
        int capacity = p->path_capacity ? p->path_capacity * 2 : 8;
        char **grown = realloc(p->paths, (size_t)capacity * sizeof *grown);
        if (grown == NULL) {
            free(path);
            return NULL;
        }
        p->paths = grown;
        p->path_capacity = capacity;
    }
    p->paths[p->path_count++] = path;
    return path;
}

/* Returns a malloc'd, NUL-terminated copy of length bytes (the caller frees it), or NULL. */
static char *copy_text(const char *text, size_t length)
{
    char *copy = malloc(length + 1);
    if (copy != NULL) {
        memcpy(copy, text, length);
        copy[length] = '\0';
    }
    return copy;
}

/* Returns the variable called name (length bytes), or NULL. Linear: scenes have few. */
static variable *find_variable(parser *p, const char *name, size_t length)
{
    for (int i = 0; i < p->variable_count; i++)
        if (strlen(p->variables[i].name) == length && memcmp(p->variables[i].name, name, length) == 0)
            return &p->variables[i];
    return NULL;
}

/* Returns the variable called name, adding an unset one if there is none; NULL when
 * memory runs out (the error is then reported). */
static variable *find_or_add_variable(parser *p, const char *name, size_t length)
{
    variable *found = find_variable(p, name, length);
    if (found != NULL)
        return found;
    if (p->variable_count == p->variable_capacity) {
        int capacity = p->variable_capacity ? p->variable_capacity * 2 : 16;
        variable *grown = realloc(p->variables, (size_t)capacity * sizeof *grown);
        if (grown == NULL) {
            fail_out_of_memory(p);
            return NULL;
        }
        p->variables = grown;
        p->variable_capacity = capacity;
    }
    char *copy = copy_text(name, length);
    if (copy == NULL) {
        fail_out_of_memory(p);
        return NULL;
    }
    variable *added = &p->variables[p->variable_count++];
    *added = (variable){.name = copy};
    return added;
}

/* The expression module's view of the variables: only those with a value exist, and
 * every use is remembered for the unused -D check. */
static bool lookup_variable(void *context, const char *name, size_t length, double *value)
{
    variable *found = find_variable(context, name, length);
    if (found == NULL || !found->has_value)
        return false;
    found->mentioned = true;
    *value = found->value;
    return true;
}

/* Makes room for element count of *array (element_size bytes each, *capacity of them);
 * reports running out of memory and returns false when it cannot. */
static bool grow_array(parser *p, void **array, int count, int *capacity, size_t element_size)
{
    if (count < *capacity)
        return true;
    if (*capacity > INT_MAX / 2)
        return fail_out_of_memory(p);
    int new_capacity = *capacity ? *capacity * 2 : 16;
    void *grown = realloc(*array, (size_t)new_capacity * element_size);
    if (grown == NULL)
        return fail_out_of_memory(p);
    *array = grown;
    *capacity = new_capacity;
    return true;
}

/* Stores position at index of a parallel position array (index is at most one past the
 * last element stored). */
static bool remember_position(parser *p, source_position **positions, int *capacity, int index,
                              source_position position)
{
    if (!grow_array(p, (void **)positions, index, capacity, sizeof **positions))
        return false;
    (*positions)[index] = position;
    return true;
}

/* Returns the position of byte offset of line, for messages about it later. */
static source_position position_in(const source_line *line, size_t offset)
{
    return (source_position){.path = line->file->path, .line = line->number, .column = offset + 1};
}

/* Frees what the parser owns (variables, paths, positions, blocks, groups); never the scene. */
static void parser_free(parser *p)
{
    for (int i = 0; i < p->variable_count; i++)
        free(p->variables[i].name);
    free(p->variables);
    for (int i = 0; i < p->path_count; i++)
        free(p->paths[i]);
    free(p->paths);
    free(p->material_positions);
    free(p->texture_positions);
    free(p->shape_positions);
    free(p->mesh_objects);
    for (int i = 0; i < p->group_count; i++)
        free(p->groups[i].placements);
    free(p->groups);
    for (int i = 0; i < p->block_count; i++)
        free(p->blocks[i].shapes);
}

/* ------------------------------------------------------------------ reading files */

/* Reads the whole file at path into a malloc'd, NUL-terminated buffer (the caller frees
 * *text) and fills *info. Returns 0, or the errno that explains the failure (a directory
 * is EISDIR, so that every "cannot read" message reads the same way). */
static int read_whole_file(const char *path, char **text, size_t *length, struct stat *info)
{
    int descriptor = open(path, O_RDONLY | O_CLOEXEC);
    if (descriptor < 0)
        return errno;
    if (fstat(descriptor, info) != 0) {
        int saved = errno;
        close(descriptor);
        return saved;
    }
    if (S_ISDIR(info->st_mode)) {
        close(descriptor);
        return EISDIR;
    }
    if (S_ISREG(info->st_mode) && (uintmax_t)info->st_size > MAX_SCENE_FILE_BYTES) {
        close(descriptor);
        return EFBIG;
    }
    /* st_size is only a hint: pipes report 0 and files may grow while being read. */
    size_t capacity = S_ISREG(info->st_mode) && info->st_size > 0 ? (size_t)info->st_size + 1 : 4096;
    size_t used = 0;
    char *buffer = malloc(capacity);
    if (buffer == NULL) {
        close(descriptor);
        return ENOMEM;
    }
    for (;;) {
        if (used + 1 >= capacity) {
            char *grown = capacity > SIZE_MAX / 2 ? NULL : realloc(buffer, capacity * 2);
            if (grown == NULL) {
                free(buffer);
                close(descriptor);
                return ENOMEM;
            }
            buffer = grown;
            capacity *= 2;
        }
        ssize_t got = read(descriptor, buffer + used, capacity - used - 1);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            int saved = errno;
            free(buffer);
            close(descriptor);
            return saved;
        }
        if (got == 0)
            break;
        used += (size_t)got;
        if (used > MAX_SCENE_FILE_BYTES) {
            free(buffer);
            close(descriptor);
            return EFBIG;
        }
    }
    close(descriptor);
    buffer[used] = '\0';
    *text = buffer;
    *length = used;
    return 0;
}

/* Returns the path of an include as "directory of includer" + include text (absolute
 * include paths are kept), malloc'd; NULL when memory runs out. */
static char *resolve_include_path(const char *includer_path, const char *text, size_t length)
{
    size_t directory_length = 0;
    if (length == 0 || text[0] != '/') {
        const char *slash = strrchr(includer_path, '/');
        if (slash != NULL)
            directory_length = (size_t)(slash - includer_path) + 1;
    }
    char *resolved = malloc(directory_length + length + 1);
    if (resolved == NULL)
        return NULL;
    memcpy(resolved, includer_path, directory_length);
    memcpy(resolved + directory_length, text, length);
    resolved[directory_length + length] = '\0';
    return resolved;
}

/* ------------------------------------------------------------------ lexing */

/* Checks that a line holds only text: no control bytes other than tab and carriage
 * return, and well-formed UTF-8 (so binary files fail at their first odd byte rather
 * than with a confusing message about a token). */
static bool check_line_bytes(parser *p, const source_line *line)
{
    const unsigned char *bytes = (const unsigned char *)line->text;
    size_t i = 0;
    while (i < line->length) {
        unsigned char c = bytes[i];
        if (c < 0x80) {
            if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f)
                return fail_at(p, line, i, "unexpected byte 0x%02X (a control character; scene files are text)", c);
            i++;
            continue;
        }
        /* Lead byte ranges and the allowed range of the first continuation byte reject
         * overlong forms, surrogates and code points above U+10FFFF. */
        size_t continuation_count = 0;
        unsigned char low = 0x80, high = 0xBF;
        if (c >= 0xC2 && c <= 0xDF)
            continuation_count = 1;
        else if (c == 0xE0)
            continuation_count = 2, low = 0xA0;
        else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF)
            continuation_count = 2;
        else if (c == 0xED)
            continuation_count = 2, high = 0x9F;
        else if (c == 0xF0)
            continuation_count = 3, low = 0x90;
        else if (c >= 0xF1 && c <= 0xF3)
            continuation_count = 3;
        else if (c == 0xF4)
            continuation_count = 3, high = 0x8F;
        bool valid = continuation_count > 0 && continuation_count < line->length - i;
        for (size_t k = 1; valid && k <= continuation_count; k++) {
            unsigned char next = bytes[i + k];
            valid = next >= (k == 1 ? low : 0x80) && next <= (k == 1 ? high : 0xBF);
        }
        if (!valid)
            return fail_at(p, line, i, "unexpected byte 0x%02X (not valid UTF-8; scene files are text)", c);
        i += continuation_count + 1;
    }
    return true;
}

/* Spaces and tabs separate tokens; a carriage return too, so CRLF files read as LF. */
static bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

/* A word ends at a space, a comment, a string or a reserved brace. */
static bool ends_word(char c)
{
    return is_space(c) || c == '#' || c == '"' || c == '{' || c == '}';
}

/* Reads the next token of line into *t. A word that starts with '(' runs to its matching
 * ')' across spaces (so `(4 * cos($t))` is one number); an unbalanced one runs to the end
 * of the line and the expression evaluator reports it. A brace is a token of its own when
 * braces_allowed (where a block may open or close), an error elsewhere. Returns false on
 * a lexical error. At the end of the line (or a comment) it keeps returning TOKEN_END. */
static bool lex_token(parser *p, source_line *line, token *t, bool braces_allowed)
{
    while (line->cursor < line->length && is_space(line->text[line->cursor]))
        line->cursor++;
    if (line->cursor == line->length || line->text[line->cursor] == '#') {
        *t = (token){.kind = TOKEN_END, .offset = line->last_token_end};
        return true;
    }
    size_t start = line->cursor;
    char c = line->text[start];
    if ((c == '{' || c == '}') && braces_allowed) {
        *t = (token){.kind = c == '{' ? TOKEN_OPEN_BRACE : TOKEN_CLOSE_BRACE, .offset = start, .length = 1};
        line->cursor = line->last_token_end = start + 1;
        return true;
    }
    if (c == '{')
        return fail_at(p, line, start, "unexpected '{' (only a group, instance or volume line ends with '{')");
    if (c == '}')
        return fail_at(p, line, start, "unexpected '}' (a '}' closes a block on a line of its own)");
    if (c == '"') {
        const char *closing = memchr(line->text + start + 1, '"', line->length - start - 1);
        if (closing == NULL)
            return fail_at(p, line, start, "unterminated string (expected a closing '\"' on the same line)");
        size_t end = (size_t)(closing - line->text) + 1;
        *t = (token){.kind = TOKEN_STRING, .offset = start, .length = end - start};
        line->cursor = line->last_token_end = end;
        return true;
    }
    size_t end = start;
    if (c == '(') {
        size_t depth = 0;
        while (end < line->length && line->text[end] != '#') {
            char inside = line->text[end++];
            if (inside == '(')
                depth++;
            else if (inside == ')' && --depth == 0)
                break;
        }
        /* An unclosed group swallowed the trailing spaces before a comment or the end. */
        while (end > start + 1 && is_space(line->text[end - 1]))
            end--;
    }
    while (end < line->length && !ends_word(line->text[end]))
        end++;
    *t = (token){.kind = TOKEN_WORD, .offset = start, .length = end - start};
    line->cursor = line->last_token_end = end;
    return true;
}

/* Reads the next token where a brace is an error (almost everywhere); see lex_token. */
static bool next_token(parser *p, source_line *line, token *t)
{
    return lex_token(p, line, t, false);
}

/* True when t is the bare word `word` (keywords are case-sensitive). */
static bool token_is(const source_line *line, const token *t, const char *word)
{
    size_t length = strlen(word);
    return t->kind == TOKEN_WORD && t->length == length && memcmp(line->text + t->offset, word, length) == 0;
}

/* Fails unless the rest of the line is empty; after names the statement for the message. */
static bool expect_end_of_line(parser *p, source_line *line, const char *after)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(p, line, &t))
        return false;
    if (t.kind == TOKEN_END)
        return true;
    char found[QUOTE_BUFFER + 16];
    return fail_at(p, line, t.offset, "unexpected %s after %s (expected end of line)",
                   describe_token(line, &t, found, sizeof found), after);
}

/* ------------------------------------------------------------------ numbers */

/* Runs the expression evaluator over length bytes of line at offset; on failure writes
 * the file:line:column prefix in front of its message. */
static bool evaluate(parser *p, const source_line *line, size_t offset, size_t length, double *value)
{
    rt_error expression_error;
    int column = 0;
    if (expression_evaluate(line->text + offset, length, (int)(offset > INT_MAX - 1 ? INT_MAX - 1 : offset + 1),
                            lookup_variable, p, value, &column, &expression_error) == RT_OK)
        return true;
    source_position position = {.path = line->file->path, .line = line->number, .column = (size_t)column};
    return fail_at_position(p, &position, "%s", expression_error.message);
}

/* True for [+-] digits [. digits] [e [+-] digits] or [+-] . digits [e ...]: the only
 * bare numbers a statement takes (everything else must be $name or (expression)). */
static bool is_number_literal(const char *text, size_t length)
{
    size_t i = 0, digits = 0;
    if (i < length && (text[i] == '+' || text[i] == '-'))
        i++;
    while (i < length && text[i] >= '0' && text[i] <= '9')
        i++, digits++;
    if (i < length && text[i] == '.') {
        i++;
        while (i < length && text[i] >= '0' && text[i] <= '9')
            i++, digits++;
    }
    if (digits == 0)
        return false;
    if (i < length && (text[i] == 'e' || text[i] == 'E')) {
        i++;
        if (i < length && (text[i] == '+' || text[i] == '-'))
            i++;
        size_t exponent_digits = 0;
        while (i < length && text[i] >= '0' && text[i] <= '9')
            i++, exponent_digits++;
        if (exponent_digits == 0)
            return false;
    }
    return i == length;
}

/* True when text (after an optional sign) spells nan, inf or infinity, in any case. */
static bool spells_non_finite(const char *text, size_t length)
{
    if (length > 0 && (text[0] == '+' || text[0] == '-'))
        text++, length--;
    static const char *const spellings[] = {"nan", "inf", "infinity"};
    for (int i = 0; i < 3; i++)
        if (strlen(spellings[i]) == length && strncasecmp(text, spellings[i], length) == 0)
            return true;
    return false;
}

/* Returns the offset just after the ')' that closes text[0]'s '(', or length + 1 when
 * it never closes. */
static size_t group_end(const char *text, size_t length)
{
    size_t depth = 0;
    for (size_t i = 0; i < length; i++) {
        if (text[i] == '(')
            depth++;
        else if (text[i] == ')' && --depth == 0)
            return i + 1;
    }
    return length + 1;
}

/* Evaluates token t as a number for what (e.g. "the sphere's radius"): a literal, a
 * $variable or a parenthesised expression. The result is always finite. */
static bool number_from_token(parser *p, const source_line *line, const token *t, const char *what, double *value)
{
    char found[QUOTE_BUFFER + 16];
    if (t->kind != TOKEN_WORD)
        return fail_at(p, line, t->offset, "expected a number for %s, found %s", what,
                       describe_token(line, t, found, sizeof found));
    const char *text = line->text + t->offset;
    size_t length = t->length;
    if (text[0] == '(') {
        if (!evaluate(p, line, t->offset, length, value))
            return false;
        if (group_end(text, length) != length)
            return fail_at(p, line, t->offset, "expected a number for %s, found %s (an expression must be "
                           "entirely inside one pair of parentheses)", what,
                           describe_token(line, t, found, sizeof found));
        return true;
    }
    if (text[0] == '$') {
        if (!expression_is_variable_name(text + 1, length - 1))
            return fail_at(p, line, t->offset, "expected a number for %s, found %s (a variable is $name; "
                           "write an expression in parentheses, e.g. ($a+1))", what,
                           describe_token(line, t, found, sizeof found));
        return evaluate(p, line, t->offset, length, value);
    }
    if (is_number_literal(text, length)) {
        char *copy = copy_text(text, length);
        if (copy == NULL)
            return fail_out_of_memory(p);
        *value = strtod(copy, NULL);
        free(copy);
        if (!isfinite(*value))
            return fail_at(p, line, t->offset, "expected a finite number for %s, found %s (out of range)", what,
                           describe_token(line, t, found, sizeof found));
        return true;
    }
    if (spells_non_finite(text, length))
        return fail_at(p, line, t->offset, "expected a number for %s, found %s (NaN and infinity are not allowed)",
                       what, describe_token(line, t, found, sizeof found));
    /* An operator past a leading sign, or a '(' inside, means an unparenthesised expression. */
    bool looks_like_expression = memchr(text, '(', length) != NULL;
    for (size_t i = 1; i < length; i++)
        if (strchr("+-*/^", text[i]) != NULL)
            looks_like_expression = true;
    if (looks_like_expression)
        return fail_at(p, line, t->offset, "expected a number for %s, found %s (write an expression in "
                       "parentheses, e.g. (2*3))", what, describe_token(line, t, found, sizeof found));
    return fail_at(p, line, t->offset, "expected a number for %s, found %s", what,
                   describe_token(line, t, found, sizeof found));
}

/* Reads the next token as a number for what; *offset (when not NULL) gets the token's
 * offset for range errors. */
static bool read_number(parser *p, source_line *line, const char *what, double *value, size_t *offset)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(p, line, &t))
        return false;
    if (t.kind == TOKEN_END)
        return fail_at(p, line, t.offset, "expected a number for %s, found end of line", what);
    if (offset != NULL)
        *offset = t.offset;
    return number_from_token(p, line, &t, what, value);
}

/* The renderer works in 32-bit floats: a value that is finite in double may not be. */
static bool to_float(parser *p, const source_line *line, size_t offset, const char *what, double value, float *out)
{
    if (fabs(value) > FLT_MAX) {
        char number[40];
        return fail_at(p, line, offset, "%s is %s, too large for the renderer's 32-bit floats", what,
                       format_number(number, sizeof number, value));
    }
    *out = (float)value;
    return true;
}

/* Reads the next token as a number that must fit a float; *offset as read_number. */
static bool read_float(parser *p, source_line *line, const char *what, float *out, size_t *offset)
{
    double value = 0;
    size_t where = 0;
    if (!read_number(p, line, what, &value, &where) || !to_float(p, line, where, what, value, out))
        return false;
    if (offset != NULL)
        *offset = where;
    return true;
}

/* Reads a whole number in [minimum, maximum]. */
static bool read_integer(parser *p, source_line *line, const char *what, long long minimum, long long maximum,
                         long long *out)
{
    double value = 0;
    size_t offset = 0;
    if (!read_number(p, line, what, &value, &offset))
        return false;
    if (value != floor(value) || value < (double)minimum || value > (double)maximum) {
        char number[40];
        return fail_at(p, line, offset, "%s must be a whole number from %lld to %lld, found %s", what, minimum,
                       maximum, format_number(number, sizeof number, value));
    }
    *out = (long long)value;
    return true;
}

/* Reads three numbers x y z for owner (e.g. "the camera's from"); offsets (when not NULL)
 * get each token's offset. */
static bool read_vector(parser *p, source_line *line, const char *owner, float out[3], size_t offsets[3])
{
    static const char *const axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "%s %s", owner, axes[i]);
        if (!read_float(p, line, what, &out[i], offsets != NULL ? &offsets[i] : NULL))
            return false;
    }
    return true;
}

/* The same in double, for transforms (composed in double); each value must still fit a
 * float, as everything the renderer gets does. */
static bool read_point(parser *p, source_line *line, const char *owner, double out[3], size_t offsets[3])
{
    static const char *const axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "%s %s", owner, axes[i]);
        size_t offset = 0;
        float unused;
        if (!read_number(p, line, what, &out[i], &offset) || !to_float(p, line, offset, what, out[i], &unused))
            return false;
        if (offsets != NULL)
            offsets[i] = offset;
    }
    return true;
}

/* Reads the next token without consuming it (a lexical error is still reported). */
static bool peek_token(parser *p, source_line *line, token *t)
{
    size_t cursor = line->cursor, last_token_end = line->last_token_end;
    bool ok = next_token(p, line, t);
    line->cursor = cursor;
    line->last_token_end = last_token_end;
    return ok;
}

/* Reads three colour components for owner (e.g. "material 'red'"); each must be >= 0. */
static bool read_colour(parser *p, source_line *line, const char *owner, float out[3])
{
    static const char *const channels[3] = {"red", "green", "blue"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s component of %s", channels[i], owner);
        size_t offset = 0;
        double value = 0;
        if (!read_number(p, line, what, &value, &offset))
            return false;
        if (value < 0) {
            char number[40];
            return fail_at(p, line, offset, "%s must be >= 0, found %s", what,
                           format_number(number, sizeof number, value));
        }
        if (!to_float(p, line, offset, what, value, &out[i]))
            return false;
    }
    return true;
}

/* ------------------------------------------------------------------ clauses */

/* Matches t against the clause names of a statement; returns the index or -1. A clause
 * seen twice in one statement is an error (the second probably meant another clause). */
static bool match_clause(parser *p, const source_line *line, const token *t, const char *statement,
                         const char *const *names, int count, size_t *first_offsets, int *index)
{
    char found[QUOTE_BUFFER + 16];
    for (int i = 0; i < count; i++) {
        if (!token_is(line, t, names[i]))
            continue;
        if (first_offsets[i] != SIZE_MAX)
            return fail_at(p, line, t->offset, "%s clause '%s' given twice in one statement (first at column %zu)",
                           statement, names[i], first_offsets[i] + 1);
        first_offsets[i] = t->offset;
        *index = i;
        return true;
    }
    char expected[DESCRIPTION_BUFFER] = "";
    for (int i = 0; i < count; i++) {
        size_t used = strlen(expected);
        snprintf(expected + used, sizeof expected - used, "%s%s", i == 0 ? "" : i == count - 1 ? " or " : ", ",
                 names[i]);
    }
    return fail_at(p, line, t->offset, "unknown %s clause %s (expected %s)", statement,
                   describe_token(line, t, found, sizeof found), expected);
}

/* ------------------------------------------------------------------ names and references */

/* Names (of materials, textures and groups) are plain words so that a statement stays
 * easy to read and a name can never be mistaken for a number, a $variable, an expression
 * or a @texture reference. */
static bool is_name(const char *text, size_t length)
{
    for (size_t i = 0; i < length; i++) {
        char c = text[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
              c == '.'))
            return false;
    }
    return length > 0;
}

/* Checks that token t is a valid name for a kind ("material", "texture", "group") being
 * defined and copies it into name. */
static bool name_from_token(parser *p, const source_line *line, const token *t, const char *kind,
                            char name[SCENE_NAME_MAX])
{
    char found[QUOTE_BUFFER + 16];
    const char *text = line->text + t->offset;
    if (t->kind != TOKEN_WORD || !is_name(text, t->length))
        return fail_at(p, line, t->offset, "expected a %s name (letters, digits, '_', '-' and '.'), found %s", kind,
                       describe_token(line, t, found, sizeof found));
    if (t->length > SCENE_NAME_MAX - 1)
        return fail_at(p, line, t->offset, "%s name %s is %zu bytes long; the limit is %d", kind,
                       describe_token(line, t, found, sizeof found), t->length, SCENE_NAME_MAX - 1);
    memcpy(name, text, t->length);
    name[t->length] = '\0';
    return true;
}

/* Reads the name after `material NAME` or `texture NAME` (*t gets its token). */
static bool read_definition_name(parser *p, source_line *line, const char *kind, token *t,
                                 char name[SCENE_NAME_MAX])
{
    if (!next_token(p, line, t))
        return false;
    if (t->kind == TOKEN_END)
        return fail_at(p, line, t->offset, "expected a %s name after %s, found end of line", kind, kind);
    return name_from_token(p, line, t, kind, name);
}

/* Looks up the material named by token t for owner (e.g. "the sphere"); users names the
 * statements that use materials in the hint (e.g. "spheres"). */
static bool material_from_token(parser *p, const source_line *line, const token *t, const char *owner,
                                const char *users, int *material)
{
    char found[QUOTE_BUFFER + 16];
    if (t->kind != TOKEN_WORD)
        return fail_at(p, line, t->offset, "expected a material name for %s, found %s", owner,
                       describe_token(line, t, found, sizeof found));
    *material = -1;
    if (t->length < SCENE_NAME_MAX) {
        char name[SCENE_NAME_MAX];
        memcpy(name, line->text + t->offset, t->length);
        name[t->length] = '\0';
        *material = scene_find_material(p->scene, name);
    }
    if (*material < 0)
        return fail_at(p, line, t->offset, "%s's material %s is not defined (a material must be defined before the "
                       "%s that use it)", owner, describe_token(line, t, found, sizeof found), users);
    return true;
}

/* Returns the index of the texture called name (length bytes), or -1. The hidden textures
 * that hold a checker's plain colours have an empty name and are never found. */
static int find_texture(const scene *s, const char *name, size_t length)
{
    for (int i = 0; i < s->texture_count; i++)
        if (strlen(s->textures[i].name) == length && length > 0 && memcmp(s->textures[i].name, name, length) == 0)
            return i;
    return -1;
}

/* Reads token t, written @NAME, as a reference to a texture defined earlier. */
static bool texture_from_token(parser *p, const source_line *line, const token *t, int *texture)
{
    char found[QUOTE_BUFFER + 16];
    const char *text = line->text + t->offset;
    if (t->kind != TOKEN_WORD || t->length < 2 || text[0] != '@' || !is_name(text + 1, t->length - 1))
        return fail_at(p, line, t->offset, "expected a texture reference @NAME, found %s",
                       describe_token(line, t, found, sizeof found));
    *texture = find_texture(p->scene, text + 1, t->length - 1);
    if (*texture < 0)
        return fail_at(p, line, t->offset, "texture %s is not defined (a texture must be defined before it is used)",
                       quote(found, sizeof found, text + 1, t->length - 1));
    return true;
}

/* Reads COLOR for owner: R G B (each >= 0), or @NAME of a texture defined earlier, which
 * sets *texture (else -1) and leaves out at 1 1 1, so that colour x texture = texture. */
static bool read_colour_or_texture(parser *p, source_line *line, const char *owner, float out[3], int *texture)
{
    token t = {.kind = TOKEN_END};
    if (!peek_token(p, line, &t))
        return false;
    *texture = -1;
    if (t.kind != TOKEN_WORD || line->text[t.offset] != '@')
        return read_colour(p, line, owner, out);
    if (!next_token(p, line, &t) || !texture_from_token(p, line, &t, texture))
        return false;
    out[0] = out[1] = out[2] = 1;
    return true;
}

/* Returns the index of the named group called name, or -1. */
static int find_group(const parser *p, const char *name)
{
    for (int i = 0; i < p->group_count; i++)
        if (strcmp(p->groups[i].name, name) == 0)
            return i;
    return -1;
}

/* ------------------------------------------------------------------ asset paths */

/* Reads a quoted, non-empty path for what (e.g. "the mesh") and resolves it as include
 * paths are: relative to the directory of the file that names it. The caller frees
 * *resolved; *offset gets the string's offset. Whether the file exists is the asset
 * loader's business (it reports the position recorded here). */
static bool read_asset_path(parser *p, source_line *line, const char *what, char **resolved, size_t *offset)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(p, line, &t))
        return false;
    char found[QUOTE_BUFFER + 16];
    if (t.kind != TOKEN_STRING)
        return fail_at(p, line, t.offset, "expected a quoted path for %s (e.g. \"file.png\"), found %s", what,
                       describe_token(line, &t, found, sizeof found));
    if (t.length == 2)
        return fail_at(p, line, t.offset, "expected a path inside the quotes of %s, found an empty string", what);
    char *path = resolve_include_path(line->file->path, line->text + t.offset + 1, t.length - 2);
    if (path == NULL)
        return fail_out_of_memory(p);
    size_t length = strlen(path);
    if (length > MAX_ASSET_PATH) {
        free(path);
        return fail_at(p, line, t.offset, "the path of %s is %zu bytes long once resolved; the limit is %d", what,
                       length, MAX_ASSET_PATH);
    }
    *resolved = path;
    *offset = t.offset;
    return true;
}

/* Writes "FILE:LINE:COLUMN" of where into buffer, for the asset loader's messages. */
static void format_position(char *buffer, size_t size, const source_position *where)
{
    snprintf(buffer, size, "%s:%d:%zu", where->path, where->line, where->column);
}

/* Reads the quoted path of an image for what and sets *image to its index, adding the
 * image on first use (images are shared by resolved path). */
static bool read_image(parser *p, source_line *line, const char *what, int *image)
{
    char *path = NULL;
    size_t offset = 0;
    if (!read_asset_path(p, line, what, &path, &offset))
        return false;
    for (int i = 0; i < p->scene->image_count; i++) {
        if (strcmp(p->scene->images[i].path, path) == 0) {
            free(path);
            *image = i;
            return true;
        }
    }
    scene_image added;
    memset(&added, 0, sizeof added);
    memcpy(added.path, path, strlen(path) + 1);
    free(path);
    source_position where = position_in(line, offset);
    format_position(added.position, sizeof added.position, &where);
    *image = scene_add_image(p->scene, &added);
    return *image >= 0 || fail_out_of_memory(p);
}

/* ------------------------------------------------------------------ affine maps */

/* Returns the map that leaves every point where it is. */
static affine affine_identity(void)
{
    affine identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    return identity;
}

/* Returns outer ∘ inner: inner applies first. */
static affine affine_compose(const affine *outer, const affine *inner)
{
    affine result;
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 4; column++) {
            double sum = column == 3 ? outer->m[row][3] : 0;
            for (int k = 0; k < 3; k++)
                sum += outer->m[row][k] * inner->m[k][column];
            result.m[row][column] = sum;
        }
    }
    return result;
}

/* Returns the determinant of the 3x3 (linear) part. */
static double affine_determinant(const affine *a)
{
    const double (*m)[4] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* Returns the right-handed rotation by degrees about the unit axis (x, y, z) through the
 * origin (Rodrigues' formula). */
static affine affine_rotation(const double axis[3], double degrees)
{
    double radians = degrees * (3.14159265358979323846 / 180.0);
    double c = cos(radians), s = sin(radians), t = 1 - c;
    double x = axis[0], y = axis[1], z = axis[2];
    affine rotation = {{
        {t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0},
        {t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0},
        {t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0},
    }};
    return rotation;
}

/* ------------------------------------------------------------------ blocks and placements */

/* The block whose contents the current line adds to (the top level when none is open). */
static block *current_block(parser *p)
{
    return &p->blocks[p->block_count - 1];
}

/* Names a kind of block in messages. */
static const char *block_noun(block_kind kind)
{
    switch (kind) {
    case BLOCK_GROUP:
        return "group";
    case BLOCK_INSTANCE:
        return "instance block";
    case BLOCK_VOLUME:
        return "volume";
    default:
        return "top level";
    }
}

/* Counts one more instance or group record against MAX_PLACEMENTS; where is the statement
 * that causes it. */
static bool count_placement(parser *p, const source_position *where)
{
    if (p->placement_total >= MAX_PLACEMENTS)
        return fail_at_position(p, where, "the scene places too many objects: more than %d instances and group "
                                "placements together (instances of groups of instances multiply)", MAX_PLACEMENTS);
    p->placement_total++;
    return true;
}

/* Places local (relative to the current block's contents) through every open block, as
 * described at the top of this file, and adds the resulting scene instance. */
static bool place_object(parser *p, const placement *local, const source_position *where)
{
    placement placed = *local;
    for (int k = p->block_count - 1; k >= 1; k--) {
        const block *b = &p->blocks[k];
        placed.transform = affine_compose(&b->transform, &placed.transform);
        if (placed.material < 0)
            placed.material = b->material;
        if (!placed.volume && b->kind == BLOCK_VOLUME) {
            placed.volume = true;
            placed.density = b->density;
            memcpy(placed.volume_albedo, b->albedo, sizeof placed.volume_albedo);
        }
        if (b->group < 0)
            continue;
        named_group *group = &p->groups[b->group];
        if (!count_placement(p, where) ||
            !grow_array(p, (void **)&group->placements, group->placement_count, &group->placement_capacity,
                        sizeof *group->placements))
            return false;
        group->placements[group->placement_count++] = placed;
    }
    scene_instance instance = {
        .object = placed.object, .material = placed.material, .volume = placed.volume,
        .density = placed.density,
    };
    memcpy(instance.volume_albedo, placed.volume_albedo, sizeof instance.volume_albedo);
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 4; column++) {
            double value = placed.transform.m[row][column];
            if (!(fabs(value) <= FLT_MAX))
                return fail_at_position(p, where, "the transforms around this statement place it at a scale or "
                                        "distance too large for the renderer's 32-bit floats (%g)", value);
            instance.object_to_world[row][column] = (float)value;
        }
    }
    if (!count_placement(p, where))
        return false;
    return scene_add_instance(p->scene, &instance) >= 0 || fail_out_of_memory(p);
}

/* Adds shape (of the statement at where) to the current block; the block's first shape
 * creates and places its object, whose shapes are filled in when the block closes. */
static bool add_block_shape(parser *p, const scene_shape *shape, const source_position *where)
{
    block *b = current_block(p);
    if (b->object < 0) {
        scene_object object = {.first_shape = 0, .shape_count = 0, .mesh = -1};
        b->object = scene_add_object(p->scene, &object);
        if (b->object < 0)
            return fail_out_of_memory(p);
        placement local = {.object = b->object, .transform = affine_identity(), .material = -1};
        if (!place_object(p, &local, where))
            return false;
    }
    if (!grow_array(p, (void **)&b->shapes, b->shape_count, &b->shape_capacity, sizeof *b->shapes))
        return false;
    b->shapes[b->shape_count++] = (pending_shape){.shape = *shape, .position = *where};
    return true;
}

/* Moves a block's buffered shapes into the scene, contiguous, as its object's shapes. */
static bool flush_block_shapes(parser *p, block *b)
{
    if (b->object < 0)
        return true;
    scene *s = p->scene;
    s->objects[b->object].first_shape = s->shape_count;
    for (int i = 0; i < b->shape_count; i++) {
        int index = scene_add_shape(s, &b->shapes[i].shape);
        if (index < 0)
            return fail_out_of_memory(p);
        if (!remember_position(p, &p->shape_positions, &p->shape_position_capacity, index, b->shapes[i].position))
            return false;
    }
    s->objects[b->object].shape_count = b->shape_count;
    return true;
}

/* Places every placement named group made again, through the current blocks (whose top
 * is the instance block with the instance's own transform and material). */
static bool place_group(parser *p, int group, const source_position *where)
{
    for (int i = 0; i < p->groups[group].placement_count; i++) {
        /* A copy: placing records into the enclosing groups, never into this closed one,
         * but the copy keeps that reasoning out of the way. */
        placement recorded = p->groups[group].placements[i];
        if (!place_object(p, &recorded, where))
            return false;
    }
    return true;
}

/* Opens a block of kind for the statement whose keyword is at keyword; an implicit block
 * (the instance statement without braces) is not counted against MAX_BLOCK_DEPTH. */
static bool open_block(parser *p, const source_line *line, const token *keyword, block_kind kind, bool implicit)
{
    if (!implicit && p->block_count - 1 >= MAX_BLOCK_DEPTH)
        return fail_at(p, line, keyword->offset, "blocks nested too deeply: this %s would be level %d, the limit is %d",
                       block_noun(kind), p->block_count, MAX_BLOCK_DEPTH);
    p->blocks[p->block_count++] = (block){
        .kind = kind, .opened = position_in(line, keyword->offset), .file = line->file,
        .transform = affine_identity(), .material = -1, .group = -1, .instance_of = -1, .object = -1,
    };
    return true;
}

/* Closes the current block (its contents already handled) and frees its buffers. */
static void pop_block(parser *p)
{
    block *b = current_block(p);
    free(b->shapes);
    p->block_count--;
}

/* Starts a statement that adds content to the current block: after it, no transform may
 * follow in the block, and an instance block takes nothing but transforms. */
static bool begin_content(parser *p, const source_line *line, const token *keyword)
{
    block *b = current_block(p);
    if (b->kind == BLOCK_INSTANCE) {
        char found[QUOTE_BUFFER + 16];
        return fail_at(p, line, keyword->offset, "only transforms (translate, rotate, scale, matrix) may appear inside "
                       "an instance block, found %s", describe_token(line, keyword, found, sizeof found));
    }
    b->content_seen = true;
    return true;
}

/* ------------------------------------------------------------------ statements */

static bool parse_source(parser *p, const source_file *file);

/* include "PATH": parses the file at PATH (relative to the including file's directory)
 * as if its lines stood here, after checking for cycles and the depth limit. */
static bool statement_include(parser *p, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(p, line, &t))
        return false;
    char found[QUOTE_BUFFER + 16];
    if (t.kind != TOKEN_STRING)
        return fail_at(p, line, t.offset, "expected a quoted path after include (e.g. include \"common.txt\"), found %s",
                       describe_token(line, &t, found, sizeof found));
    if (t.length == 2)
        return fail_at(p, line, t.offset, "expected a path inside the quotes of include, found an empty string");
    if (!expect_end_of_line(p, line, "the included path"))
        return false;

    const source_file *includer = line->file;
    const char *path = keep_path(p, resolve_include_path(includer->path, line->text + t.offset + 1, t.length - 2));
    if (path == NULL)
        return fail_out_of_memory(p);

    char *text = NULL;
    size_t length = 0;
    struct stat info;
    int failure = read_whole_file(path, &text, &length, &info);
    if (failure == ENOMEM)
        return fail_out_of_memory(p);
    if (failure != 0)
        return fail_at(p, line, keyword->offset, "cannot read included file '%s': %s", path, strerror(failure));

    /* Compare files by identity, not by name: "a.txt" and "./a.txt" are one file. */
    for (const source_file *outer = includer; outer != NULL; outer = outer->includer) {
        if (!outer->has_identity || outer->device != info.st_dev || outer->inode != info.st_ino)
            continue;
        /* The chain runs from the repeated file down to this include; the links point
         * upwards, so count the levels and then walk up to each one in turn. */
        char chain[sizeof p->error->message] = "";
        size_t used = 0;
        int levels = 1;
        for (const source_file *level = includer; level != outer; level = level->includer)
            levels++;
        for (int i = levels - 1; i >= 0 && used < sizeof chain; i--) {
            const source_file *level = includer;
            for (int step = 0; step < i; step++)
                level = level->includer;
            used += (size_t)snprintf(chain + used, sizeof chain - used, "%s -> ", level->path);
        }
        if (used < sizeof chain)
            snprintf(chain + used, sizeof chain - used, "%s", path);
        free(text);
        return fail_at(p, line, keyword->offset, "include cycle: %s", chain);
    }

    int depth = includer->depth + 1;
    if (depth > p->max_include_depth) {
        free(text);
        return fail_at(p, line, keyword->offset, "includes nested too deeply: '%s' would be level %d, the limit is %d",
                       path, depth, p->max_include_depth);
    }

    source_file included = {
        .path = path, .text = text, .length = length, .has_identity = true,
        .device = info.st_dev, .inode = info.st_ino, .depth = depth, .includer = includer,
    };
    bool ok = parse_source(p, &included);
    free(text);
    return ok;
}

/* set NAME EXPRESSION: defines $NAME, unless a -D define already fixed it. */
static bool statement_set(parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    token name = {.kind = TOKEN_END};
    if (!next_token(p, line, &name))
        return false;
    char found[QUOTE_BUFFER + 16];
    if (name.kind == TOKEN_END)
        return fail_at(p, line, name.offset, "expected a variable name after set, found end of line");
    const char *text = line->text + name.offset;
    if (name.kind != TOKEN_WORD || !expression_is_variable_name(text, name.length))
        return fail_at(p, line, name.offset, "expected a variable name after set (letters, digits and '_', not "
                       "starting with a digit%s), found %s", name.kind == TOKEN_WORD && text[0] == '$' ?
                       "; write it without '$'" : "", describe_token(line, &name, found, sizeof found));

    /* The rest of the line, up to a comment, is one expression: no parentheses needed. */
    size_t start = line->cursor;
    while (start < line->length && is_space(line->text[start]))
        start++;
    size_t end = start;
    while (end < line->length && line->text[end] != '#')
        end++;
    line->cursor = line->length;
    if (start == end)
        return fail_at(p, line, name.offset + name.length, "expected an expression for $%.*s, found end of line",
                       quoted_length(text, name.length), text);

    variable *target = find_or_add_variable(p, text, name.length);
    if (target == NULL)
        return false;
    target->mentioned = true;
    if (target->from_define) {
        /* The skipped expression still counts as using the -D variables it names, so
         * that `-D a=1 -D b=2` with `set a $b` does not call -D b unused. */
        for (size_t i = start; i < end; i++) {
            if (line->text[i] != '$')
                continue;
            size_t name_end = i + 1;
            while (name_end < end && expression_is_variable_name(line->text + i + 1, name_end - i))
                name_end++;
            variable *used = find_variable(p, line->text + i + 1, name_end - i - 1);
            if (used != NULL)
                used->mentioned = true;
        }
        return true;
    }
    double value = 0;
    if (!evaluate(p, line, start, end - start, &value))
        return false;
    target->value = value;
    target->has_value = true;
    return true;
}

/* camera [from X Y Z] [at X Y Z] [up X Y Z] [fov D] [aperture A] [focus D]
 * [shutter OPEN CLOSE]; the frame is checked once the whole scene is read
 * (check_finished_scene). */
static bool statement_camera(parser *p, source_line *line, const token *keyword)
{
    static const char *const clauses[] = {"from", "at", "up", "fov", "aperture", "focus", "shutter"};
    size_t first_offsets[7] = {SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX};
    scene_camera *camera = &p->scene->camera;
    p->camera_seen = true;
    p->last_camera = (source_position){.path = line->file->path, .line = line->number, .column = keyword->offset + 1};
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(p, line, &t))
            return false;
        if (t.kind == TOKEN_END)
            return true;
        int clause = -1;
        if (!match_clause(p, line, &t, "camera", clauses, 7, first_offsets, &clause))
            return false;
        double value = 0;
        size_t offset = 0;
        char number[40];
        switch (clause) {
        case 0:
            if (!read_vector(p, line, "the camera's from", camera->look_from, NULL))
                return false;
            break;
        case 1:
            if (!read_vector(p, line, "the camera's at", camera->look_at, NULL))
                return false;
            break;
        case 2:
            if (!read_vector(p, line, "the camera's up", camera->up, NULL))
                return false;
            break;
        case 3:
            if (!read_number(p, line, "the camera's fov", &value, &offset))
                return false;
            if (!(value > 0 && value < 180))
                return fail_at(p, line, offset, "the camera's fov must be between 0 and 180 degrees (both "
                               "excluded), found %s", format_number(number, sizeof number, value));
            camera->vertical_fov_degrees = (float)value;
            break;
        case 4:
            if (!read_number(p, line, "the camera's aperture", &value, &offset))
                return false;
            if (value < 0)
                return fail_at(p, line, offset, "the camera's aperture must be >= 0, found %s",
                               format_number(number, sizeof number, value));
            if (!to_float(p, line, offset, "the camera's aperture", value, &camera->aperture))
                return false;
            break;
        case 5:
            if (!read_number(p, line, "the camera's focus distance", &value, &offset))
                return false;
            if (value < 0)
                return fail_at(p, line, offset, "the camera's focus distance must be >= 0 (0 means the "
                               "distance to 'at'), found %s", format_number(number, sizeof number, value));
            if (!to_float(p, line, offset, "the camera's focus distance", value, &camera->focus_distance))
                return false;
            break;
        default: {
            double close = 0;
            size_t close_offset = 0;
            char close_number[40];
            if (!read_number(p, line, "the camera's shutter open time", &value, &offset) ||
                !read_number(p, line, "the camera's shutter close time", &close, &close_offset))
                return false;
            if (!(value >= 0 && value <= 1) || !(close >= value && close <= 1))
                return fail_at(p, line, value >= 0 && value <= 1 ? close_offset : offset, "the camera's shutter "
                               "must have 0 <= open <= close <= 1, found open %s and close %s",
                               format_number(number, sizeof number, value),
                               format_number(close_number, sizeof close_number, close));
            camera->shutter_open = (float)value;
            camera->shutter_close = (float)close;
            break;
        }
        }
    }
}

/* render [size W H] [spp N] [depth N] [seed N]. */
static bool statement_render(parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    static const char *const clauses[] = {"size", "spp", "depth", "seed"};
    size_t first_offsets[4] = {SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX};
    scene_render_settings *render = &p->scene->render;
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(p, line, &t))
            return false;
        if (t.kind == TOKEN_END)
            return true;
        int clause = -1;
        if (!match_clause(p, line, &t, "render", clauses, 4, first_offsets, &clause))
            return false;
        long long width, height, value;
        switch (clause) {
        case 0:
            if (!read_integer(p, line, "the render width", 1, 16384, &width) ||
                !read_integer(p, line, "the render height", 1, 16384, &height))
                return false;
            render->width = (int)width;
            render->height = (int)height;
            break;
        case 1:
            if (!read_integer(p, line, "the samples per pixel (spp)", 1, 1073741824, &value))
                return false;
            render->samples_per_pixel = (int)value;
            break;
        case 2:
            if (!read_integer(p, line, "the render depth", 1, 100000, &value))
                return false;
            render->max_depth = (int)value;
            break;
        default:
            if (!read_integer(p, line, "the render seed", 0, 4294967295LL, &value))
                return false;
            render->seed = (uint32_t)value;
            break;
        }
    }
}

/* sky gradient R G B  R G B | constant R G B | box "+X" "-X" "+Y" "-Y" "+Z" "-Z" |
 * environment "FILE", then [intensity I] (and [rotate DEGREES] for box and environment).
 * The last sky statement wins, wholly: what it leaves out is back at the default. */
static bool statement_sky(parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    static const char *const face_names[SKY_FACE_COUNT] = {
        "the sky box's +X face", "the sky box's -X face", "the sky box's +Y face",
        "the sky box's -Y face", "the sky box's +Z face", "the sky box's -Z face",
    };
    token type = {.kind = TOKEN_END};
    if (!next_token(p, line, &type))
        return false;
    scene defaults;
    scene_defaults(&defaults);
    scene_sky sky = defaults.sky;
    bool has_image = false;
    if (token_is(line, &type, "gradient")) {
        sky.type = SKY_GRADIENT;
        if (!read_colour(p, line, "the sky's bottom colour", sky.bottom) ||
            !read_colour(p, line, "the sky's top colour", sky.top))
            return false;
    } else if (token_is(line, &type, "constant")) {
        sky.type = SKY_CONSTANT;
        if (!read_colour(p, line, "the sky colour", sky.bottom))
            return false;
        memcpy(sky.top, sky.bottom, sizeof sky.top);
    } else if (token_is(line, &type, "box")) {
        sky.type = SKY_BOX;
        has_image = true;
        for (int face = 0; face < SKY_FACE_COUNT; face++)
            if (!read_image(p, line, face_names[face], &sky.faces[face]))
                return false;
    } else if (token_is(line, &type, "environment")) {
        sky.type = SKY_ENVIRONMENT;
        has_image = true;
        if (!read_image(p, line, "the sky environment", &sky.environment))
            return false;
    } else {
        char found[QUOTE_BUFFER + 16];
        return fail_at(p, line, type.offset, "expected a sky type (gradient, constant, box or environment), found %s",
                       describe_token(line, &type, found, sizeof found));
    }
    static const char *const clauses[] = {"intensity", "rotate"};
    size_t first_offsets[2] = {SIZE_MAX, SIZE_MAX};
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(p, line, &t))
            return false;
        if (t.kind == TOKEN_END)
            break;
        int clause = -1;
        if (!match_clause(p, line, &t, "sky", clauses, has_image ? 2 : 1, first_offsets, &clause))
            return false;
        double value = 0;
        size_t offset = 0;
        char number[40];
        if (clause == 0) {
            if (!read_number(p, line, "the sky's intensity", &value, &offset))
                return false;
            if (!(value >= 0))
                return fail_at(p, line, offset, "the sky's intensity must be >= 0, found %s",
                               format_number(number, sizeof number, value));
            if (!to_float(p, line, offset, "the sky's intensity", value, &sky.intensity))
                return false;
        } else if (!read_number(p, line, "the sky's rotation in degrees", &value, &offset) ||
                   !to_float(p, line, offset, "the sky's rotation", value, &sky.rotation_degrees)) {
            return false;
        }
    }
    p->scene->sky = sky;
    return true;
}

/* ambient R G B: the Whitted integrator's ambient term (each >= 0); the last one wins. */
static bool statement_ambient(parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    float ambient[3];
    if (!read_colour(p, line, "the ambient colour", ambient) || !expect_end_of_line(p, line, "the ambient colour"))
        return false;
    memcpy(p->scene->ambient, ambient, sizeof ambient);
    return true;
}

/* Scales the vector v (not zero) to unit length in double, dividing by its largest
 * component first so that tiny vectors do not underflow; stores it as float. */
static void normalise_into(const double v[3], float out[3])
{
    double largest = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
    double unit[3], length = 0;
    for (int i = 0; i < 3; i++) {
        unit[i] = v[i] / largest;
        length += unit[i] * unit[i];
    }
    length = sqrt(length);
    for (int i = 0; i < 3; i++)
        out[i] = (float)(unit[i] / length);
}

/* Reads an angle in degrees for what (a cone half-angle, the sun's diameter): 0 <= angle < 90. */
static bool read_light_angle(parser *p, source_line *line, const char *what, double *value, size_t *offset)
{
    if (!read_number(p, line, what, value, offset))
        return false;
    if (!(*value >= 0 && *value < 90)) {
        char number[40];
        return fail_at(p, line, *offset, "%s must be from 0 up to (not including) 90 degrees, found %s", what,
                       format_number(number, sizeof number, *value));
    }
    return true;
}

/* Reads the falloff clause of owner ("the point light"): inverse_square, or polynomial
 * C L Q (each >= 0, not all 0), into light. */
static bool read_light_falloff(parser *p, source_line *line, const char *owner, scene_light *light)
{
    static const char *const terms[3] = {"constant", "linear", "quadratic"};
    token kind = {.kind = TOKEN_END};
    if (!next_token(p, line, &kind))
        return false;
    if (token_is(line, &kind, "inverse_square")) {
        light->falloff = FALLOFF_INVERSE_SQUARE;
        return true;
    }
    char found[QUOTE_BUFFER + 16];
    if (!token_is(line, &kind, "polynomial"))
        return fail_at(p, line, kind.offset, "expected a falloff for %s (inverse_square, or polynomial C L Q), "
                       "found %s", owner, describe_token(line, &kind, found, sizeof found));
    float attenuation[3];
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s term of %s's polynomial falloff", terms[i], owner);
        double value = 0;
        size_t offset = 0;
        char number[40];
        if (!read_number(p, line, what, &value, &offset))
            return false;
        if (value < 0)
            return fail_at(p, line, offset, "%s must be >= 0, found %s", what,
                           format_number(number, sizeof number, value));
        if (!to_float(p, line, offset, what, value, &attenuation[i]))
            return false;
    }
    /* Compared as floats: a term that rounds to 0 does not help the renderer either. */
    if (attenuation[0] == 0 && attenuation[1] == 0 && attenuation[2] == 0)
        return fail_at(p, line, kind.offset, "the terms of %s's polynomial falloff must not all be 0 (the light "
                       "would be infinitely bright at every distance)", owner);
    light->falloff = FALLOFF_POLYNOMIAL;
    memcpy(light->attenuation, attenuation, sizeof attenuation);
    return true;
}

/* light point X Y Z [color R G B] [intensity I] [falloff inverse_square | falloff polynomial C L Q]
 * light spot X Y Z at X Y Z [color R G B] [intensity I] [cone INNER OUTER] [falloff ...]
 * light sun DX DY DZ [color R G B] [intensity I] [angle DEGREES]
 * Only at the top level. scene_light.color is colour x intensity; the sun's direction is
 * the one its light travels. */
static bool statement_light(parser *p, source_line *line, const token *keyword)
{
    if (p->block_count > 1) {
        const block *b = current_block(p);
        return fail_at(p, line, keyword->offset, "lights go at the top level of a scene, not inside a group (this "
                       "light is inside the %s opened at %s:%d:%zu)", block_noun(b->kind), b->opened.path,
                       b->opened.line, b->opened.column);
    }
    token type = {.kind = TOKEN_END};
    if (!next_token(p, line, &type))
        return false;
    char found[QUOTE_BUFFER + 16];
    scene_light_type kind;
    const char *owner, *statement;
    if (token_is(line, &type, "point"))
        kind = SCENE_LIGHT_POINT, owner = "the point light", statement = "point light";
    else if (token_is(line, &type, "spot"))
        kind = SCENE_LIGHT_SPOT, owner = "the spot light", statement = "spot light";
    else if (token_is(line, &type, "sun"))
        kind = SCENE_LIGHT_SUN, owner = "the sun", statement = "sun light";
    else
        return fail_at(p, line, type.offset, "expected a light type (point, spot or sun), found %s",
                       describe_token(line, &type, found, sizeof found));
    scene_light light = scene_light_defaults(kind);

    char what[DESCRIPTION_BUFFER];
    if (kind == SCENE_LIGHT_SUN) {
        double direction[3];
        size_t offsets[3];
        if (!read_point(p, line, "the sun's direction", direction, offsets))
            return false;
        if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0)
            return fail_at(p, line, offsets[0], "the sun's direction (0 0 0) has zero length, so it has no "
                           "direction (it is the direction the light travels, e.g. 0 -1 0 shines straight down)");
        normalise_into(direction, light.direction);
    } else {
        snprintf(what, sizeof what, "%s's position", owner);
        if (!read_vector(p, line, what, light.position, NULL))
            return false;
    }
    if (kind == SCENE_LIGHT_SPOT) {
        token at = {.kind = TOKEN_END};
        if (!next_token(p, line, &at))
            return false;
        if (!token_is(line, &at, "at"))
            return fail_at(p, line, at.offset, "expected 'at' and the point the spot light shines at after its "
                           "position, found %s", describe_token(line, &at, found, sizeof found));
        float target[3];
        size_t offsets[3];
        if (!read_vector(p, line, "the spot light's at", target, offsets))
            return false;
        double direction[3];
        for (int i = 0; i < 3; i++)
            direction[i] = (double)target[i] - light.position[i];
        if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0)
            return fail_at(p, line, offsets[0], "the spot light's at is its position (%g %g %g), so it has no "
                           "direction", target[0], target[1], target[2]);
        normalise_into(direction, light.direction);
    }

    /* The clauses each type takes; the index into all_clauses is what the switch uses. */
    static const char *const all_clauses[] = {"color", "intensity", "falloff", "cone", "angle"};
    static const char *const point_clauses[] = {"color", "intensity", "falloff"};
    static const char *const spot_clauses[] = {"color", "intensity", "cone", "falloff"};
    static const char *const sun_clauses[] = {"color", "intensity", "angle"};
    const char *const *names = kind == SCENE_LIGHT_POINT ? point_clauses
                               : kind == SCENE_LIGHT_SPOT ? spot_clauses : sun_clauses;
    int count = kind == SCENE_LIGHT_SPOT ? 4 : 3;
    size_t first_offsets[4] = {SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX};
    float colour[3] = {1, 1, 1};
    double intensity = 1;
    size_t intensity_offset = SIZE_MAX;
    char number[40], second[40];
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(p, line, &t))
            return false;
        if (t.kind == TOKEN_END)
            break;
        int index = -1;
        if (!match_clause(p, line, &t, statement, names, count, first_offsets, &index))
            return false;
        int clause = 0;
        while (strcmp(all_clauses[clause], names[index]) != 0)
            clause++;
        switch (clause) {
        case 0:
            snprintf(what, sizeof what, "%s's color", owner);
            if (!read_colour(p, line, what, colour))
                return false;
            break;
        case 1:
            snprintf(what, sizeof what, "%s's intensity", owner);
            if (!read_number(p, line, what, &intensity, &intensity_offset))
                return false;
            if (!(intensity >= 0))
                return fail_at(p, line, intensity_offset, "%s must be >= 0, found %s", what,
                               format_number(number, sizeof number, intensity));
            break;
        case 2:
            if (!read_light_falloff(p, line, owner, &light))
                return false;
            break;
        case 3: {
            double inner = 0, outer = 0;
            size_t inner_offset = 0, outer_offset = 0;
            if (!read_light_angle(p, line, "the spot light's inner cone angle", &inner, &inner_offset) ||
                !read_light_angle(p, line, "the spot light's outer cone angle", &outer, &outer_offset))
                return false;
            if (inner > outer)
                return fail_at(p, line, outer_offset, "the spot light's cone must have 0 <= inner <= outer < 90 "
                               "degrees, found inner %s and outer %s", format_number(number, sizeof number, inner),
                               format_number(second, sizeof second, outer));
            light.spot_inner_degrees = (float)inner;
            light.spot_outer_degrees = (float)outer;
            break;
        }
        default: {
            double angle = 0;
            size_t offset = 0;
            if (!read_light_angle(p, line, "the sun's angle", &angle, &offset))
                return false;
            light.sun_angle_degrees = (float)angle;
            break;
        }
        }
    }
    for (int i = 0; i < 3; i++) {
        snprintf(what, sizeof what, "%s's color x intensity", owner);
        /* Only a given intensity can take a (float) colour out of range. */
        if (!to_float(p, line, intensity_offset != SIZE_MAX ? intensity_offset : keyword->offset, what,
                      colour[i] * intensity, &light.color[i]))
            return false;
    }
    return scene_add_light(p->scene, &light) >= 0 || fail_out_of_memory(p);
}

/* Reads specular R G B for owner (e.g. "material 'm'"): each component from 0 to 1. */
static bool read_specular(parser *p, source_line *line, const char *owner, float out[3])
{
    static const char *const channels[3] = {"red", "green", "blue"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s component of the specular colour of %s", channels[i], owner);
        size_t offset = 0;
        double value = 0;
        if (!read_number(p, line, what, &value, &offset))
            return false;
        if (!(value >= 0 && value <= 1)) {
            char number[40];
            return fail_at(p, line, offset, "%s must be between 0 and 1, found %s", what,
                           format_number(number, sizeof number, value));
        }
        out[i] = (float)value;
    }
    return true;
}

/* Reads the phong exponent of owner: > 0, and not 0 as a float either (0 means "the
 * default" in scene_material). */
static bool read_phong_exponent(parser *p, source_line *line, const char *owner, float *out)
{
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "the phong exponent of %s", owner);
    double value = 0;
    size_t offset = 0;
    char number[40];
    if (!read_number(p, line, what, &value, &offset))
        return false;
    if (!(value > 0))
        return fail_at(p, line, offset, "%s must be > 0, found %s", what, format_number(number, sizeof number, value));
    if (!to_float(p, line, offset, what, value, out))
        return false;
    if (*out == 0)
        return fail_at(p, line, offset, "%s %s is too small for the renderer's 32-bit floats", what,
                       format_number(number, sizeof number, value));
    return true;
}

/* Reads the optional clauses of a material, in any order: a number (fuzz, strength) into
 * *value (offset into *value_offset), normal_map "FILE" into material->normal_map, phong
 * EXPONENT and specular R G B (lambertian and metal) into the Whitted fields. statement
 * names the material type for messages ("metal material"), owner the material
 * ("material 'm'"). */
static bool read_material_clauses(parser *p, source_line *line, const char *statement, const char *owner,
                                  const char *const *names, int count, scene_material *material, double *value,
                                  size_t *value_offset)
{
    size_t first_offsets[8] = {SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX};
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(p, line, &t))
            return false;
        if (t.kind == TOKEN_END)
            return true;
        int index = -1;
        if (!match_clause(p, line, &t, statement, names, count, first_offsets, &index))
            return false;
        char description[DESCRIPTION_BUFFER];
        snprintf(description, sizeof description, "the %s of the %s", names[index], statement);
        if (strcmp(names[index], "normal_map") == 0) {
            if (!read_image(p, line, description, &material->normal_map))
                return false;
            /* A normal map holds vectors: the loader must not sRGB-decode it. */
            p->scene->images[material->normal_map].data = true;
        } else if (strcmp(names[index], "phong") == 0) {
            if (!read_phong_exponent(p, line, owner, &material->phong_exponent))
                return false;
        } else if (strcmp(names[index], "specular") == 0) {
            if (!read_specular(p, line, owner, material->specular))
                return false;
            material->specular_set = true;
        } else if (!read_number(p, line, description, value, value_offset)) {
            return false;
        }
    }
}

/* material NAME lambertian COLOR [normal_map "F"] [phong E] [specular R G B] |
 * metal COLOR [fuzz F] [normal_map "F"] [phong E] [specular R G B] |
 * dielectric IOR [normal_map "F"] | emissive COLOR [strength S], COLOR being R G B or
 * @TEXTURE. Remembers where NAME was defined for duplicate errors. */
static bool statement_material(parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    token name = {.kind = TOKEN_END};
    scene_material material = scene_material_defaults();
    material.type = MATERIAL_LAMBERTIAN;
    if (!read_definition_name(p, line, "material", &name, material.name))
        return false;
    int existing = scene_find_material(p->scene, material.name);
    if (existing >= 0) {
        const source_position *first = &p->material_positions[existing];
        return fail_at(p, line, name.offset, "material '%s' is already defined at %s:%d:%zu", material.name,
                       first->path, first->line, first->column);
    }

    char owner[OWNER_BUFFER];
    snprintf(owner, sizeof owner, "material '%s'", material.name);
    token type = {.kind = TOKEN_END};
    if (!next_token(p, line, &type))
        return false;
    double value = 0;
    size_t offset = type.offset;
    char number[40];
    char found[QUOTE_BUFFER + 16];
    static const char *const normal_map_only[] = {"normal_map"};
    if (token_is(line, &type, "lambertian")) {
        static const char *const clauses[] = {"normal_map", "phong", "specular"};
        material.type = MATERIAL_LAMBERTIAN;
        if (!read_colour_or_texture(p, line, owner, material.albedo, &material.albedo_texture) ||
            !read_material_clauses(p, line, "lambertian material", owner, clauses, 3, &material, NULL, NULL))
            return false;
    } else if (token_is(line, &type, "metal")) {
        static const char *const clauses[] = {"fuzz", "normal_map", "phong", "specular"};
        material.type = MATERIAL_METAL;
        value = 0;
        if (!read_colour_or_texture(p, line, owner, material.albedo, &material.albedo_texture) ||
            !read_material_clauses(p, line, "metal material", owner, clauses, 4, &material, &value, &offset))
            return false;
        if (!(value >= 0 && value <= 1))
            return fail_at(p, line, offset, "the fuzz of %s must be between 0 and 1, found %s", owner,
                           format_number(number, sizeof number, value));
        material.fuzz = (float)value;
    } else if (token_is(line, &type, "dielectric")) {
        material.type = MATERIAL_DIELECTRIC;
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the index of refraction of %s", owner);
        if (!read_number(p, line, what, &value, &offset))
            return false;
        if (!(value > 0))
            return fail_at(p, line, offset, "%s must be > 0, found %s", what,
                           format_number(number, sizeof number, value));
        if (!to_float(p, line, offset, what, value, &material.index_of_refraction))
            return false;
        if (material.index_of_refraction == 0)
            return fail_at(p, line, offset, "%s %s is too small for the renderer's 32-bit floats", what,
                           format_number(number, sizeof number, value));
        if (!read_material_clauses(p, line, "dielectric material", owner, normal_map_only, 1, &material, NULL, NULL))
            return false;
    } else if (token_is(line, &type, "emissive")) {
        static const char *const clauses[] = {"strength"};
        material.type = MATERIAL_EMISSIVE;
        float colour[3];
        value = 1;
        if (!read_colour_or_texture(p, line, owner, colour, &material.emission_texture) ||
            !read_material_clauses(p, line, "emissive material", owner, clauses, 1, &material, &value, &offset))
            return false;
        if (!(value >= 0))
            return fail_at(p, line, offset, "the strength of %s must be >= 0, found %s", owner,
                           format_number(number, sizeof number, value));
        for (int i = 0; i < 3; i++)
            if (!to_float(p, line, offset, "the emission (colour x strength)", colour[i] * value,
                          &material.emission[i]))
                return false;
    } else {
        return fail_at(p, line, type.offset, "expected a material type (lambertian, metal, dielectric or "
                       "emissive), found %s", describe_token(line, &type, found, sizeof found));
    }

    int index = scene_add_material(p->scene, &material);
    if (index < 0)
        return fail_out_of_memory(p);
    return remember_position(p, &p->material_positions, &p->material_position_capacity, index,
                             position_in(line, name.offset));
}

/* Appends texture (defined by the statement at where) and sets *index to its index. */
static bool add_texture(parser *p, const scene_texture *texture, source_position where, int *index)
{
    *index = scene_add_texture(p->scene, texture);
    if (*index < 0)
        return fail_out_of_memory(p);
    return remember_position(p, &p->texture_positions, &p->texture_position_capacity, *index, where);
}

/* Reads the scale of owner (a checker's cell size or a noise frequency): > 0. */
static bool read_texture_scale(parser *p, source_line *line, const char *owner, float *scale)
{
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "the scale of %s", owner);
    double value = 0;
    size_t offset = 0;
    char number[40];
    if (!read_number(p, line, what, &value, &offset))
        return false;
    if (!(value > 0))
        return fail_at(p, line, offset, "%s must be > 0, found %s", what, format_number(number, sizeof number, value));
    if (!to_float(p, line, offset, what, value, scale))
        return false;
    if (*scale == 0)
        return fail_at(p, line, offset, "%s %s is too small for the renderer's 32-bit floats", what,
                       format_number(number, sizeof number, value));
    return true;
}

/* Reads one colour of a checker (which is "even" or "odd"): @TEXTURE, or R G B, which
 * becomes a hidden constant texture (empty name) defined by the checker's statement. */
static bool read_checker_colour(parser *p, source_line *line, const char *owner, const char *which,
                                source_position where, int *texture)
{
    char description[DESCRIPTION_BUFFER];
    snprintf(description, sizeof description, "the %s colour of %s", which, owner);
    scene_texture constant = {.type = TEXTURE_CONSTANT, .even = -1, .odd = -1, .image = -1};
    if (!read_colour_or_texture(p, line, description, constant.color, texture))
        return false;
    return *texture >= 0 || add_texture(p, &constant, where, texture);
}

/* texture NAME constant COLOR | checker SCALE COLOR COLOR | noise SCALE |
 * turbulence SCALE | marble SCALE | image "FILE". */
static bool statement_texture(parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    token name = {.kind = TOKEN_END};
    scene_texture texture = {.even = -1, .odd = -1, .image = -1};
    if (!read_definition_name(p, line, "texture", &name, texture.name))
        return false;
    int existing = find_texture(p->scene, texture.name, strlen(texture.name));
    if (existing >= 0) {
        const source_position *first = &p->texture_positions[existing];
        return fail_at(p, line, name.offset, "texture '%s' is already defined at %s:%d:%zu", texture.name,
                       first->path, first->line, first->column);
    }
    char owner[OWNER_BUFFER];
    snprintf(owner, sizeof owner, "texture '%s'", texture.name);
    source_position where = position_in(line, name.offset);
    token type = {.kind = TOKEN_END};
    if (!next_token(p, line, &type))
        return false;
    if (token_is(line, &type, "constant")) {
        int reference = -1;
        texture.type = TEXTURE_CONSTANT;
        if (!read_colour_or_texture(p, line, owner, texture.color, &reference))
            return false;
        if (reference >= 0) {
            /* `constant @other` is another name for the same texture. */
            scene_texture alias = p->scene->textures[reference];
            memcpy(alias.name, texture.name, sizeof alias.name);
            texture = alias;
        }
    } else if (token_is(line, &type, "checker")) {
        texture.type = TEXTURE_CHECKER;
        if (!read_texture_scale(p, line, owner, &texture.scale) ||
            !read_checker_colour(p, line, owner, "even", where, &texture.even) ||
            !read_checker_colour(p, line, owner, "odd", where, &texture.odd))
            return false;
    } else if (token_is(line, &type, "noise") || token_is(line, &type, "turbulence") ||
               token_is(line, &type, "marble")) {
        texture.type = token_is(line, &type, "noise") ? TEXTURE_NOISE
                       : token_is(line, &type, "turbulence") ? TEXTURE_TURBULENCE : TEXTURE_MARBLE;
        if (!read_texture_scale(p, line, owner, &texture.scale))
            return false;
    } else if (token_is(line, &type, "image")) {
        texture.type = TEXTURE_IMAGE;
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the image of %s", owner);
        if (!read_image(p, line, what, &texture.image))
            return false;
    } else {
        char found[QUOTE_BUFFER + 16];
        return fail_at(p, line, type.offset, "expected a texture type (constant, checker, noise, turbulence, marble "
                       "or image), found %s", describe_token(line, &type, found, sizeof found));
    }
    if (!expect_end_of_line(p, line, "the texture"))
        return false;
    int index = -1;
    return add_texture(p, &texture, where, &index);
}

/* ------------------------------------------------------------------ transforms */

/* Checks that a transform statement may stand here: inside a block, before its contents. */
static bool begin_transform(parser *p, const source_line *line, const token *keyword)
{
    char word[QUOTE_BUFFER + 16];
    describe_token(line, keyword, word, sizeof word);
    if (p->block_count == 1)
        return fail_at(p, line, keyword->offset, "%s outside a block: a transform applies to the contents of a "
                       "group, instance or volume", word);
    const block *b = current_block(p);
    if (b->content_seen)
        return fail_at(p, line, keyword->offset, "%s after the %s's contents: transforms come first in a group "
                       "(before its shapes, meshes, groups, instances and volumes)", word, block_noun(b->kind));
    return true;
}

/* Makes transform apply after the transforms the current block already has. */
static void append_transform(parser *p, const affine *transform)
{
    block *b = current_block(p);
    b->transform = affine_compose(transform, &b->transform);
}

/* translate X Y Z */
static bool statement_translate(parser *p, source_line *line, const token *keyword)
{
    double offset[3];
    if (!begin_transform(p, line, keyword) || !read_point(p, line, "the translation", offset, NULL) ||
        !expect_end_of_line(p, line, "the translation"))
        return false;
    affine translation = affine_identity();
    for (int i = 0; i < 3; i++)
        translation.m[i][3] = offset[i];
    append_transform(p, &translation);
    return true;
}

/* rotate AX AY AZ DEGREES: right-handed, about the axis through the origin. */
static bool statement_rotate(parser *p, source_line *line, const token *keyword)
{
    double axis[3], degrees = 0;
    size_t offsets[3];
    if (!begin_transform(p, line, keyword) || !read_point(p, line, "the rotation axis", axis, offsets) ||
        !read_number(p, line, "the rotation angle in degrees", &degrees, NULL) ||
        !expect_end_of_line(p, line, "the rotation"))
        return false;
    /* Divide by the largest component first, so that tiny axes do not underflow. */
    double largest = fmax(fabs(axis[0]), fmax(fabs(axis[1]), fabs(axis[2])));
    if (largest == 0)
        return fail_at(p, line, offsets[0], "the rotation axis (0 0 0) has zero length, so it has no direction");
    double unit[3], length = 0;
    for (int i = 0; i < 3; i++) {
        unit[i] = axis[i] / largest;
        length += unit[i] * unit[i];
    }
    length = sqrt(length);
    for (int i = 0; i < 3; i++)
        unit[i] /= length;
    affine rotation = affine_rotation(unit, degrees);
    append_transform(p, &rotation);
    return true;
}

/* scale S | scale SX SY SZ: about the origin; negative factors mirror, 0 is an error. */
static bool statement_scale(parser *p, source_line *line, const token *keyword)
{
    double factors[3];
    size_t offsets[3];
    token next = {.kind = TOKEN_END};
    if (!begin_transform(p, line, keyword) || !read_number(p, line, "the scale", &factors[0], &offsets[0]) ||
        !peek_token(p, line, &next))
        return false;
    if (next.kind == TOKEN_END) {
        factors[1] = factors[2] = factors[0];
        offsets[1] = offsets[2] = offsets[0];
    } else if (!read_number(p, line, "the scale y", &factors[1], &offsets[1]) ||
               !read_number(p, line, "the scale z", &factors[2], &offsets[2]) ||
               !expect_end_of_line(p, line, "the scale")) {
        return false;
    }
    affine scale = affine_identity();
    char number[40];
    for (int i = 0; i < 3; i++) {
        float as_float = 0;
        if (!to_float(p, line, offsets[i], "the scale", factors[i], &as_float))
            return false;
        if (factors[i] == 0)
            return fail_at(p, line, offsets[i], "the scale must not be 0 on any axis (it would flatten the "
                           "contents), found 0");
        if (as_float == 0)
            return fail_at(p, line, offsets[i], "the scale %s is too small for the renderer's 32-bit floats",
                           format_number(number, sizeof number, factors[i]));
        scale.m[i][i] = factors[i];
    }
    append_transform(p, &scale);
    return true;
}

/* matrix M00 M01 M02 M03  M10 .. M13  M20 .. M23: row-major 3x4, world = M p. */
static bool statement_matrix(parser *p, source_line *line, const token *keyword)
{
    if (!begin_transform(p, line, keyword))
        return false;
    affine matrix;
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 4; column++) {
            char what[DESCRIPTION_BUFFER];
            snprintf(what, sizeof what, "the matrix element M%d%d", row, column);
            size_t offset = 0;
            float unused;
            if (!read_number(p, line, what, &matrix.m[row][column], &offset) ||
                !to_float(p, line, offset, what, matrix.m[row][column], &unused))
                return false;
        }
    }
    if (!expect_end_of_line(p, line, "the matrix"))
        return false;
    double determinant = affine_determinant(&matrix);
    if (!(fabs(determinant) >= 1e-12))
        return fail_at(p, line, keyword->offset, "the matrix is singular (the determinant of its 3x3 part is %g); a "
                       "transform must be invertible", determinant);
    append_transform(p, &matrix);
    return true;
}

/* ------------------------------------------------------------------ shapes */

/* Reads the optional MATERIAL that ends a shape statement for owner ("the sphere"; users
 * is "spheres"), then the end of the line. Inside a block it may be left out (*material
 * -1: the enclosing group's applies); at the top level nothing could supply it. */
static bool read_shape_material(parser *p, source_line *line, const char *owner, const char *users, int *material)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(p, line, &t))
        return false;
    if (t.kind == TOKEN_END) {
        if (p->block_count == 1)
            return fail_at(p, line, t.offset, "expected a material name for %s, found end of line (a shape needs a "
                           "material outside a group)", owner);
        *material = -1;
        return true;
    }
    return material_from_token(p, line, &t, owner, users, material) && expect_end_of_line(p, line, owner);
}

/* Reads the radius of owner ("the sphere"): > 0, and not 0 as a float either. */
static bool read_radius(parser *p, source_line *line, const char *owner, float *radius)
{
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "%s's radius", owner);
    double value = 0;
    size_t offset = 0;
    char number[40];
    if (!read_number(p, line, what, &value, &offset))
        return false;
    if (!(value > 0))
        return fail_at(p, line, offset, "%s must be > 0, found %s", what, format_number(number, sizeof number, value));
    if (!to_float(p, line, offset, what, value, radius))
        return false;
    if (*radius == 0)
        return fail_at(p, line, offset, "%s %s is too small for the renderer's 32-bit floats", what,
                       format_number(number, sizeof number, value));
    return true;
}

/* sphere X Y Z RADIUS [MATERIAL]: at the top level one of the scene's plain spheres (as in
 * the first version of the format), inside a block a shape of the block's object. */
static bool statement_sphere(parser *p, source_line *line, const token *keyword)
{
    float center[3], radius = 0;
    int material = -1;
    if (!read_vector(p, line, "the sphere's center", center, NULL) || !read_radius(p, line, "the sphere", &radius) ||
        !read_shape_material(p, line, "the sphere", "spheres", &material))
        return false;
    if (p->block_count == 1) {
        scene_sphere sphere = {.center = {center[0], center[1], center[2]}, .radius = radius, .material = material};
        return scene_add_sphere(p->scene, &sphere) >= 0 || fail_out_of_memory(p);
    }
    scene_shape shape = {.type = SHAPE_SPHERE, .material = material, .radius = radius};
    memcpy(shape.points[0], center, sizeof center);
    source_position where = position_in(line, keyword->offset);
    return add_block_shape(p, &shape, &where);
}

/* moving_sphere X0 Y0 Z0  X1 Y1 Z1  RADIUS [MATERIAL]: centres at time 0 and time 1. */
static bool statement_moving_sphere(parser *p, source_line *line, const token *keyword)
{
    scene_shape shape = {.type = SHAPE_MOVING_SPHERE};
    if (!read_vector(p, line, "the moving sphere's centre at time 0", shape.points[0], NULL) ||
        !read_vector(p, line, "the moving sphere's centre at time 1", shape.points[1], NULL) ||
        !read_radius(p, line, "the moving sphere", &shape.radius) ||
        !read_shape_material(p, line, "the moving sphere", "moving spheres", &shape.material))
        return false;
    source_position where = position_in(line, keyword->offset);
    return add_block_shape(p, &shape, &where);
}

/* Reads the three corner normals of the triangle's `normals` clause into shape: each three
 * numbers (finite, within the float range), not all zero, stored at unit length. */
static bool read_triangle_normals(parser *p, source_line *line, scene_shape *shape)
{
    static const char *const corners[3] = {"first", "second", "third"};
    for (int k = 0; k < 3; k++) {
        char owner[DESCRIPTION_BUFFER];
        snprintf(owner, sizeof owner, "the triangle's %s normal", corners[k]);
        double normal[3];
        size_t offsets[3];
        if (!read_point(p, line, owner, normal, offsets))
            return false;
        if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0)
            return fail_at(p, line, offsets[0], "%s is zero (0 0 0), so it has no direction (a normal needs a "
                           "length > 0; it is made unit length)", owner);
        normalise_into(normal, shape->normals[k]);
    }
    shape->has_normals = true;
    return true;
}

/* Reads the three corner texture coordinates of the triangle's `uvs` clause into shape. */
static bool read_triangle_uvs(parser *p, source_line *line, scene_shape *shape)
{
    static const char *const corners[3] = {"first", "second", "third"};
    static const char *const axes[2] = {"u", "v"};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < 2; i++) {
            char what[DESCRIPTION_BUFFER];
            snprintf(what, sizeof what, "the triangle's %s uv %s", corners[k], axes[i]);
            if (!read_float(p, line, what, &shape->uvs[k][i], NULL))
                return false;
        }
    }
    shape->has_uvs = true;
    return true;
}

/* True when token t of line is the name of a material defined so far. */
static bool names_material(parser *p, const source_line *line, const token *t)
{
    char name[SCENE_NAME_MAX];
    if (t->kind != TOKEN_WORD || t->length >= SCENE_NAME_MAX)
        return false;
    memcpy(name, line->text + t->offset, t->length);
    name[t->length] = '\0';
    return scene_find_material(p->scene, name) >= 0;
}

/* Reads the next token of line into *t without consuming it; true when nothing but a
 * comment follows it (the last word of a statement). */
static bool is_last_word(parser *p, source_line *line, token *t)
{
    size_t cursor = line->cursor, last_token_end = line->last_token_end;
    token after = {.kind = TOKEN_END};
    bool ok = next_token(p, line, t) && next_token(p, line, &after);
    line->cursor = cursor;
    line->last_token_end = last_token_end;
    return ok && after.kind == TOKEN_END;
}

/* triangle X Y Z  X Y Z  X Y Z [normals NX NY NZ  NX NY NZ  NX NY NZ] [uvs U V  U V  U V]
 * [MATERIAL]: counter-clockwise seen from the front; the clauses in either order, each at
 * most once. A clause word that ends the line is the material when a material of that
 * name is defined (so a scene whose material is called `normals` reads as it did). */
static bool statement_triangle(parser *p, source_line *line, const token *keyword)
{
    scene_shape shape = {.type = SHAPE_TRIANGLE};
    if (!read_vector(p, line, "the triangle's first corner", shape.points[0], NULL) ||
        !read_vector(p, line, "the triangle's second corner", shape.points[1], NULL) ||
        !read_vector(p, line, "the triangle's third corner", shape.points[2], NULL))
        return false;
    static const char *const clauses[] = {"normals", "uvs"};
    size_t first_offsets[2] = {SIZE_MAX, SIZE_MAX};
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!peek_token(p, line, &t))
            return false;
        if (!token_is(line, &t, clauses[0]) && !token_is(line, &t, clauses[1]))
            break;
        token word = {.kind = TOKEN_END};
        if (is_last_word(p, line, &word) && names_material(p, line, &t))
            break;
        int clause = -1;
        if (!next_token(p, line, &t) || !match_clause(p, line, &t, "triangle", clauses, 2, first_offsets, &clause))
            return false;
        if (!(clause == 0 ? read_triangle_normals(p, line, &shape) : read_triangle_uvs(p, line, &shape)))
            return false;
    }
    /* A word that is followed by more and names no material is a misspelt clause. */
    token t = {.kind = TOKEN_END}, word = {.kind = TOKEN_END};
    if (!peek_token(p, line, &t))
        return false;
    if (t.kind == TOKEN_WORD && !is_last_word(p, line, &word) && !names_material(p, line, &t)) {
        char found[QUOTE_BUFFER + 16];
        return fail_at(p, line, t.offset, "unknown triangle clause %s (expected normals or uvs, or a material "
                       "defined earlier as the last word)", describe_token(line, &t, found, sizeof found));
    }
    if (!read_shape_material(p, line, "the triangle", "triangles", &shape.material))
        return false;
    source_position where = position_in(line, keyword->offset);
    return add_block_shape(p, &shape, &where);
}

/* quad QX QY QZ  UX UY UZ  VX VY VZ [MATERIAL]: the parallelogram Q + a u + b v. */
static bool statement_quad(parser *p, source_line *line, const token *keyword)
{
    scene_shape shape = {.type = SHAPE_QUAD};
    size_t edge_offsets[3];
    if (!read_vector(p, line, "the quad's corner", shape.points[0], NULL) ||
        !read_vector(p, line, "the quad's edge u", shape.points[1], edge_offsets) ||
        !read_vector(p, line, "the quad's edge v", shape.points[2], NULL) ||
        !read_shape_material(p, line, "the quad", "quads", &shape.material))
        return false;
    const float *u = shape.points[1], *v = shape.points[2];
    double cross[3] = {
        (double)u[1] * v[2] - (double)u[2] * v[1],
        (double)u[2] * v[0] - (double)u[0] * v[2],
        (double)u[0] * v[1] - (double)u[1] * v[0],
    };
    double cross_length = sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    double u_length = sqrt((double)u[0] * u[0] + (double)u[1] * u[1] + (double)u[2] * u[2]);
    double v_length = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
    /* Relative test, as for the camera: the sine of the angle between the edges. */
    if (!(cross_length > 1e-6 * u_length * v_length))
        return fail_at(p, line, edge_offsets[0], "the quad's edges u (%g %g %g) and v (%g %g %g) are parallel or "
                       "zero, so it has no area", u[0], u[1], u[2], v[0], v[1], v[2]);
    source_position where = position_in(line, keyword->offset);
    return add_block_shape(p, &shape, &where);
}

/* box X0 Y0 Z0  X1 Y1 Z1 [MATERIAL]: axis-aligned, from the minimum to the maximum corner;
 * six quads with outward normals (u x v), in the order +X -X +Y -Y +Z -Z. */
static bool statement_box(parser *p, source_line *line, const token *keyword)
{
    static const char *const axes[3] = {"x", "y", "z"};
    float low[3], high[3], size[3];
    size_t high_offsets[3];
    int material = -1;
    if (!read_vector(p, line, "the box's minimum corner", low, NULL) ||
        !read_vector(p, line, "the box's maximum corner", high, high_offsets) ||
        !read_shape_material(p, line, "the box", "boxes", &material))
        return false;
    for (int i = 0; i < 3; i++) {
        if (!(low[i] < high[i]))
            return fail_at(p, line, high_offsets[i], "the box's minimum %s (%g) must be less than its maximum %s (%g)",
                           axes[i], low[i], axes[i], high[i]);
        size[i] = high[i] - low[i];
        if (!isfinite(size[i]))
            return fail_at(p, line, high_offsets[i], "the box's size along %s is too large for the renderer's "
                           "32-bit floats", axes[i]);
    }
    source_position where = position_in(line, keyword->offset);
    for (int axis = 0; axis < 3; axis++) {
        /* With b, c the next axes in cyclic order, e_b x e_c = e_axis: the + face takes
         * edges (b, c), the - face (c, b). */
        int b = (axis + 1) % 3, c = (axis + 2) % 3;
        for (int side = 0; side < 2; side++) {
            scene_shape quad = {.type = SHAPE_QUAD, .material = material};
            memcpy(quad.points[0], low, sizeof low);
            if (side == 0)
                quad.points[0][axis] = high[axis];
            quad.points[1][side == 0 ? b : c] = size[side == 0 ? b : c];
            quad.points[2][side == 0 ? c : b] = size[side == 0 ? c : b];
            if (!add_block_shape(p, &quad, &where))
                return false;
        }
    }
    return true;
}

/* mesh "FILE.obj" [MATERIAL]: one instance of the mesh's object (one per resolved path,
 * however often it is placed); the asset loader reads the file later. */
static bool statement_mesh(parser *p, source_line *line, const token *keyword)
{
    char *path = NULL;
    size_t offset = 0;
    int material = -1;
    if (!read_asset_path(p, line, "the mesh", &path, &offset))
        return false;
    if (!read_shape_material(p, line, "the mesh", "meshes", &material)) {
        free(path);
        return false;
    }
    scene *s = p->scene;
    int mesh = 0;
    while (mesh < s->mesh_count && strcmp(s->meshes[mesh].path, path) != 0)
        mesh++;
    if (mesh == s->mesh_count) {
        scene_mesh added;
        memset(&added, 0, sizeof added);
        memcpy(added.path, path, strlen(path) + 1);
        source_position named = position_in(line, offset);
        format_position(added.position, sizeof added.position, &named);
        added.default_material = -1;
        scene_object object = {.first_shape = 0, .shape_count = 0, .mesh = mesh};
        free(path);
        path = NULL;
        if (scene_add_mesh(s, &added) < 0)
            return fail_out_of_memory(p);
        int object_index = scene_add_object(s, &object);
        if (object_index < 0)
            return fail_out_of_memory(p);
        if (!grow_array(p, (void **)&p->mesh_objects, mesh, &p->mesh_object_capacity, sizeof *p->mesh_objects))
            return false;
        p->mesh_objects[mesh] = object_index;
    }
    free(path);
    placement local = {.object = p->mesh_objects[mesh], .transform = affine_identity(), .material = material};
    source_position where = position_in(line, keyword->offset);
    return place_object(p, &local, &where);
}

/* ------------------------------------------------------------------ blocks */

/* Reads the optional `material MATERIAL` clause of a group or instance line: t holds the
 * token after the name and is advanced past the clause. */
static bool read_block_material(parser *p, source_line *line, token *t, const char *owner, const char *users,
                                int *material)
{
    *material = -1;
    if (!token_is(line, t, "material"))
        return true;
    token name = {.kind = TOKEN_END};
    return lex_token(p, line, &name, true) && material_from_token(p, line, &name, owner, users, material) &&
           lex_token(p, line, t, true);
}

/* Checks that t is the '{' that ends the opening line of a block (what: "the group line"). */
static bool expect_open_brace(parser *p, source_line *line, const token *t, const char *what)
{
    char found[QUOTE_BUFFER + 16];
    if (t->kind != TOKEN_OPEN_BRACE)
        return fail_at(p, line, t->offset, "expected '{' at the end of %s, found %s", what,
                       describe_token(line, t, found, sizeof found));
    return expect_end_of_line(p, line, "'{' (a block's '{' ends its line)");
}

/* group [NAME] [material MATERIAL] {: opens a block whose contents share its transforms
 * and material; a named group can be placed again with `instance NAME`. */
static bool statement_group(parser *p, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!lex_token(p, line, &t, true))
        return false;
    char name[SCENE_NAME_MAX] = "";
    source_position named = {0};
    if (t.kind == TOKEN_WORD && !token_is(line, &t, "material")) {
        if (!name_from_token(p, line, &t, "group", name))
            return false;
        int existing = find_group(p, name);
        if (existing >= 0) {
            const source_position *first = &p->groups[existing].position;
            return fail_at(p, line, t.offset, "group '%s' is already defined at %s:%d:%zu", name, first->path,
                           first->line, first->column);
        }
        named = position_in(line, t.offset);
        if (!lex_token(p, line, &t, true))
            return false;
    }
    int material = -1;
    if (!read_block_material(p, line, &t, "the group", "groups", &material) ||
        !expect_open_brace(p, line, &t, "the group line") || !open_block(p, line, keyword, BLOCK_GROUP, false))
        return false;
    block *b = current_block(p);
    b->material = material;
    if (name[0] == '\0')
        return true;
    if (!grow_array(p, (void **)&p->groups, p->group_count, &p->group_capacity, sizeof *p->groups))
        return false;
    named_group *group = &p->groups[p->group_count];
    *group = (named_group){.position = named, .open = true};
    memcpy(group->name, name, sizeof group->name);
    b->group = p->group_count++;
    return true;
}

/* instance NAME [material MATERIAL] [{ transforms }]: places every object the named group
 * placed again, with the block's transforms; MATERIAL fills what has no material yet. */
static bool statement_instance(parser *p, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(p, line, &t))
        return false;
    if (t.kind == TOKEN_END)
        return fail_at(p, line, t.offset, "expected a group name after instance, found end of line");
    char name[SCENE_NAME_MAX];
    if (!name_from_token(p, line, &t, "group", name))
        return false;
    int group = find_group(p, name);
    if (group < 0)
        return fail_at(p, line, t.offset, "unknown group '%s' (a group must be defined with group %s { ... } before "
                       "it is instanced)", name, name);
    if (p->groups[group].open)
        return fail_at(p, line, t.offset, "group '%s' is still open: a group cannot contain an instance of itself",
                       name);
    int material = -1;
    if (!lex_token(p, line, &t, true) ||
        !read_block_material(p, line, &t, "the instance", "instances", &material))
        return false;
    if (t.kind == TOKEN_END) {
        /* No braces: an implicit instance block with no transform, closed at once. */
        if (!open_block(p, line, keyword, BLOCK_INSTANCE, true))
            return false;
        current_block(p)->material = material;
        bool placed = place_group(p, group, &current_block(p)->opened);
        pop_block(p);
        return placed;
    }
    if (!expect_open_brace(p, line, &t, "the instance line (or end of line)") ||
        !open_block(p, line, keyword, BLOCK_INSTANCE, false))
        return false;
    current_block(p)->material = material;
    current_block(p)->instance_of = group;
    return true;
}

/* volume DENSITY R G B {: a constant medium whose boundary is the block's contents. */
static bool statement_volume(parser *p, source_line *line, const token *keyword)
{
    static const char *const channels[3] = {"red", "green", "blue"};
    double value = 0;
    size_t offset = 0;
    char number[40];
    float density = 0, albedo[3];
    if (!read_number(p, line, "the volume's density", &value, &offset))
        return false;
    if (!(value > 0))
        return fail_at(p, line, offset, "the volume's density must be > 0, found %s",
                       format_number(number, sizeof number, value));
    if (!to_float(p, line, offset, "the volume's density", value, &density))
        return false;
    if (density == 0)
        return fail_at(p, line, offset, "the volume's density %s is too small for the renderer's 32-bit floats",
                       format_number(number, sizeof number, value));
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s component of the volume's albedo", channels[i]);
        if (!read_number(p, line, what, &value, &offset))
            return false;
        if (!(value >= 0 && value <= 1))
            return fail_at(p, line, offset, "%s must be between 0 and 1, found %s", what,
                           format_number(number, sizeof number, value));
        albedo[i] = (float)value;
    }
    token t = {.kind = TOKEN_END};
    if (!lex_token(p, line, &t, true) || !expect_open_brace(p, line, &t, "the volume line") ||
        !open_block(p, line, keyword, BLOCK_VOLUME, false))
        return false;
    block *b = current_block(p);
    b->density = density;
    memcpy(b->albedo, albedo, sizeof b->albedo);
    return true;
}

/* }: closes the current block, which the same file must have opened. An instance block
 * now places its group; a group or volume moves its shapes into the scene. */
static bool statement_close(parser *p, source_line *line, const token *brace)
{
    if (p->block_count == 1)
        return fail_at(p, line, brace->offset, "unexpected '}' (no block is open)");
    block *b = current_block(p);
    if (b->file != line->file)
        return fail_at(p, line, brace->offset, "unexpected '}': this file opened no block (the open %s was opened "
                       "at %s:%d:%zu; a block must be closed in the file that opens it)", block_noun(b->kind),
                       b->opened.path, b->opened.line, b->opened.column);
    if (!expect_end_of_line(p, line, "'}' (a '}' stands alone on its line)"))
        return false;
    if (b->kind == BLOCK_INSTANCE) {
        if (!place_group(p, b->instance_of, &b->opened))
            return false;
    } else {
        if (!flush_block_shapes(p, b))
            return false;
        if (b->group >= 0)
            p->groups[b->group].open = false;
    }
    pop_block(p);
    return true;
}

/* ------------------------------------------------------------------ lines and files */

typedef bool (*statement_parser)(parser *p, source_line *line, const token *keyword);

/* The statements, by their first word. Transforms and include do not count as a block's
 * content (transforms must come first; an include's own statements count). */
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
    {"group", statement_group, true},
    {"instance", statement_instance, true},
    {"volume", statement_volume, true},
    {"translate", statement_translate, false},
    {"rotate", statement_rotate, false},
    {"scale", statement_scale, false},
    {"matrix", statement_matrix, false},
};

/* Parses one line: checks its bytes, then dispatches on the first word (or brace). */
static bool parse_statement(parser *p, source_line *line)
{
    if (!check_line_bytes(p, line))
        return false;
    token keyword = {.kind = TOKEN_END};
    if (!lex_token(p, line, &keyword, true))
        return false;
    if (keyword.kind == TOKEN_END)
        return true;
    if (keyword.kind == TOKEN_CLOSE_BRACE)
        return statement_close(p, line, &keyword);
    if (keyword.kind == TOKEN_OPEN_BRACE)
        return fail_at(p, line, keyword.offset, "unexpected '{' (only a group, instance or volume line ends with '{')");
    for (size_t i = 0; i < sizeof statements / sizeof statements[0]; i++) {
        if (!token_is(line, &keyword, statements[i].keyword))
            continue;
        if (statements[i].is_content && !begin_content(p, line, &keyword))
            return false;
        return statements[i].parse(p, line, &keyword);
    }
    char found[QUOTE_BUFFER + 16];
    return fail_at(p, line, keyword.offset, "unknown statement %s (expected include, set, camera, render, sky, "
                   "ambient, light, texture, material, sphere, moving_sphere, triangle, quad, box, mesh, group, "
                   "instance, volume, translate, rotate, scale or matrix)",
                   describe_token(line, &keyword, found, sizeof found));
}

/* Parses every line of file in order; the file must close every block it opens. */
static bool parse_source(parser *p, const source_file *file)
{
    int open_before = p->block_count;
    size_t start = 0;
    /* A UTF-8 byte order mark is an editor's artefact, not part of the first keyword. */
    if (file->length >= 3 && memcmp(file->text, "\xEF\xBB\xBF", 3) == 0)
        start = 3;
    int number = 1;
    for (;;) {
        const char *newline = memchr(file->text + start, '\n', file->length - start);
        size_t end = newline != NULL ? (size_t)(newline - file->text) : file->length;
        source_line line = {
            .file = file, .text = file->text + start, .length = end - start, .number = number,
        };
        if (!parse_statement(p, &line))
            return false;
        if (newline == NULL)
            break;
        start = end + 1;
        number++;
    }
    if (p->block_count == open_before)
        return true;
    const block *unclosed = current_block(p);
    return fail_at_position(p, &unclosed->opened, "this %s is never closed (expected a '}' on a line of its own "
                            "before the end of %s)", block_noun(unclosed->kind), file->path);
}

/* ------------------------------------------------------------------ whole scene */

/* Evaluates the -D defines before the file is read, so that they exist from line 1. */
static bool apply_defines(parser *p)
{
    const scene_parse_options *options = p->options;
    for (int i = 0; i < options->define_count; i++) {
        const scene_define *define = &options->defines[i];
        const char *name = define->name != NULL ? define->name : "";
        if (!expression_is_variable_name(name, strlen(name)))
            return fail_without_position(p, "-D %s=%s: '%s' is not a valid variable name (letters, digits and '_', "
                                         "not starting with a digit)", name, define->value ? define->value : "",
                                         name);
        if (define->value == NULL)
            return fail_without_position(p, "-D %s: missing value (write -D %s=VALUE)", name, name);
        rt_error expression_error;
        int column = 0;
        double value = 0;
        /* Columns count in "NAME=VALUE", the text the user typed after -D. */
        if (expression_evaluate(define->value, strlen(define->value), (int)strlen(name) + 2, NULL, NULL, &value,
                                &column, &expression_error) != RT_OK)
            return fail_without_position(p, "-D %s=%s: column %d: %s", name, define->value, column,
                                         expression_error.message);
        variable *target = find_or_add_variable(p, name, strlen(name));
        if (target == NULL)
            return false;
        target->value = value;
        target->has_value = true;
        target->from_define = true;
    }
    return true;
}

/* The checks that need the whole scene: a -D that nothing mentions, and a camera whose
 * final from/at/up (clauses may come from several statements) has no valid frame. */
static bool check_finished_scene(parser *p)
{
    for (int i = 0; i < p->options->define_count; i++) {
        const char *name = p->options->defines[i].name;
        variable *defined = find_variable(p, name, strlen(name));
        if (p->options->defines[i].optional)
            continue;
        if (defined == NULL || !defined->mentioned)
            return fail_without_position(p, "-D %s: the scene never sets or uses $%s", name, name);
    }
    if (!p->camera_seen)
        return true;
    const scene_camera *camera = &p->scene->camera;
    double direction[3], up[3];
    for (int i = 0; i < 3; i++) {
        direction[i] = (double)camera->look_at[i] - camera->look_from[i];
        up[i] = camera->up[i];
    }
    if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0)
        return fail_at_position(p, &p->last_camera, "the camera's from and at are the same point (%g %g %g), "
                                "so it has no view direction", camera->look_from[0], camera->look_from[1],
                                camera->look_from[2]);
    double cross[3] = {
        direction[1] * up[2] - direction[2] * up[1],
        direction[2] * up[0] - direction[0] * up[2],
        direction[0] * up[1] - direction[1] * up[0],
    };
    double cross_length = sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    double direction_length = sqrt(direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
    double up_length = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    /* Relative test: the sine of the angle between them, well above float rounding. */
    if (up_length == 0 || cross_length <= 1e-6 * direction_length * up_length)
        return fail_at_position(p, &p->last_camera, "the camera's up (%g %g %g) is parallel to its view direction "
                                "(%g %g %g); choose an up that is not", up[0], up[1], up[2], direction[0],
                                direction[1], direction[2]);
    return true;
}

/* Every surface needs a material: a shape without its own takes its instance's, which is
 * -1 when no enclosing group (or instance statement) gave one. A volume's boundary needs
 * none, and a mesh may carry its own (the loader reads usemtl), so only shapes count. */
static bool check_shape_materials(parser *p)
{
    const scene *s = p->scene;
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        if (instance->volume || instance->material >= 0)
            continue;
        const scene_object *object = &s->objects[instance->object];
        for (int k = object->first_shape; k < object->first_shape + object->shape_count; k++)
            if (s->shapes[k].material < 0)
                return fail_at_position(p, &p->shape_positions[k], "this shape has no material: give it one, or "
                                        "give a group around it (or the instance that places it) a material");
    }
    return true;
}

/* A volume's boundary must be closed: crossing it is how a ray enters and leaves the
 * medium. Whether a set of surfaces is closed is not cheap to know in general, but the flat
 * shapes (triangles and quads) of one boundary object can only be closed among themselves
 * (a sphere's curved surface never meets a straight edge), and no closed surface is made
 * of fewer than 4 flat faces: so 1 to 3 of them in a volume's object are an open surface
 * for certain (the common mistake: a single quad or triangle). Meshes are checked by the
 * asset loader, which knows their triangles. */
static bool check_volume_boundaries(parser *p)
{
    const scene *s = p->scene;
    for (int i = 0; i < s->instance_count; i++) {
        if (!s->instances[i].volume)
            continue;
        const scene_object *object = &s->objects[s->instances[i].object];
        int flat = 0, first_flat = -1;
        for (int k = object->first_shape; k < object->first_shape + object->shape_count; k++) {
            if (s->shapes[k].type != SHAPE_TRIANGLE && s->shapes[k].type != SHAPE_QUAD)
                continue;
            if (first_flat < 0)
                first_flat = k;
            flat++;
        }
        if (flat == 0 || flat >= 4)
            continue;
        const char *noun = s->shapes[first_flat].type == SHAPE_QUAD ? "quad" : "triangle";
        if (flat == 1)
            return fail_at_position(p, &p->shape_positions[first_flat], "this %s is the only flat surface of a "
                                    "volume's boundary, which must be closed: one %s encloses nothing (use a box, a "
                                    "sphere or a closed mesh, or put the %s outside the volume)", noun, noun, noun);
        return fail_at_position(p, &p->shape_positions[first_flat], "this %s is one of only %d flat surfaces "
                                "(triangles and quads) of a volume's boundary, which must be closed: fewer than 4 "
                                "flat faces enclose nothing (use a box, a sphere or a closed mesh)", noun, flat);
    }
    return true;
}

/* Shared end of both entry points: parses top (whose text the caller owns) and frees
 * everything on failure, leaving *out as scene_defaults(). */
static rt_status parse_scene(parser *p, const source_file *top)
{
    bool ok = apply_defines(p) && parse_source(p, top) && flush_block_shapes(p, &p->blocks[0]) &&
              check_finished_scene(p) && check_shape_materials(p) && check_volume_boundaries(p);
    parser_free(p);
    if (!ok) {
        scene_free(p->scene);
        return p->status;
    }
    return RT_OK;
}

scene_parse_options scene_parse_options_defaults(void)
{
    return (scene_parse_options){0};
}

/* Starts a parse into out (set to scene_defaults()); options NULL means all defaults. */
static void parser_init(parser *p, const scene_parse_options *options, scene *out, rt_error *error)
{
    static const scene_parse_options defaults = {0};
    *p = (parser){.scene = out, .options = options != NULL ? options : &defaults, .error = error,
                  .status = RT_OK};
    p->max_include_depth = p->options->max_include_depth > 0 ? p->options->max_include_depth
                                                             : DEFAULT_MAX_INCLUDE_DEPTH;
    p->blocks[0] = (block){
        .kind = BLOCK_TOP_LEVEL, .transform = affine_identity(), .material = -1, .group = -1,
        .instance_of = -1, .object = -1,
    };
    p->block_count = 1;
    scene_defaults(out);
}

rt_status scene_load_file(const char *path, const scene_parse_options *options, scene *out, rt_error *error)
{
    if (out == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "SCENE: scene_load_file needs an output scene");
    if (path == NULL) {
        scene_defaults(out);
        return rt_error_set(error, RT_ERROR_INPUT, "SCENE: no scene file given");
    }
    parser p;
    parser_init(&p, options, out, error);
    const char *kept_path = keep_path(&p, copy_text(path, strlen(path)));
    if (kept_path == NULL) {
        fail_out_of_memory(&p);
        parser_free(&p);
        return p.status;
    }
    char *text = NULL;
    size_t length = 0;
    struct stat info;
    int failure = read_whole_file(path, &text, &length, &info);
    if (failure != 0) {
        parser_free(&p);
        return rt_error_set(error, failure == ENOMEM ? RT_ERROR_RUNTIME : RT_ERROR_INPUT,
                            "SCENE: cannot read '%s': %s", path, strerror(failure));
    }
    source_file top = {
        .path = kept_path, .text = text, .length = length, .has_identity = true,
        .device = info.st_dev, .inode = info.st_ino,
    };
    rt_status status = parse_scene(&p, &top);
    free(text);
    return status;
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
    if (source_name == NULL)
        source_name = "<string>";
    parser p;
    parser_init(&p, options, out, error);
    const char *kept_name = keep_path(&p, copy_text(source_name, strlen(source_name)));
    if (kept_name == NULL) {
        fail_out_of_memory(&p);
        parser_free(&p);
        return p.status;
    }
    source_file top = {.path = kept_name, .text = text, .length = strlen(text)};
    return parse_scene(&p, &top);
}
