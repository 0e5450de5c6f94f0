/* large_pages.h: large blocks of memory on transparent huge pages (2 MiB), also the GPU
 * driver's.
 *
 * Memory is slow to touch the first time: each 4 KiB page is a page fault, and on a
 * virtual machine (CI runners, cloud farms) a fault costs about 11 us (docs/performance.md,
 * "Memory touched the first time"). llvmpipe zeroes every texture it creates, so the
 * tracer's pass state at 1200x675 (16 RGBA32F textures, 207 MB) took 0.58 s to create on
 * such a machine before the first pass, of a 6.8 s render. With the kernel's transparent
 * huge pages asked for (madvise), a fault brings 2 MiB, and the same took 0.03-0.36 s.
 *
 * Only where 4 KiB pages are slow: a 2 MiB page is not free either. The kernel (with its
 * usual "defrag" setting, madvise) finds or makes a free 2 MiB block for an advised fault,
 * and on a virtual machine that block may be memory the host has never backed, while 4
 * KiB faults get pages just freed: on a machine whose 4 KiB faults cost 2.3 us, the
 * weekend's state (1200x675) took 0.3-0.4 s longer to create with the advice than
 * without, whenever the render before it had not left huge pages free, and a 1920x1080
 * render 1.5-2.0 s against 1.2-1.3 (docs/performance.md, the log, 2026-12-06). So the
 * first large block measures what a 4 KiB page's first touch costs
 * (large_pages_fault_microseconds: 256 fresh pages of a mapping of its own, about 1 ms)
 * and advises huge pages from LARGE_PAGES_SLOW_FAULT_MICROSECONDS on, where the 11 us
 * machine above gained 0.2-0.5 s a render. RTSPHERES_HUGE_PAGES=1 in the environment
 * asks for the advice whatever the cost, RTSPHERES_HUGE_PAGES=0 (or the older
 * RTSPHERES_NO_HUGE_PAGES=1) never; to measure it, or should a system mind.
 *
 * Where the kernel's setting (/sys/kernel/mm/transparent_hugepage/enabled) is "always",
 * the advice changes nothing; where it is "never", nothing either; where it is "madvise"
 * (the default of many distributions' kernels), it is what asks.
 *
 * The driver allocates its textures with posix_memalign (Mesa 22.3), which this module
 * defines for the whole process: a shared library calls the executable's definition
 * before libc's (ELF symbol interposition; the Makefile's link of the program exports
 * it), and blocks are freed by glibc's free as before. It is glibc's memalign, except
 * that a block of LARGE_PAGES_ROUNDED_BYTES or more is aligned to a huge page, rounded up
 * to whole ones and advised: a 320x180 texture (0.9 MB) would otherwise hold no whole
 * huge page. That costs at most one huge page of memory a block where every byte is used
 * (a 1920x1080 render's peak grew by 8 MB of 740). A driver that allocates another way is
 * simply not advised; tests/render/test-large-pages.sh checks that llvmpipe's calls bind here.
 *
 * Not the heap: glibc's heap (the small blocks of Mesa's shader compiler and of the
 * libraries' start-up) stays as glibc has it. Advising it from the program's start (a
 * function in the preinit_array, glibc's thresholds at their maxima and a 64 MiB top pad;
 * 2026-12-03) sped up the first pass on one virtual machine and slowed whole renders on
 * another (2026-12-06: the weekend at 1200x675 8 spp 2.41 s against 2.02 s without it, a
 * 1920x1080 1-spp render 2.10 s against 1.59 s, the kernel zeroing 2 MiB pages the heap
 * never used), for 30 to 100 MB more at a render's peak; docs/performance.md, the log.
 *
 *   void *large_pages_alloc(size_t bytes)
 *   void *large_pages_calloc(size_t count, size_t size)
 *       malloc and calloc for arrays of an image's size (read-backs, per-pixel sums and
 *       lists): through posix_memalign above, so that from LARGE_PAGES_ROUNDED_BYTES on
 *       they start a huge page and are advised. NULL when out of memory (or, for
 *       large_pages_calloc, when count x size overflows); free with free().
 *
 *   double large_pages_fault_microseconds(void)
 *       What the first touch of a fresh 4 KiB page costs on this machine, measured once
 *       per process (the first call, about 1 ms) and then remembered; 0 if it could not be
 *       measured (no mapping to be had).
 *
 *   bool large_pages_advising(void)
 *       Whether large blocks get the advice: the environment's RTSPHERES_HUGE_PAGES, else
 *       not with RTSPHERES_NO_HUGE_PAGES=1, else whether a 4 KiB page costs at least
 *       LARGE_PAGES_SLOW_FAULT_MICROSECONDS (measured on the first call).
 *
 *   void large_pages_advise(void *block, size_t bytes)
 *       Asks for huge pages over the whole 4 KiB pages inside [block, block + bytes) when
 *       bytes >= LARGE_PAGES_MIN_BYTES. Call it before the block is first written. Never
 *       fails: without the advice the memory is the same, only slower to touch.
 */
#ifndef RT_LARGE_PAGES_H
#define RT_LARGE_PAGES_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LARGE_PAGES_HUGE_BYTES ((size_t)2 << 20)       /* x86-64's huge page */
#define LARGE_PAGES_MIN_BYTES LARGE_PAGES_HUGE_BYTES     /* large_pages_advise's smallest block */
#define LARGE_PAGES_ROUNDED_BYTES ((size_t)512 << 10)    /* posix_memalign's */
#define LARGE_PAGES_SLOW_FAULT_MICROSECONDS 5.0          /* huge pages from this 4 KiB fault cost on */

double large_pages_fault_microseconds(void);
bool large_pages_advising(void);
void *large_pages_alloc(size_t bytes);
void *large_pages_calloc(size_t count, size_t size);
void large_pages_advise(void *block, size_t bytes);

#ifdef __cplusplus
}
#endif

#endif
