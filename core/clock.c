/* clock.c: when this process started, on the monotonic clock of core/clock.h. */
#include "clock.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

double clock_process_start(void)
{
    double now = clock_seconds();
    FILE *stat = fopen("/proc/self/stat", "r");
    if (stat == NULL)
        return now;
    char line[1024];
    bool read = fgets(line, sizeof line, stat) != NULL;
    fclose(stat);
    /* proc(5): the command name (field 2) is in parentheses and may hold spaces, so the
     * fields are counted from its last ')'; field 22 is the start in clock ticks since boot. */
    const char *space = read ? strrchr(line, ')') : NULL;
    for (int field = 3; space != NULL && field <= 22; field++)
        space = strchr(space + 1, ' ');   /* the space before field `field` */
    unsigned long long start_ticks = 0;
    long ticks_per_second = sysconf(_SC_CLK_TCK);
    struct timespec boot;
    if (space == NULL || sscanf(space + 1, "%llu", &start_ticks) != 1 || start_ticks == 0 || ticks_per_second <= 0
        || clock_gettime(CLOCK_BOOTTIME, &boot) != 0)
        return now;
    /* The start time counts from boot on the clock that includes suspends (CLOCK_BOOTTIME):
     * the process's age is measured there and taken off the monotonic now. */
    double age = (double)boot.tv_sec + (double)boot.tv_nsec * 1e-9 - (double)start_ticks / (double)ticks_per_second;
    return age > 0 ? now - age : now;
}
