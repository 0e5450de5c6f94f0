/* test_large_pages.c: core/large_pages.h: the process's posix_memalign keeps POSIX's
 * contract, and large blocks (only they, and only when asked for or where 4 KiB faults
 * are slow) carry the kernel's huge-page advice, as /proc/self/smaps shows it (the "hg"
 * VmFlag). */
#include "large_pages.h"

#include <sys/mman.h>

#include "support.h"

/* Larger than glibc's mmap threshold (at most 32 MiB): a mapping of its own, advised. */
#define OWN_MAPPING_BYTES ((size_t)40 << 20)

/* Whether the mapping that holds address has the huge-page advice (VmFlags "hg"). */
static bool advised(const void *address)
{
    FILE *maps = fopen("/proc/self/smaps", "r");
    assert_non_null(maps);
    char line[512];
    bool inside = false, found = false, result = false;
    while (!found && fgets(line, sizeof line, maps) != NULL) {
        unsigned long start, end;
        if (sscanf(line, "%lx-%lx ", &start, &end) == 2 && strchr(line, '-') < strchr(line, ' ')) {
            inside = (uintptr_t)address >= start && (uintptr_t)address < end;
            continue;
        }
        if (inside && strncmp(line, "VmFlags:", 8) == 0) {
            found = true;
            result = strstr(line, " hg") != NULL;
        }
    }
    fclose(maps);
    assert_true(found);
    return result;
}

/* The advice needs a kernel with transparent huge pages; without them the tests of it skip.
 * Asked of the kernel itself (a chroot may have no /sys): madvise fails without them. */
static bool kernel_has_huge_pages(void)
{
    size_t bytes = LARGE_PAGES_HUGE_BYTES;
    void *probe = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (probe == MAP_FAILED)
        return false;
    bool has = madvise(probe, bytes, MADV_HUGEPAGE) == 0;
    munmap(probe, bytes);
    return has;
}

/* EINVAL for alignments POSIX refuses, ENOMEM when the memory cannot be had; otherwise an
 * aligned, writable block that free() takes. */
static void posix_memalign_keeps_its_contract(void **state)
{
    (void)state;
    void *block = NULL;
    const size_t refused[] = {0, 3, sizeof(void *) / 2, 3 * sizeof(void *), 4096 + sizeof(void *)};
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++)
        assert_int_equal(posix_memalign(&block, refused[k], 64), EINVAL);
    assert_null(block);
#ifndef __SANITIZE_ADDRESS__
    /* AddressSanitizer ends the process on such a request instead (allocator_may_return_null=0). */
    assert_int_equal(posix_memalign(&block, 64, SIZE_MAX - 4096), ENOMEM);
    assert_null(block);
#endif
    const size_t alignments[] = {sizeof(void *), 64, 4096, (size_t)2 << 20};
    const size_t sizes[] = {1, 100, (size_t)3 << 20};
    for (size_t a = 0; a < sizeof alignments / sizeof alignments[0]; a++)
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
            assert_int_equal(posix_memalign(&block, alignments[a], sizes[s]), 0);
            assert_non_null(block);
            assert_int_equal((uintptr_t)block % alignments[a], 0);
            memset(block, 0x5a, sizes[s]);
            assert_int_equal(((unsigned char *)block)[sizes[s] - 1], 0x5a);
            free(block);
        }
}

/* posix_memalign advises a block of LARGE_PAGES_ROUNDED_BYTES or more, aligned to a huge
 * page; large_pages_advise a block of LARGE_PAGES_MIN_BYTES or more, and not a smaller one. */
