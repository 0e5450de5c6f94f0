/* scene_parse.c: see scene_parse.h; the format is documented in docs/scene-format.md.
 *
 * The whole file is read into memory and cut into lines; each line is one statement,
 * lexed on demand (so that `set` can take the raw rest of its line as an expression).
 * Every failure formats its message once, at the place that finds it, and then every
 * caller just returns false up to scene_load_*, which frees everything. */
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

/* How much of a bad token a message quotes; enough to recognise it, not a whole line. */
#define QUOTE_LIMIT 40
#define QUOTE_BUFFER (QUOTE_LIMIT + 8)
#define DESCRIPTION_BUFFER 160
#define OWNER_BUFFER 96

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

/* Frees what the parser owns (variables, paths, positions); never the scene. */
static void parser_free(parser *p)
{
    for (int i = 0; i < p->variable_count; i++)
        free(p->variables[i].name);
    free(p->variables);
    for (int i = 0; i < p->path_count; i++)
        free(p->paths[i]);
    free(p->paths);
    free(p->material_positions);
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
 * of the line and the expression evaluator reports it. Returns false on a lexical error
 * (unterminated string, reserved brace). At the end of the line (or a comment) it keeps
 * returning TOKEN_END. */
static bool next_token(parser *p, source_line *line, token *t)
{
    while (line->cursor < line->length && is_space(line->text[line->cursor]))
        line->cursor++;
    if (line->cursor == line->length || line->text[line->cursor] == '#') {
        *t = (token){.kind = TOKEN_END, .offset = line->last_token_end};
        return true;
    }
    size_t start = line->cursor;
    char c = line->text[start];
    if (c == '{' || c == '}')
        return fail_at(p, line, start, "unexpected '%c' (braces are reserved for a later version of the format)", c);
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

/* Reads three numbers x y z for owner (e.g. "the camera's from"). */
static bool read_vector(parser *p, source_line *line, const char *owner, float out[3])
{
    static const char *const axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "%s %s", owner, axes[i]);
        if (!read_float(p, line, what, &out[i], NULL))
            return false;
    }
    return true;
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
static bool statement_set(parser *p, source_line *line)
{
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

/* camera [from X Y Z] [at X Y Z] [up X Y Z] [fov D] [aperture A] [focus D]; the frame is
 * checked once the whole scene is read (check_finished_scene). */
static bool statement_camera(parser *p, source_line *line, const token *keyword)
{
    static const char *const clauses[] = {"from", "at", "up", "fov", "aperture", "focus"};
    size_t first_offsets[6] = {SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX};
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
        if (!match_clause(p, line, &t, "camera", clauses, 6, first_offsets, &clause))
            return false;
        double value = 0;
        size_t offset = 0;
        char number[40];
        switch (clause) {
        case 0:
            if (!read_vector(p, line, "the camera's from", camera->look_from))
                return false;
            break;
        case 1:
            if (!read_vector(p, line, "the camera's at", camera->look_at))
                return false;
            break;
        case 2:
            if (!read_vector(p, line, "the camera's up", camera->up))
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
        default:
            if (!read_number(p, line, "the camera's focus distance", &value, &offset))
                return false;
            if (value < 0)
                return fail_at(p, line, offset, "the camera's focus distance must be >= 0 (0 means the "
                               "distance to 'at'), found %s", format_number(number, sizeof number, value));
            if (!to_float(p, line, offset, "the camera's focus distance", value, &camera->focus_distance))
                return false;
            break;
        }
    }
}

/* render [size W H] [spp N] [depth N] [seed N]. */
static bool statement_render(parser *p, source_line *line)
{
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

/* sky gradient R G B R G B | sky constant R G B; the last sky statement wins. */
static bool statement_sky(parser *p, source_line *line)
{
    token type = {.kind = TOKEN_END};
    if (!next_token(p, line, &type))
        return false;
    scene_sky sky = p->scene->sky;
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
    } else {
        char found[QUOTE_BUFFER + 16];
        return fail_at(p, line, type.offset, "expected a sky type (gradient or constant), found %s",
                       describe_token(line, &type, found, sizeof found));
    }
    if (!expect_end_of_line(p, line, "the sky"))
        return false;
    p->scene->sky = sky;
    return true;
}

/* Material names are plain words so that a sphere line stays easy to read and a name
 * can never be mistaken for a number, a $variable or an expression. */
static bool is_material_name(const char *text, size_t length)
{
    for (size_t i = 0; i < length; i++) {
        char c = text[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
              c == '.'))
            return false;
    }
    return length > 0;
}

/* Reads the optional `[NAME VALUE]` clause of a material (fuzz or strength), which
 * may appear at most once. */
static bool read_material_clause(parser *p, source_line *line, const char *clause, const char *what,
                                 double *value, size_t *offset)
{
    size_t first_offset = SIZE_MAX;
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(p, line, &t))
            return false;
        if (t.kind == TOKEN_END)
            return true;
        int index = -1;
        if (!match_clause(p, line, &t, what, &clause, 1, &first_offset, &index))
            return false;
        char description[DESCRIPTION_BUFFER];
        snprintf(description, sizeof description, "the %s of the %s", clause, what);
        if (!read_number(p, line, description, value, offset))
            return false;
    }
}

/* material NAME lambertian R G B | metal R G B [fuzz F] | dielectric IOR |
 * emissive R G B [strength S]. Remembers where NAME was defined for duplicate errors. */
