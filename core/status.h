/* status.h: the status codes and error messages every core function reports through.
 *
 * Core functions never print and never exit. They return an rt_status and, on failure,
 * fill an rt_error with one human-readable sentence (prefixed with the module tag, e.g.
 * "SCENE: ", "BVH: ", "GPU: ", or with "file:line:column: " where there is a position).
 * Only cli/ decides what to print and which exit code to use:
 *
 *   RT_OK                 success
 *   RT_ERROR_INPUT        the user's input is wrong (scene file, image, option value): exit 2
 *   RT_ERROR_RUNTIME      something failed while working (write failed, GL error): exit 1
 *   RT_ERROR_NO_DEVICE    no usable EGL device or driver is installed: exit 1, with install advice
 *   RT_ERROR_INTERRUPTED  the user interrupted a render (SIGINT/SIGTERM): exit 1 (130 by cli)
 */
#ifndef RT_STATUS_H
#define RT_STATUS_H

#include <stdarg.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rt_status {
    RT_OK = 0,
    RT_ERROR_INPUT,
    RT_ERROR_RUNTIME,
    RT_ERROR_NO_DEVICE,
    RT_ERROR_INTERRUPTED,
} rt_status;

/* One error message. A fixed buffer so that reporting an error never allocates. */
typedef struct rt_error {
    char message[1024];
} rt_error;

/* Formats a message into error (when error is not NULL) and returns status, so that a
 * failing function can end with `return rt_error_set(error, RT_ERROR_INPUT, "...", ...);`. */
rt_status rt_error_set(rt_error *error, rt_status status, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

/* The same with a va_list, for wrappers that add their own prefix. */
rt_status rt_error_set_va(rt_error *error, rt_status status, const char *format, va_list arguments);

/* Returns a short constant name for a status ("input error", ...); never NULL. */
const char *rt_status_name(rt_status status);

#ifdef __cplusplus
}
#endif

#endif