static void large_blocks_are_advised(void **state)
{
    (void)state;
    if (!kernel_has_huge_pages())
        skip_because(large_blocks_are_advised, "this kernel has no transparent huge pages");
    setenv("RTSPHERES_HUGE_PAGES", "1", 1);
    void *large = NULL;
    assert_int_equal(posix_memalign(&large, 64, OWN_MAPPING_BYTES), 0);
    assert_true(advised((char *)large + OWN_MAPPING_BYTES / 2));
    free(large);
    /* From LARGE_PAGES_ROUNDED_BYTES on, a block starts a huge page, so that it fills one. */
    void *medium = NULL;
    assert_int_equal(posix_memalign(&medium, 64, LARGE_PAGES_ROUNDED_BYTES + 4096), 0);
    assert_int_equal((uintptr_t)medium % LARGE_PAGES_HUGE_BYTES, 0);
    assert_true(advised(medium));
    memset(medium, 1, LARGE_PAGES_ROUNDED_BYTES + 4096);
    free(medium);
    /* large_pages_advise on a mapping of our own: the same advice, and none below the size. */
    char *mapping = mmap(NULL, 2 * LARGE_PAGES_MIN_BYTES, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    assert_true(mapping != MAP_FAILED);
    large_pages_advise(mapping, LARGE_PAGES_MIN_BYTES - 4096);
    assert_false(advised(mapping));
    large_pages_advise(mapping, 2 * LARGE_PAGES_MIN_BYTES);
    assert_true(advised(mapping));
    munmap(mapping, 2 * LARGE_PAGES_MIN_BYTES);
    unsetenv("RTSPHERES_HUGE_PAGES");
}

/* Whether large_pages_advise advises a fresh mapping of our own. */
static bool advises_a_mapping(void)
{
    size_t bytes = 2 * LARGE_PAGES_MIN_BYTES;
    char *mapping = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    assert_true(mapping != MAP_FAILED);
    large_pages_advise(mapping, bytes);
    bool result = advised(mapping);
    munmap(mapping, bytes);
    return result;
}

/* RTSPHERES_HUGE_PAGES=1 asks for the advice and =0 forbids it, whatever a fault costs;
 * RTSPHERES_NO_HUGE_PAGES=1 forbids it too. */
static void environment_decides_when_set(void **state)
{
    (void)state;
    if (!kernel_has_huge_pages())
        skip_because(environment_decides_when_set, "this kernel has no transparent huge pages");
    unsetenv("RTSPHERES_NO_HUGE_PAGES");
    setenv("RTSPHERES_HUGE_PAGES", "1", 1);
    bool when_asked = advises_a_mapping() && large_pages_advising();
    setenv("RTSPHERES_NO_HUGE_PAGES", "1", 1);
    bool asked_over_old_off = advises_a_mapping();
    setenv("RTSPHERES_HUGE_PAGES", "0", 1);
    unsetenv("RTSPHERES_NO_HUGE_PAGES");
    bool when_forbidden = advises_a_mapping() || large_pages_advising();
    unsetenv("RTSPHERES_HUGE_PAGES");
    setenv("RTSPHERES_NO_HUGE_PAGES", "1", 1);
    bool when_old_off = advises_a_mapping() || large_pages_advising();
    unsetenv("RTSPHERES_NO_HUGE_PAGES");
    assert_true(when_asked);
    assert_true(asked_over_old_off);
    assert_false(when_forbidden);
    assert_false(when_old_off);
}

/* Unset, the measured cost of a 4 KiB fault decides: measured once (the same answer
 * again), plausible (a fault costs more than nothing and less than a millisecond), and
 * the advice given exactly from LARGE_PAGES_SLOW_FAULT_MICROSECONDS on. */
static void fault_cost_decides_when_unset(void **state)
{
    (void)state;
    unsetenv("RTSPHERES_HUGE_PAGES");
    unsetenv("RTSPHERES_NO_HUGE_PAGES");
    double cost = large_pages_fault_microseconds();
    assert_true(cost > 0 && cost < 1000);
    assert_true(large_pages_fault_microseconds() == cost);
    bool slow = cost >= LARGE_PAGES_SLOW_FAULT_MICROSECONDS;
    assert_int_equal(large_pages_advising(), slow);
    if (kernel_has_huge_pages())
        assert_int_equal(advises_a_mapping(), slow);
    print_message("a 4 KiB page's first touch: %.2f us (huge pages %s)\n", cost, slow ? "advised" : "not advised");
}

/* large_pages_alloc and _calloc: image-sized arrays through the same path (aligned and
 * advised from LARGE_PAGES_ROUNDED_BYTES on, where huge pages are asked for), calloc's
 * zeroes, and NULL on overflow. */
static void image_arrays_take_the_same_path(void **state)
{
    (void)state;
    setenv("RTSPHERES_HUGE_PAGES", "1", 1);
    size_t bytes = LARGE_PAGES_ROUNDED_BYTES * 3;
    unsigned char *block = large_pages_alloc(bytes);
    assert_non_null(block);
    assert_int_equal((uintptr_t)block % LARGE_PAGES_HUGE_BYTES, 0);
    if (kernel_has_huge_pages())
        assert_true(advised(block));
    memset(block, 7, bytes);
    free(block);
    uint32_t *zeros = large_pages_calloc(bytes / sizeof(uint32_t), sizeof(uint32_t));
    assert_non_null(zeros);
    for (size_t k = 0; k < bytes / sizeof(uint32_t); k++)
        assert_int_equal(zeros[k], 0);
    free(zeros);
    unsigned char *small = large_pages_calloc(3, 5);
    assert_non_null(small);
    for (int k = 0; k < 15; k++)
        assert_int_equal(small[k], 0);
    free(small);
    assert_null(large_pages_calloc(SIZE_MAX / 2, 3));
    unsetenv("RTSPHERES_HUGE_PAGES");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(posix_memalign_keeps_its_contract),
        cmocka_unit_test(large_blocks_are_advised),
        cmocka_unit_test(environment_decides_when_set),
        cmocka_unit_test(fault_cost_decides_when_unset),
        cmocka_unit_test(image_arrays_take_the_same_path),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
