/* status.c: see status.h. */
#include "status.h"

#include <stdio.h>

rt_status rt_error_set_va(rt_error *error, rt_status status, const char *format, va_list arguments)
{
    if (error != NULL)
        vsnprintf(error->message, sizeof error->message, format, arguments);
    return status;
}

rt_status rt_error_set(rt_error *error, rt_status status, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    rt_error_set_va(error, status, format, arguments);
    va_end(arguments);
    return status;
}

const char *rt_status_name(rt_status status)
{
    switch (status) {
    case RT_OK: return "ok";
    case RT_ERROR_INPUT: return "input error";
    case RT_ERROR_RUNTIME: return "runtime error";
    case RT_ERROR_NO_DEVICE: return "no usable device";
    case RT_ERROR_INTERRUPTED: return "interrupted";
    }
    return "unknown status";
}
