/* array.h - growable arrays: one doubling reserve for every module. */
#ifndef CAROM_ARRAY_H
#define CAROM_ARRAY_H

#include <stdlib.h>

/* Makes *items hold at least `need` elements of `elem` bytes (doubling from 64).
 * Returns 0 on out of memory, leaving the array as it was. */
static inline int array_reserve(void **items, int *capacity, int need, size_t elem)
{
    if (need <= *capacity) return 1;
    int n = *capacity ? *capacity : 64;
    while (n < need) n *= 2;
    void *p = realloc(*items, elem * (size_t)n);
    if (!p) return 0;
    *items = p;
    *capacity = n;
    return 1;
}

#endif
