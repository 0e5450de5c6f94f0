/* batch.h: plain helpers for batch rendering: frame lists, shards (I/N splits) and
 * printf-style output names. No GL, no I/O; used by the render command and unit-tested.
 *
 * Frame list syntax: comma-separated items, each `N`, `A-B` (A to B inclusive) or
 * `A-B:S` (every S-th frame from A up to B). Frames are whole numbers 0..99999999, kept
 * in the order given; a frame listed twice is an error (it would render twice to the
 * same file). At most BATCH_MAX_FRAMES frames.
 *
 * Output patterns: a name with exactly one `%d`-style conversion (`%d`, `%4d`, `%04d`)
 * is formatted with the frame number; `%%` is a literal percent sign. Every output name
 * is a pattern, with or without --frames: without them the frame number is the value of
 * `-D frame=VALUE` when given, else 0 (output_name_without_frames()).
 */
#ifndef RT_BATCH_H
#define RT_BATCH_H

#include <stdbool.h>
#include <stddef.h>

#include "status.h"

#define BATCH_MAX_FRAMES 1000000

typedef struct frame_list {
    int *frames;
    int count;
} frame_list;

/* Parses text into *out (allocated; free with frame_list_free()). Errors are
 * RT_ERROR_INPUT naming the offending item, e.g. "frames: '5-2' runs backwards". */
rt_status frame_list_parse(const char *text, frame_list *out, rt_error *error);

/* Frees out->frames and zeroes *out. */
void frame_list_free(frame_list *list);

/* Parses "I/N" (0 <= I < N <= 1000000) into *index and *count. */
rt_status shard_parse(const char *text, int *index, int *count, rt_error *error);

/* Splits total items into count contiguous parts as evenly as possible and returns part
 * index as [*start, *start + *length): part i starts at floor(i * total / count). */
void shard_range(int index, int count, long long total, long long *start, long long *length);

/* True when pattern holds a %d-style conversion (so each frame gets its own name). */
bool output_pattern_has_frame(const char *pattern);

/* Formats pattern with frame into name (size bytes). A pattern with no conversion is
 * copied as it is. More than one conversion, or any other conversion, is RT_ERROR_INPUT. */
rt_status output_pattern_format(const char *pattern, int frame, char *name, size_t size, rt_error *error);

/* The output name of a render without --frames: pattern formatted with the value of
 * frame_define (the VALUE text of the last `-D frame=VALUE`, an expression without
 * variables), or with 0 when frame_define is NULL. The value matters only when pattern
 * has a conversion; then it must be a whole number 0..99999999, like a --frames entry.
 * Errors (RT_ERROR_INPUT): those of output_pattern_format(), a value that does not
 * evaluate or is not such a whole number. */
rt_status output_name_without_frames(const char *pattern, const char *frame_define, char *name, size_t size,
                                     rt_error *error);

#endif
