/* clock.h: the one clock of the code base: monotonic seconds (CLOCK_MONOTONIC), for
 * durations only (render times, pass times, checkpoints, progress). Never wall-clock time.
 *
 *   double clock_seconds(void)        seconds since an arbitrary fixed point
 *   double clock_process_start(void)  clock_seconds() when this process started (core/clock.c)
 */
#ifndef RT_CLOCK_H
#define RT_CLOCK_H

#include <time.h>

static inline double clock_seconds(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)now.tv_sec + (double)now.tv_nsec * 1e-9;
}

/* Returns the clock_seconds() value at which this process was started (its exec), so that
 * the dynamic loader's work before main counts: loading OpenImageIO's libraries takes about
 * 0.2 s (docs/performance.md, "Ideas"). Read from /proc/self/stat, whose start time has the
 * kernel's clock-tick resolution (10 ms on Linux), so the result is up to one tick early.
 * Returns clock_seconds() itself when that cannot be read (no /proc). */
double clock_process_start(void);

#endif
