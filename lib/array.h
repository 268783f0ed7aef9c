/* array.h - growable arrays: one doubling reserve for every module. */
#ifndef CAROM_ARRAY_H
#define CAROM_ARRAY_H

#include <stdlib.h>
#include "pages.h"

/* Makes *items hold at least `need` elements of `elem` bytes (doubling from 64).
 * Returns 0 on out of memory, leaving the array as it was. */
static inline int array_reserve(void **items, int *capacity, int need, size_t elem)
{
    if (need <= *capacity) return 1;
    int n = *capacity ? *capacity : 64;
    while (n < need) n *= 2;
    void *p = realloc(*items, elem * (size_t)n);
    if (!p) return 0;
    pages_hint_huge(p, elem * (size_t)n);
    *items = p;
    *capacity = n;
    return 1;
}

/* The same for an array whose size the caller knows at each call (per-body
 * and per-contact step scratch): when it must grow, to need + need / 8
 * instead of the next doubling, so what it holds stays within an eighth of
 * what it needs. Doubling kept up to twice that (65,536 slots for 49,996
 * bodies), and in the heap a reserved page is resident as soon as the
 * allocator hands out memory it used before. */
static inline int array_reserve_near(void **items, int *capacity, int need, size_t elem)
{
    if (need <= *capacity) return 1;
    int n = need + need / 8 + 16;
    if (n < need) n = need; /* (overflow) */
    void *p = realloc(*items, elem * (size_t)n);
    if (!p) return 0;
    pages_hint_huge(p, elem * (size_t)n);
    *items = p;
    *capacity = n;
    return 1;
}

#endif
