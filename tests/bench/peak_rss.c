/* peak_rss.c: runs a command and reports its peak resident set size and wall time, for
 * `make bench` (tests/bench/run.sh). Debian minbase has no /usr/bin/time, and the
 * kernel already keeps the number: wait4() returns the child's rusage, whose ru_maxrss
 * (KiB on Linux) is the high-water mark of the process with all its threads, llvmpipe's
 * rendering threads included. Sampling /proc while it runs would miss short peaks.
 *
 * The CPU time (user + system, all threads) comes with it: divided by the wall time it
 * says how many cores the command really had, which is how other work on a shared
 * machine shows.
 *
 * usage: peak_rss PROGRAM [ARGS...]
 * The command's stdin, stdout and stderr are its own. When it ends, one line goes to
 * stderr (after everything the command wrote there):
 *   peak_rss: 123456 KiB peak RSS, 12.345 s wall, 23.456 s CPU
 * Exit status: the command's own; 128 + N when signal N ended it; 127 when it could not
 * be started.
 */
#define _DEFAULT_SOURCE
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* Returns seconds on the monotonic clock. */
static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Returns a timeval in seconds. */
static double timeval_seconds(struct timeval t)
{
    return (double)t.tv_sec + 1e-6 * (double)t.tv_usec;
}

/* Starts argv[1..] as a child, waits for it and prints its peak RSS, wall and CPU time;
 * returns the exit status described above. */
int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: peak_rss PROGRAM [ARGS...]\n");
        return 2;
    }
    double start = now_seconds();
    pid_t child = fork();
    if (child < 0) {
        perror("peak_rss: fork");
        return 127;
    }
    if (child == 0) {
        execvp(argv[1], argv + 1);
        fprintf(stderr, "peak_rss: cannot run %s: %s\n", argv[1], strerror(errno));
        _exit(127);
    }
    int status;
    struct rusage usage;
    pid_t waited;
    // Retry when a signal to this wrapper interrupts the wait: the child is still running.
    do
        waited = wait4(child, &status, 0, &usage);
    while (waited < 0 && errno == EINTR);
    if (waited < 0) {
        perror("peak_rss: wait4");
        return 127;
    }
    double seconds = now_seconds() - start;
    fprintf(stderr, "peak_rss: %ld KiB peak RSS, %.3f s wall, %.3f s CPU\n", usage.ru_maxrss, seconds,
            timeval_seconds(usage.ru_utime) + timeval_seconds(usage.ru_stime));
    if (WIFSIGNALED(status))
        return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
}
