/* shape_def.h - a public carom_shape_def checked and turned into the internal
 * shape (hull built), shared by body creation and the shape queries. */
#ifndef CAROM_SHAPE_DEF_H
#define CAROM_SHAPE_DEF_H

#include "world.h"

#define COMPOUND_MAX_CHILDREN 256

/* The reason sd is not a valid shape for a body of this type, into msg
 * (without a function name); 1 (msg untouched) when it is valid. */
int shape_def_reason(const carom_shape_def *sd, carom_body_type type, char *msg, size_t size);
/* The same for a mesh def (its size, then mesh_check), a height field def
 * (its size, then heightfield_check) and a compound's children (count, the
 * first's size, then each child's shape, pose, friction, restitution,
 * density and material). */
int mesh_def_reason(const carom_mesh_def *md, char *msg, size_t size);
int heightfield_def_reason(const carom_heightfield_def *hd, char *msg, size_t size);
int compound_children_reason(const carom_compound_child *children, int count, char *msg, size_t size);
/* Child i of a compound def's array (its stride is the first child's size). */
carom_compound_child compound_child_at(const carom_compound_child *children, int i);

/* The rules on a shape def alone (a compound's children are checked with
 * the body def); "fn: message" on the world on error. */
carom_status shape_def_check(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn);
/* Validates sd for a body of the given type and builds *out (a hull is
 * allocated: hull_free(out->hull) when done). On error records
 * "fn: message" on the world and returns its status; *out is then empty. */
carom_status shape_from_def(const carom_world *w, const carom_shape_def *sd, carom_body_type type, const char *fn,
                            shape *out);

#endif
