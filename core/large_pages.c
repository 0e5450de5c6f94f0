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

/* Whether the advice is wanted: not when RTSPHERES_NO_HUGE_PAGES is set to anything but
 * "0" or "". getenv neither allocates nor fails, so this is safe inside an allocator, and
 * cheap next to the blocks it is asked for (a few hundred a render). */
static int advice_wanted(void)
{
    const char *off = getenv("RTSPHERES_NO_HUGE_PAGES");
    return off == NULL || off[0] == '\0' || strcmp(off, "0") == 0;
}

void large_pages_advise(void *block, size_t bytes)
{
    if (block == NULL || bytes < LARGE_PAGES_MIN_BYTES || !advice_wanted())
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
    bool whole_pages = bytes >= LARGE_PAGES_ROUNDED_BYTES && rounded >= bytes && advice_wanted();
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
