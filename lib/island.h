/* island.h - islands and sleeping (island.c). */
#ifndef CAROM_ISLAND_H
#define CAROM_ISLAND_H

#include "step.h"

/* Forms this step's islands and puts those at rest long enough to sleep. */
void world_update_sleep(carom_world *w, const step_context *ctx);

#endif