static bool statement_material(parser *p, source_line *line)
{
    token name = {.kind = TOKEN_END};
    if (!next_token(p, line, &name))
        return false;
    char found[QUOTE_BUFFER + 16];
    if (name.kind == TOKEN_END)
        return fail_at(p, line, name.offset, "expected a material name after material, found end of line");
    const char *name_text = line->text + name.offset;
    if (name.kind != TOKEN_WORD || !is_material_name(name_text, name.length))
        return fail_at(p, line, name.offset, "expected a material name (letters, digits, '_', '-' and '.'), found %s",
                       describe_token(line, &name, found, sizeof found));
    if (name.length > SCENE_NAME_MAX - 1)
        return fail_at(p, line, name.offset, "material name %s is %zu bytes long; the limit is %d",
                       describe_token(line, &name, found, sizeof found), name.length, SCENE_NAME_MAX - 1);
    scene_material material = scene_material_defaults(); material.type = MATERIAL_LAMBERTIAN;
    memcpy(material.name, name_text, name.length);
    material.name[name.length] = '\0';
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
    if (token_is(line, &type, "lambertian")) {
        material.type = MATERIAL_LAMBERTIAN;
        if (!read_colour(p, line, owner, material.albedo) || !expect_end_of_line(p, line, "a lambertian material"))
            return false;
    } else if (token_is(line, &type, "metal")) {
        material.type = MATERIAL_METAL;
        value = 0;
        if (!read_colour(p, line, owner, material.albedo) ||
            !read_material_clause(p, line, "fuzz", "metal material", &value, &offset))
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
        if (!expect_end_of_line(p, line, "a dielectric material"))
            return false;
    } else if (token_is(line, &type, "emissive")) {
        material.type = MATERIAL_EMISSIVE;
        float colour[3];
        value = 1;
        if (!read_colour(p, line, owner, colour) ||
            !read_material_clause(p, line, "strength", "emissive material", &value, &offset))
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

    if (p->scene->material_count == p->material_position_capacity) {
        int capacity = p->material_position_capacity ? p->material_position_capacity * 2 : 16;
        source_position *grown = realloc(p->material_positions, (size_t)capacity * sizeof *grown);
        if (grown == NULL)
            return fail_out_of_memory(p);
        p->material_positions = grown;
        p->material_position_capacity = capacity;
    }
    int index = scene_add_material(p->scene, &material);
    if (index < 0)
        return fail_out_of_memory(p);
    p->material_positions[index] = (source_position){
        .path = line->file->path, .line = line->number, .column = name.offset + 1,
    };
    return true;
}

/* sphere X Y Z RADIUS MATERIAL, with MATERIAL defined earlier. */
static bool statement_sphere(parser *p, source_line *line)
{
    scene_sphere sphere;
    size_t offset = 0;
    double radius = 0;
    char number[40];
    if (!read_vector(p, line, "the sphere's center", sphere.center) ||
        !read_number(p, line, "the sphere's radius", &radius, &offset))
        return false;
    if (!(radius > 0))
        return fail_at(p, line, offset, "the sphere's radius must be > 0, found %s",
                       format_number(number, sizeof number, radius));
    if (!to_float(p, line, offset, "the sphere's radius", radius, &sphere.radius))
        return false;
    if (sphere.radius == 0)
        return fail_at(p, line, offset, "the sphere's radius %s is too small for the renderer's 32-bit floats",
                       format_number(number, sizeof number, radius));
    token name = {.kind = TOKEN_END};
    if (!next_token(p, line, &name))
        return false;
    char found[QUOTE_BUFFER + 16];
    if (name.kind != TOKEN_WORD)
        return fail_at(p, line, name.offset, "expected a material name for the sphere, found %s",
                       describe_token(line, &name, found, sizeof found));
    char material_name[SCENE_NAME_MAX];
    int material = -1;
    if (name.length < SCENE_NAME_MAX) {
        memcpy(material_name, line->text + name.offset, name.length);
        material_name[name.length] = '\0';
        material = scene_find_material(p->scene, material_name);
    }
    if (material < 0)
        return fail_at(p, line, name.offset, "the sphere's material %s is not defined (a material must be "
                       "defined before the spheres that use it)", describe_token(line, &name, found, sizeof found));
    sphere.material = material;
    if (!expect_end_of_line(p, line, "the sphere"))
        return false;
    if (scene_add_sphere(p->scene, &sphere) < 0)
        return fail_out_of_memory(p);
    return true;
}

/* Parses one line: checks its bytes, then dispatches on the first word. */
static bool parse_statement(parser *p, source_line *line)
{
    if (!check_line_bytes(p, line))
        return false;
    token keyword = {.kind = TOKEN_END};
    if (!next_token(p, line, &keyword))
        return false;
    if (keyword.kind == TOKEN_END)
        return true;
    if (token_is(line, &keyword, "include"))
        return statement_include(p, line, &keyword);
    if (token_is(line, &keyword, "set"))
        return statement_set(p, line);
    if (token_is(line, &keyword, "camera"))
        return statement_camera(p, line, &keyword);
    if (token_is(line, &keyword, "render"))
        return statement_render(p, line);
    if (token_is(line, &keyword, "sky"))
        return statement_sky(p, line);
    if (token_is(line, &keyword, "material"))
        return statement_material(p, line);
    if (token_is(line, &keyword, "sphere"))
        return statement_sphere(p, line);
    char found[QUOTE_BUFFER + 16];
    return fail_at(p, line, keyword.offset, "unknown statement %s (expected include, set, camera, render, sky, "
                   "material or sphere)", describe_token(line, &keyword, found, sizeof found));
}

/* Parses every line of file in order. */
static bool parse_source(parser *p, const source_file *file)
{
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
            return true;
        start = end + 1;
        number++;
    }
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

/* Shared end of both entry points: parses top (whose text the caller owns) and frees
 * everything on failure, leaving *out as scene_defaults(). */
static rt_status parse_scene(parser *p, const source_file *top)
{
    bool ok = apply_defines(p) && parse_source(p, top) && check_finished_scene(p);
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
