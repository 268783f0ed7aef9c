/* filter.h - which pairs of bodies may touch: category/mask bits, groups and
 * the world's pair filter callback. */
#ifndef CAROM_FILTER_H
#define CAROM_FILTER_H

#include "body.h"

/* 1 when the bits and groups of the bodies at slots a and b let them touch. */
int filter_bits_allow(const body_store *s, int a, int b);

#endif
