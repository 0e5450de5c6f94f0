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
    /* proc(5): field 2 is the command name in parentheses (it may hold spaces), field 22
     * the start time in clock ticks since boot, 20 fields after the last ')'. */
    const char *field = read ? strrchr(line, ')') : NULL;
    unsigned long long start_ticks = 0;
    int index = 2;
    for (; field != NULL && index < 22; index++) {
        field = strchr(field + 1, ' ');
        if (field != NULL && index == 21 && sscanf(field + 1, "%llu", &start_ticks) != 1)
            field = NULL;
    }
    long ticks_per_second = sysconf(_SC_CLK_TCK);
    struct timespec boot;
    if (field == NULL || start_ticks == 0 || ticks_per_second <= 0 || clock_gettime(CLOCK_BOOTTIME, &boot) != 0)
        return now;
    /* The start time counts from boot on the clock that includes suspends (CLOCK_BOOTTIME):
     * the process's age is measured there and taken off the monotonic now. */
    double age = (double)boot.tv_sec + (double)boot.tv_nsec * 1e-9 - (double)start_ticks / (double)ticks_per_second;
    return age > 0 ? now - age : now;
}
