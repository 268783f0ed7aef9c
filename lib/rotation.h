/* rotation.h - orientation update of a rigid body between impulses. */
#ifndef CAROM_ROTATION_H
#define CAROM_ROTATION_H

#include "vecmath.h"

/* Advances orientation q by h for a body whose world-frame angular momentum L
 * is constant over h (no torque in between). inv_inertia_local is the
 * body-frame inverse tensor. Implicit midpoint (Cayley) on
 * Euler's equations: world L is kept exactly and kinetic energy
 * L.I^-1 L / 2 to the solve's round-off at any step size. Writes the world
 * angular velocity the rotation used (the midpoint one) to *omega_mid when
 * not NULL. */
quat rotation_free_step(quat q, const mat3 *inv_inertia_local, vec3 L, double h, vec3 *omega_mid);

/* 1 when the body-frame inverse inertia is c Id (a sphere, a cube): then
 * (I w) x w = 0, w = I^-1 L is constant and the midpoint step is the plain
 * update with it, so the step skips the solve. */
static inline int rotation_is_isotropic(const mat3 *m)
{
    return m->c0.y == 0.0 && m->c0.z == 0.0 && m->c1.x == 0.0 && m->c1.z == 0.0 && m->c2.x == 0.0 &&
           m->c2.y == 0.0 && m->c0.x == m->c1.y && m->c1.y == m->c2.z;
}

/* The alternatives measured beside it (bench/rotation_methods.c):
 * ROTATION_CARRY_L: rotate about the current world w, then w = I_new^-1 L
 *   (what the step did before: L exact, energy grows ~ (w h)^2 per step);
 * ROTATION_IMPLICIT_GYRO: one Newton step of implicit Euler on the gyroscopic
 *   term, I (w1 - w0) + h w1 x I w1 = 0, then rotate with w1 (Box3D, Bullet:
 *   stable, but it drains energy and does not keep L);
 * ROTATION_SPLITTING: symplectic splitting of the free rigid body into exact
 *   rotations about the body axes (Dullweber, Leimkuhler, McLachlan 1997),
 *   Strang order x y z y x: L exact, energy error bounded O(h^2);
 * ROTATION_MIDPOINT: rotation_free_step. */
typedef enum rotation_method {
    ROTATION_CARRY_L, ROTATION_IMPLICIT_GYRO, ROTATION_SPLITTING, ROTATION_MIDPOINT
} rotation_method;

/* One step of the chosen method on a free body with body-frame inertia
 * diag(inertia) (principal axes): updates *q and the world angular velocity *w. */
void rotation_step_method(rotation_method m, quat *q, vec3 *w, vec3 inertia, double h);

#endif
