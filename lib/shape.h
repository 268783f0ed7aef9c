/* shape.h - collision shapes in their body frame: mass properties, bounds,
 * support mapping, convex hulls. One shape per body. */
#ifndef CAROM_SHAPE_H
#define CAROM_SHAPE_H

#include "vecmath.h"
#include "hull.h"

enum {
    SHAPE_SPHERE = 0,   /* radius, centred on the body origin */
    SHAPE_BOX,          /* half extents along the body axes */
    SHAPE_CAPSULE,      /* segment from -half_height to +half_height on local z, plus radius */
    SHAPE_CYLINDER,     /* axis local z, from -half_height to +half_height, radius */
    SHAPE_HULL,         /* convex hull, vertices in the body frame */
    SHAPE_PLANE,        /* static only: points x with dot(normal, x) = offset (body frame); solid below */
    SHAPE_MESH,         /* static or kinematic: triangles (mesh.h) */
    SHAPE_HEIGHTFIELD,  /* static or kinematic: a grid of heights (mesh.h) */
    SHAPE_COMPOUND,     /* convex children, each with a pose and material (shape.c; contacts: compound.c) */
    SHAPE_TYPE_COUNT
};

typedef struct shape {
    int type;
    double radius;         /* sphere, capsule, cylinder */
    double half_height;    /* capsule, cylinder */
    vec3 half_extents;     /* box */
    hull *hull;            /* SHAPE_HULL: owned by the shape */
    vec3 plane_normal;     /* SHAPE_PLANE: unit */
    double plane_offset;
    struct tri_mesh *mesh;        /* SHAPE_MESH: owned by the shape */
    struct height_field *field;   /* SHAPE_HEIGHTFIELD: owned by the shape */
    struct compound *compound;    /* SHAPE_COMPOUND: owned by the shape */
} shape;

typedef struct compound {
    int count;
    struct shape *children;  /* convex, each in its own frame */
    xform *poses;            /* child frame in the body frame */
    double *friction, *restitution, *density;
    double *rolling_resistance;  /* material.c */
    int *combine;
} compound;

/* Meshes, height fields and compounds: contacts in several manifolds. */
static inline int shape_is_composite(const shape *s)
{
    return s->type == SHAPE_MESH || s->type == SHAPE_HEIGHTFIELD || s->type == SHAPE_COMPOUND;
}
/* Frees what the shape owns (hull, mesh, height field). */
void shape_free_data(shape *s);

typedef struct mass_props {
    double mass;
    vec3 center;           /* centre of mass in the body frame */
    mat3 inertia;          /* about the centre of mass, body axes */
} mass_props;

/* Volume of a shape (0 for a plane). */
double shape_volume(const shape *s);
/* Mass properties for a density (kg/m^3). */
mass_props shape_mass_from_density(const shape *s, double density);
/* Same shape, scaled to a given total mass. */
mass_props shape_mass_from_mass(const shape *s, double mass);
/* World-space bounds of the shape at transform t (a plane gives huge bounds). */
aabb shape_aabb(const shape *s, xform t);
/* Support point in the body frame: the point of the shape farthest along dir
 * (dir need not be unit; a zero dir returns some point of the shape). */
vec3 shape_support_local(const shape *s, vec3 dir);
/* Half the thinnest width of the shape: how far it may move in a step before
 * it can pass through others (continuous collision), and the size the
 * coordinates must resolve (ranges.h); 1e300 for planes, meshes and fields. */
double shape_thickness(const shape *s);
/* Bounding radius about the body origin (used for continuous collision). */
double shape_bounding_radius(const shape *s);
/* Ray cast against a shape in its body frame: origin o, direction d (not unit),
 * t in [0, max_t]. Returns 1 and sets *t and *normal (outward) on a hit;
 * a ray starting inside the shape does not hit. */
int shape_ray_cast_local(const shape *s, vec3 o, vec3 d, double max_t, double *t, vec3 *normal);

/* A compound's own (shape.c: they recurse through the shape functions above). */
/* A compound with room for n children (count 0, children zeroed); NULL when out of memory. */
compound *compound_alloc(int n);
void compound_free(compound *c);
/* Mass properties combined exactly (parallel axis); each child at its own density. */
mass_props compound_mass(const compound *c);
aabb compound_aabb(const compound *c, xform t);
int compound_ray_cast_local(const compound *c, vec3 o, vec3 d, double max_t, double *t, vec3 *normal, int *child);

#endif
