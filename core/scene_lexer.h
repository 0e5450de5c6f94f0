/* scene_lexer.h: the scene parser's lexer: files, lines and tokens (internal to the
 * parser, core/scene_*.c; the format is docs/scene-format.md).
 *
 * What it owns:
 *   - files: reading one whole (at most 256 MiB, so that include "/dev/zero" fails
 *     cleanly), the paths that messages name (kept in the lexer until the parse ends),
 *     includes (the path relative to the including file, cycles by file identity, the
 *     depth limit);
 *   - lines: a file is cut into lines and each line is one statement; a UTF-8 byte order
 *     mark at the start of a file is skipped; a line may hold only text (no control bytes
 *     but tab and carriage return, well-formed UTF-8);
 *   - tokens, lexed on demand from a line's cursor (so that `set` can take the raw rest of
 *     its line as an expression): a word runs to a space, '#', '"' or a brace, and one
 *     that starts with '(' runs to its matching ')' across spaces, so `(4 * cos($t))` is
 *     one number; a string is "..." on one line, quotes included; a brace is a token where
 *     a block may open or close (lex_token's braces_allowed) and an error elsewhere; '#'
 *     starts a comment; after the last token the lexer keeps returning TOKEN_END.
 *
 * Positions: a token lies at byte t.offset of its line, and the line knows its file and
 * number: token_position() is its FILE:LINE:COLUMN. A missing token (TOKEN_END) is
 * reported just after the last token read.
 *
 * Errors: a line reports to the report of its file (source_file.report, the parse's):
 * every function here that can fail writes one message (scene_report.h) and returns
 * false. Keywords are case-sensitive.
 *
 * Ownership: the lexer owns the kept paths (lexer_free frees them, so positions stay
 * valid until then); a source_file owns the text the lexer read for it
 * (source_file_close frees it), never the text of scene_load_string.
 */
#ifndef RT_SCENE_LEXER_H
#define RT_SCENE_LEXER_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>
#include <sys/types.h>

#include "scene_report.h"

/* One file (or the text of scene_load_string) being read. */
typedef struct source_file {
    const char *path;                /* as shown in messages; owned by the lexer's path store */
    const char *text;
    size_t length;
    char *owned_text;                /* the text when the lexer read it, else NULL */
    bool has_identity;               /* false for the text of scene_load_string */
    dev_t device;
    ino_t inode;
    int depth;                       /* 0 for the top file */
    const struct source_file *includer;
    scene_report *report;            /* where its lines report errors */
} source_file;

/* One line of a file: one statement, lexed from cursor on. */
typedef struct source_line {
    const source_file *file;
    const char *text;
    size_t length;                   /* without the '\n' */
    int number;                      /* 1-based */
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

/* The files of one parse: the paths its messages name and the include depth limit. */
typedef struct scene_lexer {
    scene_report *report;
    char **paths;                    /* every path shown in a message, freed by lexer_free */
    int path_count;
    size_t path_capacity;
    int max_include_depth;
} scene_lexer;

/* ---- files */

/* Starts a lexer that reports to report and allows includes max_include_depth deep. */
void lexer_init(scene_lexer *lexer, scene_report *report, int max_include_depth);

/* Frees the kept paths: every source_position of the parse is invalid afterwards. */
void lexer_free(scene_lexer *lexer);

/* Reads the file at path whole into *top (the top file of a parse). On failure reports
 * "SCENE: cannot read 'PATH': REASON" (RT_ERROR_INPUT; RT_ERROR_RUNTIME when memory runs
 * out) and returns false. The caller closes *top with source_file_close(). */
bool lexer_open_top_file(scene_lexer *lexer, const char *path, source_file *top);

/* Makes text (the caller's, NUL-terminated, kept alive by the caller) the top file,
 * named source_name in messages. Returns false only when memory runs out. */
bool lexer_open_string(scene_lexer *lexer, const char *text, const char *source_name, source_file *top);

/* Opens the file an include statement of line names: path_token is its string token
 * and keyword_offset where messages about the file point. The path is resolved against
 * the directory of the including file; the file must be readable, not be one of the
 * files that include it (compared by identity, so "a.txt" and "./a.txt" are one file)
 * and not be nested deeper than the limit. The caller closes *included. */
bool lexer_open_include(scene_lexer *lexer, const source_line *line, size_t keyword_offset, const token *path_token,
                        source_file *included);

/* Frees the text the lexer read for file (nothing for a string). */
void source_file_close(source_file *file);

/* Returns the malloc'd path "directory of includer_path" + text (length bytes); an
 * absolute text is kept as it is. The caller frees it; NULL when memory runs out. */
char *resolve_relative_path(const char *includer_path, const char *text, size_t length);

/* ---- lines */

/* Cuts the next line of file into *line: the first when *line is all zero, else the one
 * after *line. Returns false after the last line. An empty file has one empty line, and
 * a final '\n' is followed by an empty last line. */
bool source_file_next_line(const source_file *file, source_line *line);

/* Starts a statement: checks that the line holds only text, then reads its first token
 * into *keyword (a brace is a token here). */
bool lexer_start_statement(source_line *line, token *keyword);

/* Takes the raw rest of the line, up to a comment and without leading spaces, as bytes
 * [*start, *end) of the line (an expression); the line is then used up. */
void take_rest_of_line(source_line *line, size_t *start, size_t *end);

/* ---- tokens */

/* Reads the next token of line into *t; braces are tokens when braces_allowed (where a
 * block may open or close), an error elsewhere. An unbalanced '(' word runs to the end
 * of the line and the expression evaluator reports it. Returns false on a lexical error. */
bool lex_token(source_line *line, token *t, bool braces_allowed);

/* Reads the next token where a brace is an error (almost everywhere). */
bool next_token(source_line *line, token *t);

/* Reads the next token without consuming it (a lexical error is still reported). */
bool peek_token(source_line *line, token *t);

/* Peeks the next token into *t; true when nothing but a comment follows it (it is the
 * statement's last word). */
bool is_last_word(source_line *line, token *t);

/* True when t is the bare word `word`. Inline: the statement table compares every
 * statement's keyword with it. */
static inline bool token_is(const source_line *line, const token *t, const char *word)
{
    size_t length = strlen(word);
    return t->kind == TOKEN_WORD && t->length == length && memcmp(line->text + t->offset, word, length) == 0;
}

/* Fails unless the rest of the line is empty; after names what came last, for the
 * message ("unexpected 'x' after the translation (expected end of line)"). */
bool expect_end_of_line(source_line *line, const char *after);

/* Describes t for "found ..." in messages: 'word', the string "..." or end of line;
 * returns buffer (FOUND_BUFFER bytes are enough) or a constant. */
const char *describe_token(const source_line *line, const token *t, char *buffer, size_t size);

/* Returns the position of byte offset of line, for messages about it later. */
source_position position_in(const source_line *line, size_t offset);

/* Returns the position of token t of line. */
source_position token_position(const source_line *line, const token *t);

/* Reports an input error at byte offset of line; returns false. */
bool fail_at(const source_line *line, size_t offset, const char *format, ...) __attribute__((format(printf, 3, 4)));

#endif
