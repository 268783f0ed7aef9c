/* impulse.h - the seed's collision response as pure functions (docs/physics.md, sections 2-3).
 * The solver calls these; the tests check these.
 *
 * Convention (the seed's): n is a unit normal pointing from body 2 towards
 * body 1; r_i = P - centre_i; vr = (vP1 - vP2).n, so vr < 0 means the bodies
 * approach. An impulse J n acts on body 1, -J n on body 2. A static body has
 * inv_mass 0 and a zero inverse inertia (infinite mass); a body whose rotation
 * is locked has a zero inverse inertia. */
#ifndef CAROM_IMPULSE_H
#define CAROM_IMPULSE_H

#include "vecmath.h"

typedef struct impulse_body {
    vec3 v;             /* linear velocity of the centre of mass */
    vec3 w;             /* angular velocity, world frame */
    double inv_mass;    /* 1/m, 0 for static */
    mat3 inv_inertia;   /* world-frame inverse inertia tensor I^-1 */
} impulse_body;

/* Velocity of the material point at offset r from the centre: v + w x r. */
static inline vec3 impulse_point_velocity(const impulse_body *b, vec3 r)
{
    return v3_add(b->v, v3_cross(b->w, r));
}

/* One body's share of the denominator: n.((I^-1 (r x n)) x r) (0 when locked). */
static inline double impulse_angular_term(const impulse_body *b, vec3 r, vec3 n)
{
    return v3_dot(n, v3_cross(m3_mulv(b->inv_inertia, v3_cross(r, n)), r));
}

/* The seed's denominator 1/m1 + 1/m2 + n.((I1^-1(r1xn))xr1) + n.((I2^-1(r2xn))xr2):
 * the inverse effective mass along direction n (also used with tangents). */
static inline double impulse_inverse_effective_mass(const impulse_body *b1, const impulse_body *b2,
                                                    vec3 r1, vec3 r2, vec3 n)
{
    return b1->inv_mass + b2->inv_mass + impulse_angular_term(b1, r1, n) + impulse_angular_term(b2, r2, n);
}

/* Applies impulse p at r1 on body 1 and -p at r2 on body 2. */
static inline void impulse_apply(impulse_body *b1, impulse_body *b2, vec3 r1, vec3 r2, vec3 p)
{
    b1->v = v3_madd(b1->v, b1->inv_mass, p);
    b1->w = v3_add(b1->w, m3_mulv(b1->inv_inertia, v3_cross(r1, p)));
    b2->v = v3_madd(b2->v, -b2->inv_mass, p);
    b2->w = v3_sub(b2->w, m3_mulv(b2->inv_inertia, v3_cross(r2, p)));
}

/* Relative normal velocity vr = (vP1 - vP2).n. */
double impulse_relative_normal_velocity(const impulse_body *b1, const impulse_body *b2,
                                        vec3 r1, vec3 r2, vec3 n);
/* Particles / spheres without rotation: J = -(1+e) vr / (1/m1 + 1/m2); 0 when
 * vr >= 0 (separating) or both masses are infinite. */
double impulse_normal_particle(double inv_mass1, double inv_mass2, double vr, double e);
/* Rigid bodies: J = -(1+e) vr / denominator; 0 when separating or both static. */
double impulse_normal(const impulse_body *b1, const impulse_body *b2, vec3 r1, vec3 r2, vec3 n, double e);
/* Coulomb friction after a normal impulse jn >= 0 has been applied: the
 * tangential impulse on body 1 (vector, along -slip direction), magnitude
 * min(mu jn, what stops the slip at the point). Zero slip gives zero (no NaN).
 * *slip_dir receives the unit tangent t = ((n x vr) x n)/|...| (or zero). */
vec3 impulse_friction(const impulse_body *b1, const impulse_body *b2, vec3 r1, vec3 r2, vec3 n,
                      double mu, double jn, vec3 *slip_dir);

/* A whole collision: normal impulse with restitution e, applied, then
 * friction, applied. Returns the normal impulse J (>= 0); *tangent_impulse
 * (may be NULL) gets the friction impulse vector on body 1. */
double impulse_collide(impulse_body *b1, impulse_body *b2, vec3 r1, vec3 r2, vec3 n, double e,
                       double mu, vec3 *tangent_impulse);

/* Average impulsive force = impulse / contact time (0 when dt <= 0). */
double impulse_average_force(double impulse, double contact_time);
/* (1/2) m v.v + (1/2) w.I.w with I the world-frame inertia tensor. */
double kinetic_energy(double mass, mat3 inertia_world, vec3 v, vec3 w);
/* Angular momentum about point o of a body: I w + (c - o) x m v. */
vec3 angular_momentum_about(double mass, mat3 inertia_world, vec3 center, vec3 v, vec3 w, vec3 o);

#endif
