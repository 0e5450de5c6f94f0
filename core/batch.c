/* batch.c: see batch.h. */
#include "batch.h"

#include "array.h"
#include "expression.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LARGEST_FRAME 99999999

/* Reads a whole number of at most 9 digits at *cursor; returns 0 and advances, or -1. */
static int read_number(const char **cursor, long *value)
{
    const char *p = *cursor;
    if (!isdigit((unsigned char)*p))
        return -1;
    long number = 0;
    int digits = 0;
    while (isdigit((unsigned char)*p)) {
        if (++digits > 9)
            return -1;
        number = number * 10 + (*p++ - '0');
    }
    *cursor = p;
    *value = number;
    return 0;
}

/* Appends frame to the list, refusing duplicates and overlong lists. */
static rt_status append_frame(frame_list *list, size_t *capacity, long frame, const char *item, int item_length,
                              rt_error *error)
{
    for (int i = 0; i < list->count; i++)
        if (list->frames[i] == frame)
            return rt_error_set(error, RT_ERROR_INPUT, "frames: frame %ld is listed twice ('%.*s')", frame,
                                item_length, item);
    if (list->count == BATCH_MAX_FRAMES)
        return rt_error_set(error, RT_ERROR_INPUT, "frames: more than %d frames", BATCH_MAX_FRAMES);
    if (!array_reserve((void **)&list->frames, capacity, (size_t)list->count + 1, sizeof *list->frames))
        return rt_error_set(error, RT_ERROR_RUNTIME, "frames: out of memory");
    list->frames[list->count++] = (int)frame;
    return RT_OK;
}

rt_status frame_list_parse(const char *text, frame_list *out, rt_error *error)
{
    out->frames = NULL;
    out->count = 0;
    size_t capacity = 0;
    const char *p = text;
    if (*p == '\0')
        return rt_error_set(error, RT_ERROR_INPUT, "frames: the list is empty (e.g. 1-60 or 1-10,15,20-30:2)");
    rt_status status = RT_OK;
    while (status == RT_OK) {
        const char *item = p;
        long first, last, step = 1;
        if (read_number(&p, &first)) {
            status = rt_error_set(error, RT_ERROR_INPUT, "frames: expected a frame number at '%s'", item);
            break;
        }
        last = first;
        if (*p == '-') {
            p++;
            if (read_number(&p, &last)) {
                status = rt_error_set(error, RT_ERROR_INPUT, "frames: expected the last frame after '-' in '%s'", item);
                break;
            }
            if (*p == ':') {
                p++;
                if (read_number(&p, &step) || step < 1) {
                    status = rt_error_set(error, RT_ERROR_INPUT, "frames: expected a step of 1 or more after ':' in '%s'",
                                          item);
                    break;
                }
            }
        }
        int item_length = (int)(p - item);
        if (first > LARGEST_FRAME || last > LARGEST_FRAME) {
            status = rt_error_set(error, RT_ERROR_INPUT, "frames: '%.*s' goes past frame %d", item_length, item,
                                  LARGEST_FRAME);
            break;
        }
        if (last < first) {
            status = rt_error_set(error, RT_ERROR_INPUT, "frames: '%.*s' runs backwards", item_length, item);
            break;
        }
        for (long frame = first; frame <= last && status == RT_OK; frame += step)
            status = append_frame(out, &capacity, frame, item, item_length, error);
        if (status != RT_OK)
            break;
        if (*p == '\0')
            break;
        if (*p != ',') {
            status = rt_error_set(error, RT_ERROR_INPUT, "frames: unexpected '%c' in '%s' (expected ',' between items)",
                                  *p, text);
            break;
        }
        p++;
    }
    if (status != RT_OK)
        frame_list_free(out);
    return status;
}

void frame_list_free(frame_list *list)
{
    free(list->frames);
    list->frames = NULL;
    list->count = 0;
}

rt_status shard_parse(const char *text, int *index, int *count, rt_error *error)
{
    const char *p = text;
    long i, n;
    if (read_number(&p, &i) || *p++ != '/' || read_number(&p, &n) || *p != '\0')
        return rt_error_set(error, RT_ERROR_INPUT, "'%s' is not I/N (e.g. 3/8: part 3 of parts 0 to 7)", text);
    if (n < 1 || n > 1000000 || i >= n)
        return rt_error_set(error, RT_ERROR_INPUT, "'%s': I must be 0 to N-1 and N 1 to 1000000", text);
    *index = (int)i;
    *count = (int)n;
    return RT_OK;
}

void shard_range(int index, int count, long long total, long long *start, long long *length)
{
    long long begin = total * index / count;
    long long end = total * (index + 1) / count;
    *start = begin;
    *length = end - begin;
}

/* Finds the one %d-style conversion of pattern: returns 1 and its span, 0 when there is
 * none, -1 when there are several or another conversion. */
static int find_conversion(const char *pattern, const char **begin, const char **end)
{
    int found = 0;
    for (const char *p = pattern; *p != '\0'; p++) {
        if (*p != '%')
            continue;
        if (p[1] == '%') {
            p++;
            continue;
        }
        const char *q = p + 1;
        if (*q == '0')
            q++;
        while (isdigit((unsigned char)*q))
            q++;
        if (*q != 'd' || q - p > 4 || found)
            return -1;
        found = 1;
        *begin = p;
        *end = q + 1;
        p = q;
    }
    return found;
}

bool output_pattern_has_frame(const char *pattern)
{
    const char *begin, *end;
    return find_conversion(pattern, &begin, &end) == 1;
}

rt_status output_pattern_format(const char *pattern, int frame, char *name, size_t size, rt_error *error)
{
    const char *begin = NULL, *end = NULL;
    int found = find_conversion(pattern, &begin, &end);
    if (found < 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "output '%s': use exactly one %%d-style conversion (e.g. frame-%%04d.png) and %%%% for a "
                            "percent sign", pattern);
    size_t used = 0;
    for (const char *p = pattern; *p != '\0';) {
        char piece[32];
        const char *text = piece;
        size_t length;
        if (found && p == begin) {
            char format[8];
            snprintf(format, sizeof format, "%.*s", (int)(end - begin), begin);
            length = (size_t)snprintf(piece, sizeof piece, format, frame);
            p = end;
        } else if (p[0] == '%' && p[1] == '%') {
            text = "%";
            length = 1;
            p += 2;
        } else {
            text = p;
            length = 1;
            p++;
        }
        if (used + length + 1 > size)
            return rt_error_set(error, RT_ERROR_INPUT, "output '%s': the name is too long", pattern);
        memcpy(name + used, text, length);
        used += length;
    }
    name[used] = '\0';
    return RT_OK;
}

rt_status output_name_without_frames(const char *pattern, const char *frame_define, char *name, size_t size,
                                     rt_error *error)
{
    long frame = 0;
    if (frame_define != NULL && output_pattern_has_frame(pattern)) {
        double value = 0;
        rt_error expression_error = {{0}};
        if (expression_evaluate(frame_define, strlen(frame_define), 1, NULL, NULL, &value, NULL, &expression_error)
            != RT_OK)
            return rt_error_set(error, RT_ERROR_INPUT, "output '%s': the frame number -D frame=%s: %s", pattern,
                                frame_define, expression_error.message);
        if (!(value >= 0 && value <= LARGEST_FRAME) || value != (double)(long)value)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "output '%s': -D frame=%s is %.17g, not a frame number for the name (a whole "
                                "number 0 to %d)", pattern, frame_define, value, LARGEST_FRAME);
        frame = (long)value;
    }
    return output_pattern_format(pattern, (int)frame, name, size, error);
}
