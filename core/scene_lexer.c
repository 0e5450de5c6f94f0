/* scene_lexer.c: see scene_lexer.h. */
#include "scene_lexer.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "array.h"

/* The largest scene file read: far more than any real scene, and a clean error (EFBIG)
 * for a mistake such as include "/dev/zero", which would otherwise be read until memory
 * runs out. */
#define MAX_SCENE_FILE_BYTES ((size_t)256 << 20)

/* ------------------------------------------------------------------ files */

void lexer_init(scene_lexer *lexer, scene_report *report, int max_include_depth)
{
    *lexer = (scene_lexer){.report = report, .max_include_depth = max_include_depth};
}

void lexer_free(scene_lexer *lexer)
{
    for (int i = 0; i < lexer->path_count; i++)
        free(lexer->paths[i]);
    free(lexer->paths);
    lexer->paths = NULL;
    lexer->path_count = 0;
    lexer->path_capacity = 0;
}

/* Takes ownership of path (malloc'd, may be NULL) so it can be shown in messages until
 * the end; returns it, or NULL (having freed it) when memory runs out. */
static const char *keep_path(scene_lexer *lexer, char *path)
{
    if (path == NULL)
        return NULL;
    if (!array_reserve((void **)&lexer->paths, &lexer->path_capacity, (size_t)lexer->path_count + 1,
                       sizeof *lexer->paths)) {
        free(path);
        return NULL;
    }
    lexer->paths[lexer->path_count++] = path;
    return path;
}

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
        /* Room for one more byte and the NUL; array_reserve doubles the buffer. */
        if (!array_reserve((void **)&buffer, &capacity, used + 2, 1)) {
            free(buffer);
            close(descriptor);
            return ENOMEM;
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

char *resolve_relative_path(const char *includer_path, const char *text, size_t length)
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

/* Keeps path (malloc'd, or NULL when making it ran out of memory) as file->path and
 * reads the file there into file's text and identity. Returns 0, the errno of a failed
 * read, or -1 when keeping the path ran out of memory. */
static int keep_and_read(scene_lexer *lexer, char *path, source_file *file)
{
    file->path = keep_path(lexer, path);
    if (file->path == NULL)
        return -1;
    char *text = NULL;
    struct stat info;
    int failure = read_whole_file(file->path, &text, &file->length, &info);
    if (failure != 0)
        return failure;
    file->text = file->owned_text = text;
    file->has_identity = true;
    file->device = info.st_dev;
    file->inode = info.st_ino;
    return 0;
}

bool lexer_open_top_file(scene_lexer *lexer, const char *path, source_file *top)
{
    *top = (source_file){.report = lexer->report};
    int failure = keep_and_read(lexer, strdup(path), top);
    if (failure < 0)
        return fail_out_of_memory(lexer->report);
    if (failure != 0) {
        lexer->report->status = rt_error_set(lexer->report->error, failure == ENOMEM ? RT_ERROR_RUNTIME
                                             : RT_ERROR_INPUT, "SCENE: cannot read '%s': %s", path, strerror(failure));
        return false;
    }
    return true;
}

bool lexer_open_string(scene_lexer *lexer, const char *text, const char *source_name, source_file *top)
{
    const char *kept_name = keep_path(lexer, strdup(source_name));
    if (kept_name == NULL)
        return fail_out_of_memory(lexer->report);
    *top = (source_file){.path = kept_name, .text = text, .length = strlen(text), .report = lexer->report};
    return true;
}

/* Reports the include cycle that reading path (the file repeated) from includer closes:
 * "include cycle: A -> B -> A", from the repeated file down to this include. */
static bool fail_include_cycle(const source_line *line, size_t keyword_offset, const source_file *repeated,
                               const char *path)
{
    const source_file *includer = line->file;
    char chain[sizeof ((rt_error *)NULL)->message] = "";
    size_t used = 0;
    /* The links point upwards: count the levels, then walk up to each one in turn. */
    int levels = 1;
    for (const source_file *level = includer; level != repeated; level = level->includer)
        levels++;
    for (int i = levels - 1; i >= 0 && used < sizeof chain; i--) {
        const source_file *level = includer;
        for (int step = 0; step < i; step++)
            level = level->includer;
        used += (size_t)snprintf(chain + used, sizeof chain - used, "%s -> ", level->path);
    }
    if (used < sizeof chain)
        snprintf(chain + used, sizeof chain - used, "%s", path);
    return fail_at(line, keyword_offset, "include cycle: %s", chain);
}

bool lexer_open_include(scene_lexer *lexer, const source_line *line, size_t keyword_offset, const token *path_token,
                        source_file *included)
{
    const source_file *includer = line->file;
    source_file file = {.depth = includer->depth + 1, .includer = includer, .report = includer->report};
    int failure = keep_and_read(lexer, resolve_relative_path(includer->path, line->text + path_token->offset + 1,
                                                             path_token->length - 2), &file);
    if (failure < 0 || failure == ENOMEM)
        return fail_out_of_memory(lexer->report);
    if (failure != 0)
        return fail_at(line, keyword_offset, "cannot read included file '%s': %s", file.path, strerror(failure));

    /* Compare files by identity, not by name: "a.txt" and "./a.txt" are one file. */
    for (const source_file *outer = includer; outer != NULL; outer = outer->includer) {
        if (outer->has_identity && outer->device == file.device && outer->inode == file.inode) {
            source_file_close(&file);
            return fail_include_cycle(line, keyword_offset, outer, file.path);
        }
    }
    if (file.depth > lexer->max_include_depth) {
        source_file_close(&file);
        return fail_at(line, keyword_offset, "includes nested too deeply: '%s' would be level %d, the limit is %d",
                       file.path, file.depth, lexer->max_include_depth);
    }
    *included = file;
    return true;
}

void source_file_close(source_file *file)
{
    free(file->owned_text);
    file->owned_text = NULL;
}

/* ------------------------------------------------------------------ lines */

bool source_file_next_line(const source_file *file, source_line *line)
{
    size_t start = 0;
    int number = 1;
    if (line->file == NULL) {
        /* A UTF-8 byte order mark is an editor's artefact, not part of the first keyword. */
        if (file->length >= 3 && memcmp(file->text, "\xEF\xBB\xBF", 3) == 0)
            start = 3;
    } else {
        size_t end = (size_t)(line->text - file->text) + line->length;
        if (end == file->length)
            return false;                /* the last line had no '\n' after it */
        start = end + 1;
        number = line->number + 1;
    }
    const char *newline = memchr(file->text + start, '\n', file->length - start);
    size_t end = newline != NULL ? (size_t)(newline - file->text) : file->length;
    *line = (source_line){.file = file, .text = file->text + start, .length = end - start, .number = number};
    return true;
}

/* Checks that a line holds only text: no control bytes other than tab and carriage
 * return, and well-formed UTF-8 (so binary files fail at their first odd byte rather
 * than with a confusing message about a token). */
static bool check_line_bytes(const source_line *line)
{
    const unsigned char *bytes = (const unsigned char *)line->text;
    size_t i = 0;
    while (i < line->length) {
        unsigned char c = bytes[i];
        if (c < 0x80) {
            if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f)
                return fail_at(line, i, "unexpected byte 0x%02X (a control character; scene files are text)", c);
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
            return fail_at(line, i, "unexpected byte 0x%02X (not valid UTF-8; scene files are text)", c);
        i += continuation_count + 1;
    }
    return true;
}

bool lexer_start_statement(source_line *line, token *keyword)
{
    return check_line_bytes(line) && lex_token(line, keyword, true);
}

/* Spaces and tabs separate tokens; a carriage return too, so CRLF files read as LF. */
static bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

void take_rest_of_line(source_line *line, size_t *start, size_t *end)
{
    size_t first = line->cursor;
    while (first < line->length && is_space(line->text[first]))
        first++;
    size_t last = first;
    while (last < line->length && line->text[last] != '#')
        last++;
    line->cursor = line->length;
    *start = first;
    *end = last;
}

/* ------------------------------------------------------------------ tokens */

/* A word ends at a space, a comment, a string or a reserved brace. */
static bool ends_word(char c)
{
    return is_space(c) || c == '#' || c == '"' || c == '{' || c == '}';
}

/* Returns where the word at start ends: a word that starts with '(' first runs to its
 * matching ')' (or, unclosed, to a comment or the end, without trailing spaces). */
static size_t word_end(const source_line *line, size_t start)
{
    size_t end = start;
    if (line->text[start] == '(') {
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
    return end;
}

bool lex_token(source_line *line, token *t, bool braces_allowed)
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
        return fail_at(line, start, "unexpected '{' (only a group, instance or volume line ends with '{')");
    if (c == '}')
        return fail_at(line, start, "unexpected '}' (a '}' closes a block on a line of its own)");
    if (c == '"') {
        const char *closing = memchr(line->text + start + 1, '"', line->length - start - 1);
        if (closing == NULL)
            return fail_at(line, start, "unterminated string (expected a closing '\"' on the same line)");
        size_t end = (size_t)(closing - line->text) + 1;
        *t = (token){.kind = TOKEN_STRING, .offset = start, .length = end - start};
        line->cursor = line->last_token_end = end;
        return true;
    }
    size_t end = word_end(line, start);
    *t = (token){.kind = TOKEN_WORD, .offset = start, .length = end - start};
    line->cursor = line->last_token_end = end;
    return true;
}

bool next_token(source_line *line, token *t)
{
    return lex_token(line, t, false);
}

bool peek_token(source_line *line, token *t)
{
    size_t cursor = line->cursor, last_token_end = line->last_token_end;
    bool ok = next_token(line, t);
    line->cursor = cursor;
    line->last_token_end = last_token_end;
    return ok;
}

bool is_last_word(source_line *line, token *t)
{
    size_t cursor = line->cursor, last_token_end = line->last_token_end;
    token after = {.kind = TOKEN_END};
    bool ok = next_token(line, t) && next_token(line, &after);
    line->cursor = cursor;
    line->last_token_end = last_token_end;
    return ok && after.kind == TOKEN_END;
}

bool expect_end_of_line(source_line *line, const char *after)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    if (t.kind == TOKEN_END)
        return true;
    char found[FOUND_BUFFER];
    return fail_at(line, t.offset, "unexpected %s after %s (expected end of line)",
                   describe_token(line, &t, found, sizeof found), after);
}

const char *describe_token(const source_line *line, const token *t, char *buffer, size_t size)
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
    return quote_text(buffer, size, line->text + t->offset, t->length);
}

source_position position_in(const source_line *line, size_t offset)
{
    return (source_position){.path = line->file->path, .line = line->number, .column = offset + 1};
}

source_position token_position(const source_line *line, const token *t)
{
    return position_in(line, t->offset);
}

bool fail_at(const source_line *line, size_t offset, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    fail_at_va(line->file->report, line->file->path, line->number, offset + 1, format, arguments);
    va_end(arguments);
    return false;
}
