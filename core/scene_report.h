/* scene_report.h: how the scene parser reports a failure (internal to core/scene_*.c).
 *
 * Every failure formats its one message once, at the place that finds it, and returns
 * false; every caller then just returns false up to scene_load_* (core/scene_parse.c),
 * which frees everything and returns the recorded status. A message is
 *   "FILE:LINE:COLUMN: what was found, and what was expected"
 * (1-based line and column; scene_parse.h is the contract), or a message without a
 * position for what comes from no file (a -D define). The lexer adds fail_at() for a
 * byte of a line (scene_lexer.h).
 *
 * A scene_report is the caller's: the error buffer may be NULL (then only the status
 * is recorded). Nothing here allocates.
 */
#ifndef RT_SCENE_REPORT_H
#define RT_SCENE_REPORT_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>

#include "status.h"

/* How much of a bad token a message quotes; enough to recognise it, not a whole line. */
#define QUOTE_LIMIT 40
/* Room for a quoted token with its quotes and "..." (and "the string "). */
#define QUOTE_BUFFER (QUOTE_LIMIT + 8)
#define FOUND_BUFFER (QUOTE_BUFFER + 16)
/* Room for a description such as "the red component of material 'm'". */
#define DESCRIPTION_BUFFER 160
/* Room for an owner such as "material 'm'" (names are at most SCENE_NAME_MAX - 1 bytes). */
#define OWNER_BUFFER 96
/* Room for format_number(). */
#define NUMBER_BUFFER 40

/* A place in a scene file: what a message names. path is owned by the lexer's path store
 * (scene_lexer.h) and lives until the parse ends. */
typedef struct source_position {
    const char *path;
    int line;
    size_t column;                   /* 1-based, in bytes */
} source_position;

/* Where a parse reports to: the caller's error buffer (may be NULL) and the status of
 * the first failure (RT_OK while there is none). */
typedef struct scene_report {
    rt_error *error;
    rt_status status;
} scene_report;

/* Reports an input error at position; returns false, for `return fail_at_position(...)`. */
bool fail_at_position(scene_report *report, const source_position *position, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

/* The same for a position given in parts (the lexer's fail_at() uses it). */
bool fail_at_va(scene_report *report, const char *path, int line, size_t column, const char *format,
                va_list arguments);

/* Reports an input error that has no position in a file (a -D define); returns false. */
bool fail_without_position(scene_report *report, const char *format, ...) __attribute__((format(printf, 2, 3)));

/* Records an allocation failure, the one error that is not the user's input
 * (RT_ERROR_RUNTIME, "SCENE: out of memory while reading the scene"); returns false. */
bool fail_out_of_memory(scene_report *report);

/* Returns how many bytes of text (length bytes) a message shows: all of it, or
 * QUOTE_LIMIT bytes cut before a UTF-8 continuation byte so that the message stays
 * valid UTF-8. */
int quoted_length(const char *text, size_t length);

/* Writes 'text' (cut to QUOTE_LIMIT bytes with "...") into buffer and returns buffer. */
const char *quote_text(char *buffer, size_t size, const char *text, size_t length);

/* Formats value for a message into buffer (NUMBER_BUFFER bytes are enough) and returns
 * buffer: 15 significant digits show 0.1 as 0.1 and 1/3 as 0.333333333333333, and every
 * whole number of the integer ranges exactly. */
const char *format_number(char *buffer, size_t size, double value);

/* Writes the count words as a list for a message, "a, b or c", into buffer and returns
 * buffer (cut to size). */
const char *format_word_list(char *buffer, size_t size, const char *const *words, int count);

/* Writes "FILE:LINE:COLUMN" of where into buffer, for the asset loader's messages
 * (scene_image.position, scene_mesh.position). */
void format_position(char *buffer, size_t size, const source_position *where);

#endif
