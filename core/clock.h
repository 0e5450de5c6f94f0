/* clock.h: the one clock of the code base: monotonic seconds (CLOCK_MONOTONIC), for
 * durations only (render times, pass times, checkpoints, progress). Never wall-clock time.
 *
 *   double clock_seconds(void)   seconds since an arbitrary fixed point
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

#endif
