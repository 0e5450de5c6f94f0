/* large_pages.c: transparent huge pages for large blocks, the GPU driver's included
 * (core/large_pages.h says why). */
#include "large_pages.h"

#include <errno.h>
#include <malloc.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

/* 0: not measured yet; else the cost of a 4 KiB page's first touch in nanoseconds + 1. */
static uint64_t fault_cost_code;

double large_pages_fault_microseconds(void)
{
    uint64_t code = __atomic_load_n(&fault_cost_code, __ATOMIC_RELAXED);
    if (code == 0) {
        /* Fresh pages of a mapping of our own, kept off huge pages, one write each: what
         * the kernel charges for the pages a large block would get. Two threads may both
         * measure; either answer will do. Nothing here allocates (this runs inside
         * posix_memalign). */
        enum { PAGES = 256, PAGE = 4096 };
        double nanoseconds = 0;
        char *probe = mmap(NULL, PAGES * PAGE, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (probe != MAP_FAILED) {
            (void)madvise(probe, PAGES * PAGE, MADV_NOHUGEPAGE);
            struct timespec start, end;
            clock_gettime(CLOCK_MONOTONIC, &start);
            for (int page = 0; page < PAGES; page++)
                ((volatile char *)probe)[page * PAGE] = 1;
            clock_gettime(CLOCK_MONOTONIC, &end);
            munmap(probe, PAGES * PAGE);
            nanoseconds = ((double)(end.tv_sec - start.tv_sec) * 1e9 + (double)(end.tv_nsec - start.tv_nsec)) / PAGES;
        }
        code = (uint64_t)(nanoseconds > 0 ? nanoseconds : 0) + 1;
        __atomic_store_n(&fault_cost_code, code, __ATOMIC_RELAXED);
    }
    return (double)(code - 1) / 1000;
}

/* Whether a setting in the environment says yes (anything but "" and "0"). */
static bool environment_says(const char *name, bool *value)
{
    const char *setting = getenv(name);
    if (setting == NULL)
        return false;
    *value = setting[0] != '\0' && strcmp(setting, "0") != 0;
    return true;
}

bool large_pages_advising(void)
{
    bool value;
    if (environment_says("RTSPHERES_HUGE_PAGES", &value))
        return value;
    if (environment_says("RTSPHERES_NO_HUGE_PAGES", &value) && value)
        return false;
    return large_pages_fault_microseconds() >= LARGE_PAGES_SLOW_FAULT_MICROSECONDS;
}

void large_pages_advise(void *block, size_t bytes)
{
    if (block == NULL || bytes < LARGE_PAGES_MIN_BYTES || !large_pages_advising())
        return;
    const uintptr_t page = 4096;
    uintptr_t start = ((uintptr_t)block + page - 1) & ~(page - 1);
    uintptr_t end = ((uintptr_t)block + bytes) & ~(page - 1);
    /* madvise fails where the kernel has no transparent huge pages: the memory is the
     * same, so the result is not looked at. */
    if (end > start)
        (void)madvise((void *)start, end - start, MADV_HUGEPAGE);
}

/* The process's posix_memalign (core/large_pages.h): glibc's memalign; a block of at least
 * LARGE_PAGES_ROUNDED_BYTES is rounded up to whole huge pages and aligned to one, so that
 * every byte of it can be on huge pages (a 320x180 texture, 0.9 MB, fits none unaligned),
 * and advised. Returns 0, EINVAL for an alignment that is not a power of two multiple of
 * sizeof(void *), or ENOMEM; *out is freed with free(). */
int posix_memalign(void **out, size_t alignment, size_t bytes)
{
    if (alignment == 0 || (alignment & (alignment - 1)) != 0 || alignment % sizeof(void *) != 0)
        return EINVAL;
    size_t rounded = (bytes + LARGE_PAGES_HUGE_BYTES - 1) & ~(LARGE_PAGES_HUGE_BYTES - 1);
    bool whole_pages = bytes >= LARGE_PAGES_ROUNDED_BYTES && rounded >= bytes && large_pages_advising();
    void *block = whole_pages ? memalign(alignment > LARGE_PAGES_HUGE_BYTES ? alignment : LARGE_PAGES_HUGE_BYTES,
                                         rounded)
                              : memalign(alignment, bytes);
    if (block == NULL)
        return ENOMEM;
    if (whole_pages)
        large_pages_advise(block, rounded);
    *out = block;
    return 0;
}

void *large_pages_alloc(size_t bytes)
{
    void *block = NULL;
    return posix_memalign(&block, 64, bytes) == 0 ? block : NULL;
}

void *large_pages_calloc(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    void *block = large_pages_alloc(count * size);
    if (block != NULL)
        memset(block, 0, count * size);
    return block;
}
