/* sensor.h - the step's side of sensor.c. */
#ifndef CAROM_SENSOR_H
#define CAROM_SENSOR_H

#include "world.h"

/* (Every stage takes the step context; these two read only the world.)
 * Leaves the pairs the pre-solve callback refuses out of this step's solve
 * (after the collision stage and the seam pass). */
void world_pre_solve(carom_world *w, const step_context *ctx);
/* Raises the sensor events from the final poses (after the solve and
 * sleep); 0 on out of memory. */
int world_update_sensors(carom_world *w, const step_context *ctx);

#endif
