/* test_clock.c: the process's start on the monotonic clock (core/clock.h). */
#include "clock.h"

#include <sys/wait.h>
#include <unistd.h>

#include "support.h"

/* The start lies before now, and by no more than this test binary can have run: a misread
 * field of /proc/self/stat (another one, or the ticks taken as seconds) would put it days
 * away or after now. Two calls agree within the kernel's clock tick. */
static void process_start_is_before_now(void **state)
{
    (void)state;
    double start = clock_process_start();
    double now = clock_seconds();
    assert_true(start < now);
    assert_true(now - start < 600.0);
    double again = clock_process_start();
    assert_true(again - start < 0.011 && start - again < 0.011);
}

/* A child forked now started now, not when this binary did: its age, sent back through a
 * pipe, is below its parent's after the parent waited 30 ms (three ticks). */
static void a_new_process_is_younger(void **state)
{
    (void)state;
    struct timespec pause = {0, 30 * 1000 * 1000};
    nanosleep(&pause, NULL);
    double parent_age = clock_seconds() - clock_process_start();
    int ends[2];
    assert_int_equal(pipe(ends), 0);
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        double age = clock_seconds() - clock_process_start();
        _exit(write(ends[1], &age, sizeof age) == sizeof age ? 0 : 1);
    }
    double child_age = -1;
    assert_int_equal(read(ends[0], &child_age, sizeof child_age), (int)sizeof child_age);
    int status = 0;
    waitpid(child, &status, 0);
    close(ends[0]);
    close(ends[1]);
    assert_true(child_age >= 0);
    assert_true(child_age < parent_age);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(process_start_is_before_now),
        cmocka_unit_test(a_new_process_is_younger),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
