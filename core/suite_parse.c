/* suite_parse.c: reading a suite file (suite.h, "The suite file"). Files, lines, words,
 * quoted strings, comments, includes and positions are the scene parser's lexer's
 * (scene_lexer.h), so that a suite reads like a scene file and reports like one. */
#include "suite.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "scene_lexer.h"

/* The render and compare lines in force and the root, in one file being read. Each scope
 * owns copies of its words (an include starts with copies of its includer's). */
typedef struct file_scope {
    const char *file;            /* one of suite.files */
    char *root;                  /* prefix of relative paths: "" or ending in '/' */
    suite_word *render, *compare;
    int render_count, compare_count;
} file_scope;

typedef struct suite_parser {
    suite *out;
    scene_lexer lexer;
    scene_report report;
    size_t case_capacity, file_capacity;
} suite_parser;

static void free_words(suite_word *words, int count)
{
    for (int i = 0; i < count; i++)
        free(words[i].text);
    free(words);
}

static void free_scope(file_scope *scope)
{
    free(scope->root);
    free_words(scope->render, scope->render_count);
    free_words(scope->compare, scope->compare_count);
    memset(scope, 0, sizeof *scope);
}

/* Copies count words (then extra_count more) into a new array (*out). Returns false when
 * memory runs out. */
static bool copy_words(const suite_word *words, int count, const suite_word *extra, int extra_count,
                       suite_word **out)
{
    *out = calloc((size_t)(count + extra_count) + 1, sizeof **out);
    if (*out == NULL)
        return false;
    for (int i = 0; i < count + extra_count; i++) {
        const suite_word *from = i < count ? &words[i] : &extra[i - count];
        (*out)[i] = *from;
        (*out)[i].text = strdup(from->text);
        if ((*out)[i].text == NULL) {
            free_words(*out, i);
            *out = NULL;
            return false;
        }
    }
    return true;
}

/* Keeps a copy of path in the suite's file list; returns it, or NULL when memory runs out. */
static const char *keep_file(suite_parser *p, const char *path)
{
    suite *s = p->out;
    if (!array_reserve((void **)&s->files, &p->file_capacity, (size_t)s->file_count + 1, sizeof *s->files))
        return NULL;
    char *copy = strdup(path);
    if (copy != NULL)
        s->files[s->file_count++] = copy;
    return copy;
}

/* The text of word t of line: a string without its quotes. Returns a malloc'd copy or NULL. */
static char *word_text(const source_line *line, const token *t)
{
    bool quoted = t->kind == TOKEN_STRING;
    size_t length = quoted ? t->length - 2 : t->length;
    char *text = malloc(length + 1);
    if (text != NULL) {
        memcpy(text, line->text + t->offset + (quoted ? 1 : 0), length);
        text[length] = '\0';
    }
    return text;
}

/* Reads the rest of line as words into *words (malloc'd; *count of them), stopping
 * before the bare word stop (when not NULL; *stopped tells). */
static bool read_words(suite_parser *p, file_scope *scope, source_line *line, const char *stop, suite_word **words,
                       int *count, bool *stopped)
{
    size_t capacity = 0;
    *words = NULL;
    *count = 0;
    if (stopped != NULL)
        *stopped = false;
    for (;;) {
        token t = {.kind = TOKEN_END};
        if (!next_token(line, &t))
            return false;
        if (t.kind == TOKEN_END)
            return true;
        if (stop != NULL && token_is(line, &t, stop)) {
            *stopped = true;
            return true;
        }
        if (!array_reserve((void **)words, &capacity, (size_t)*count + 1, sizeof **words))
            return fail_out_of_memory(&p->report);
        source_position where = token_position(line, &t);
        suite_word *word = &(*words)[*count];
        *word = (suite_word){.text = word_text(line, &t), .file = scope->file, .line = where.line,
                             .column = (int)where.column};
        if (word->text == NULL)
            return fail_out_of_memory(&p->report);
        (*count)++;
    }
}

/* Replaces the scope's render or compare words with the rest of line. */
static bool statement_defaults(suite_parser *p, file_scope *scope, source_line *line, bool render)
{
    suite_word *words = NULL;
    int count = 0;
    if (!read_words(p, scope, line, NULL, &words, &count, NULL)) {
        free_words(words, count);
        return false;
    }
    suite_word **kept = render ? &scope->render : &scope->compare;
    int *kept_count = render ? &scope->render_count : &scope->compare_count;
    free_words(*kept, *kept_count);
    *kept = words;
    *kept_count = count;
    return true;
}

/* Reads the next word of line as a path or name (what describes it in the message).
 * Returns a malloc'd copy, or NULL with the failure reported. */
