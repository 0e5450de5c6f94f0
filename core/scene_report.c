/* scene_report.c: see scene_report.h. */
#include "scene_report.h"

#include <stdarg.h>
#include <stdio.h>

bool fail_at_va(scene_report *report, const char *path, int line, size_t column, const char *format,
                va_list arguments)
{
    report->status = RT_ERROR_INPUT;
    if (report->error == NULL)
        return false;
    char *message = report->error->message;
    size_t size = sizeof report->error->message;
    int prefix = snprintf(message, size, "%s:%d:%zu: ", path, line, column);
    if (prefix >= 0 && (size_t)prefix < size)
        vsnprintf(message + prefix, size - (size_t)prefix, format, arguments);
    return false;
}

bool fail_at_position(scene_report *report, const source_position *position, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    fail_at_va(report, position->path, position->line, position->column, format, arguments);
    va_end(arguments);
    return false;
}

bool fail_without_position(scene_report *report, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    rt_error_set_va(report->error, RT_ERROR_INPUT, format, arguments);
    va_end(arguments);
    report->status = RT_ERROR_INPUT;
    return false;
}

bool fail_out_of_memory(scene_report *report)
{
    report->status = rt_error_set(report->error, RT_ERROR_RUNTIME, "SCENE: out of memory while reading the scene");
    return false;
}

int quoted_length(const char *text, size_t length)
{
    if (length <= QUOTE_LIMIT)
        return (int)length;
    size_t shown = QUOTE_LIMIT;
    while (shown > 0 && ((unsigned char)text[shown] & 0xC0) == 0x80)
        shown--;
    return (int)shown;
}

const char *quote_text(char *buffer, size_t size, const char *text, size_t length)
{
    snprintf(buffer, size, "'%.*s%s'", quoted_length(text, length), text, length > QUOTE_LIMIT ? "..." : "");
    return buffer;
}

const char *format_number(char *buffer, size_t size, double value)
{
    snprintf(buffer, size, "%.15g", value);
    return buffer;
}

const char *format_word_list(char *buffer, size_t size, const char *const *words, int count)
{
    size_t used = 0;
    buffer[0] = '\0';
    for (int i = 0; i < count && used < size; i++) {
        int written = snprintf(buffer + used, size - used, "%s%s", i == 0 ? "" : i == count - 1 ? " or " : ", ",
                               words[i]);
        if (written < 0)
            break;
        used += (size_t)written;
    }
    return buffer;
}

void format_position(char *buffer, size_t size, const source_position *where)
{
    snprintf(buffer, size, "%s:%d:%zu", where->path, where->line, where->column);
}
