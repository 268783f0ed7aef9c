/* body_calls.h - the step's side of body_calls.c. */
#ifndef CAROM_BODY_CALLS_H
#define CAROM_BODY_CALLS_H

#include "world.h"

/* Records every body's pose as its previous pose, at the start of the step. */
void world_remember_poses(carom_world *w);

#endif
