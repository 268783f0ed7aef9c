/* ghost.h - ghost contacts (ghost.c): contacts on the seams between static
 * bodies (mesh triangles, neighbouring boxes) dropped before the solver. */
#ifndef CAROM_GHOST_H
#define CAROM_GHOST_H

#include "step.h"

/* (Every stage takes the step context; these two read only the world.) */
void world_remove_ghost_contacts(carom_world *w, const step_context *ctx);
/* After the solve: every manifold merged into another this step takes the
 * merged manifold's solved impulses (warm starting of the next step). */
void world_share_merged_impulses(carom_world *w, const step_context *ctx);

#endif