static char *expect_word(suite_parser *p, source_line *line, const char *what, const char *after)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return NULL;
    if (t.kind == TOKEN_END || (t.kind == TOKEN_STRING && t.length == 2)) {
        fail_at(line, t.offset, "expected %s after %s", what, after);
        return NULL;
    }
    char *text = word_text(line, &t);
    if (text == NULL)
        fail_out_of_memory(&p->report);
    return text;
}

/* root DIR: later relative paths of this file start from DIR. */
static bool statement_root(suite_parser *p, file_scope *scope, source_line *line)
{
    char *directory = expect_word(p, line, "a directory", "root");
    if (directory == NULL || !expect_end_of_line(line, "the root directory")) {
        free(directory);
        return false;
    }
    char *resolved = resolve_relative_path(scope->file, directory, strlen(directory));
    free(directory);
    size_t length = resolved ? strlen(resolved) : 0;
    char *root = resolved ? malloc(length + 2) : NULL;
    free(scope->root);
    scope->root = root;
    if (root == NULL) {
        free(resolved);
        return fail_out_of_memory(&p->report);
    }
    snprintf(root, length + 2, "%s%s", resolved, length > 0 && resolved[length - 1] != '/' ? "/" : "");
    free(resolved);
    return true;
}

/* True when name may name a case (and so a folder of the report). */
static bool valid_name(const char *name)
{
    size_t length = strlen(name);
    if (length == 0 || length >= SUITE_NAME_MAX || strcmp(name, ".") == 0 || strcmp(name, "..") == 0)
        return false;
    for (size_t i = 0; i < length; i++) {
        char c = name[i];
        bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_'
                  || c == '-';
        if (!ok)
            return false;
    }
    return true;
}

/* Returns path resolved against the scope's root (an absolute one as it is), malloc'd. */
static char *resolve(const file_scope *scope, const char *path)
{
    bool absolute = path[0] == '/';
    size_t length = (absolute ? 0 : strlen(scope->root)) + strlen(path) + 1;
    char *resolved = malloc(length);
    if (resolved != NULL)
        snprintf(resolved, length, "%s%s", absolute ? "" : scope->root, path);
    return resolved;
}

/* case NAME SCENE GOLDEN [render options] [compare compare options]. */
static bool statement_case(suite_parser *p, file_scope *scope, source_line *line, const token *keyword)
{
    suite *s = p->out;
    token name_token = {.kind = TOKEN_END};
    if (!peek_token(line, &name_token))
        return false;
    char *name = expect_word(p, line, "the case's name", "case");
    if (name == NULL)
        return false;
    if (!valid_name(name)) {
        bool ok = fail_at(line, name_token.offset,
                          "a case's name is 1 to %d letters, digits, '.', '_' or '-' (it names files), not '%s'",
                          SUITE_NAME_MAX - 1, name);
        free(name);
        return ok;
    }
    for (int i = 0; i < s->case_count; i++)
        if (strcmp(s->cases[i].name, name) == 0) {
            bool ok = fail_at(line, name_token.offset, "case '%s' is already defined at %s:%d", name,
                              s->cases[i].file, s->cases[i].line);
            free(name);
            return ok;
        }
    if (!array_reserve((void **)&s->cases, &p->case_capacity, (size_t)s->case_count + 1, sizeof *s->cases)) {
        free(name);
        return fail_out_of_memory(&p->report);
    }
    suite_case *c = &s->cases[s->case_count++];
    *c = (suite_case){.name = name, .file = scope->file, .line = line->number};
    char *scene = expect_word(p, line, "the case's scene file", "the case's name");
    char *golden = scene ? expect_word(p, line, "the case's golden image", "the scene file") : NULL;
    if (scene != NULL && golden != NULL) {
        c->scene = resolve(scope, scene);
        c->golden = resolve(scope, golden);
    }
    free(scene);
    free(golden);
    if (c->golden == NULL)
        return p->report.status != RT_OK ? false : fail_out_of_memory(&p->report);
    suite_word *own_render = NULL, *own_compare = NULL;
    int own_render_count = 0, own_compare_count = 0;
    bool has_compare = false;
    bool ok = read_words(p, scope, line, "compare", &own_render, &own_render_count, &has_compare)
              && (!has_compare || read_words(p, scope, line, NULL, &own_compare, &own_compare_count, NULL));
    if (ok && !copy_words(scope->render, scope->render_count, own_render, own_render_count, &c->render))
        ok = fail_out_of_memory(&p->report);
    if (ok && !copy_words(scope->compare, scope->compare_count, own_compare, own_compare_count, &c->compare))
        ok = fail_out_of_memory(&p->report);
    if (ok) {
        c->render_count = scope->render_count + own_render_count;
        c->compare_count = scope->compare_count + own_compare_count;
    }
    free_words(own_render, own_render_count);
    free_words(own_compare, own_compare_count);
    (void)keyword;
    return ok;
}

