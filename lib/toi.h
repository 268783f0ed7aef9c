/* toi.h - continuous collision (toi.c): a fast or bullet body moved back to
 * its time of impact. */
#ifndef CAROM_TOI_H
#define CAROM_TOI_H

#include "step.h"

int world_continuous(carom_world *w, const step_context *ctx); /* 0 on out of memory */

#endif
