/* pages.c - transparent huge pages for the large step blocks. A 50,000-body
 * world's solver streams about 90 MB of rows through each pass and reads
 * its bodies in no order the caches follow; in 4 KiB pages that is one
 * TLB entry, and one restart of the hardware prefetcher, every 4 KiB of
 * every stream. Linux backs a region marked MADV_HUGEPAGE with 2 MiB pages
 * as they are first touched (the default "madvise" mode of
 * /sys/kernel/mm/transparent_hugepage/enabled). The 20,020-body pyramid
 * grid took about a tenth less CPU a step with them. */
#if defined(__linux__)
#define _DEFAULT_SOURCE /* MADV_HUGEPAGE */
#include <stdint.h>
#include <sys/mman.h>
#endif
#include "pages.h"

void pages_hint_huge(void *p, size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    if (!p || bytes < PAGES_HUGE_MIN) return;
    /* only whole 2 MiB extents: the block's neighbours in the heap keep their pages */
    uintptr_t begin = ((uintptr_t)p + huge - 1) & ~(huge - 1), end = ((uintptr_t)p + bytes) & ~(huge - 1);
    if (end > begin) (void)madvise((void *)begin, (size_t)(end - begin), MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}
