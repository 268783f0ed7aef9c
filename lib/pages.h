/* pages.h - a hint for the large blocks a step streams through. */
#ifndef CAROM_PAGES_H
#define CAROM_PAGES_H

#include <stddef.h>

/* Blocks from this size on are worth huge pages (pages.c). */
#define PAGES_HUGE_MIN ((size_t)2 << 20)

/* Asks the system to back the block p .. p + bytes with transparent huge
 * pages where it can (Linux: madvise MADV_HUGEPAGE on its whole 2 MiB
 * extents; elsewhere, or for a block under PAGES_HUGE_MIN, nothing). Pages
 * already touched stay as they are; those touched afterwards may be huge.
 * A hint only: no result depends on it, and a refusal is ignored. */
void pages_hint_huge(void *p, size_t bytes);

#endif