static bool parse_file(suite_parser *p, const source_file *file, const file_scope *outer);

/* include "FILE": its cases, with this file's render and compare lines as its start. */
static bool statement_include(suite_parser *p, file_scope *scope, source_line *line, const token *keyword)
{
    token t = {.kind = TOKEN_END};
    if (!next_token(line, &t))
        return false;
    char found[FOUND_BUFFER];
    if (t.kind != TOKEN_STRING || t.length == 2)
        return fail_at(line, t.offset, "expected a quoted path after include (e.g. include \"more.txt\"), found %s",
                       describe_token(line, &t, found, sizeof found));
    if (!expect_end_of_line(line, "the included path"))
        return false;
    source_file included;
    if (!lexer_open_include(&p->lexer, line, keyword->offset, &t, &included))
        return false;
    bool ok = parse_file(p, &included, scope);
    source_file_close(&included);
    return ok;
}

/* Parses one line of the file in scope. */
static bool parse_statement(suite_parser *p, file_scope *scope, source_line *line)
{
    token keyword = {.kind = TOKEN_END};
    if (!lexer_start_statement(line, &keyword))
        return false;
    if (keyword.kind == TOKEN_END)
        return true;
    if (token_is(line, &keyword, "case"))
        return statement_case(p, scope, line, &keyword);
    if (token_is(line, &keyword, "render") || token_is(line, &keyword, "compare"))
        return statement_defaults(p, scope, line, token_is(line, &keyword, "render"));
    if (token_is(line, &keyword, "root"))
        return statement_root(p, scope, line);
    if (token_is(line, &keyword, "include"))
        return statement_include(p, scope, line, &keyword);
    char found[FOUND_BUFFER];
    return fail_at(line, keyword.offset, "unknown statement %s (expected case, render, compare, root or include)",
                   describe_token(line, &keyword, found, sizeof found));
}

/* Parses every line of file, starting from outer's render and compare lines (NULL: none). */
static bool parse_file(suite_parser *p, const source_file *file, const file_scope *outer)
{
    file_scope scope = {.file = keep_file(p, file->path)};
    scope.root = scope.file ? resolve_relative_path(file->path, "", 0) : NULL;
    bool ok = scope.root != NULL;
    if (ok && outer != NULL) {
        ok = copy_words(outer->render, outer->render_count, NULL, 0, &scope.render)
             && copy_words(outer->compare, outer->compare_count, NULL, 0, &scope.compare);
        if (ok) {
            scope.render_count = outer->render_count;
            scope.compare_count = outer->compare_count;
        }
    }
    if (!ok) {
        free_scope(&scope);
        return fail_out_of_memory(&p->report);
    }
    source_line line = {0};
    while (ok && source_file_next_line(file, &line))
        ok = parse_statement(p, &scope, &line);
    free_scope(&scope);
    return ok;
}

/* The suite's name: path's last component without its extension. */
static char *suite_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t length = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    char *name = malloc(length + 1);
    if (name != NULL) {
        memcpy(name, base, length);
        name[length] = '\0';
    }
    return name;
}

rt_status suite_load(const char *path, suite *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    suite_parser p = {.out = out, .report = {.error = error, .status = RT_OK}};
    out->path = strdup(path);
    out->name = suite_name(path);
    if (out->path == NULL || out->name == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "SUITE: out of memory");
    lexer_init(&p.lexer, &p.report, SUITE_MAX_INCLUDE_DEPTH);
    source_file top;
    bool ok = lexer_open_top_file(&p.lexer, path, &top);
    if (!ok && p.report.status == RT_ERROR_INPUT && error != NULL && strncmp(error->message, "SCENE: ", 7) == 0)
        memcpy(error->message, "SUITE", 5);   /* the lexer's words for the top file; it is a suite here */
    if (ok) {
        ok = parse_file(&p, &top, NULL);
        source_file_close(&top);
    }
    lexer_free(&p.lexer);
    if (ok && out->case_count == 0)
        return rt_error_set(error, RT_ERROR_INPUT, "SUITE: '%s' has no case (a line 'case NAME SCENE GOLDEN ...')",
                            path);
    return ok ? RT_OK : p.report.status;
}

void suite_free(suite *s)
{
    for (int i = 0; i < s->case_count; i++) {
        suite_case *c = &s->cases[i];
        free(c->name);
        free(c->scene);
        free(c->golden);
        free_words(c->render, c->render_count);
        free_words(c->compare, c->compare_count);
    }
    free(s->cases);
    for (int i = 0; i < s->file_count; i++)
        free(s->files[i]);
    free(s->files);
    free(s->name);
    free(s->path);
    memset(s, 0, sizeof *s);
}
