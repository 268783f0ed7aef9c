/* shape_def.h - a public carom_shape_def checked and turned into the internal
 * shape (hull built), shared by body creation and the shape queries. */
#ifndef CAROM_SHAPE_DEF_H
#define CAROM_SHAPE_DEF_H

#include "world.h"

/* The rules on a shape def alone (a compound's children are checked with
 * the body def); "fn: message" on the world on error. */
carom_status shape_def_check(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn);
/* Validates sd for a body of the given type and builds *out (a hull is
 * allocated: hull_free(out->hull) when done). On error records
 * "fn: message" on the world and returns its status; *out is then empty. */
carom_status shape_from_def(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn,
                            shape *out);

#endif
