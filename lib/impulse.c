/* impulse.c - the seed's collision response (docs/physics.md sections 2-3):
 * normal impulse with restitution, its application to linear and angular
 * velocity, and Coulomb friction that never reverses the slip. */
#include <stddef.h>
#include "impulse.h"

double impulse_relative_normal_velocity(const impulse_body *b1, const impulse_body *b2, vec3 r1, vec3 r2, vec3 n)
{
    return v3_dot(v3_sub(impulse_point_velocity(b1, r1), impulse_point_velocity(b2, r2)), n);
}

double impulse_normal_particle(double inv_mass1, double inv_mass2, double vr, double e)
{
    double k = inv_mass1 + inv_mass2;
    if (!(vr < 0.0) || !(k > 0.0)) return 0.0;
    return -(1.0 + e) * vr / k;
}

double impulse_normal(const impulse_body *b1, const impulse_body *b2, vec3 r1, vec3 r2, vec3 n, double e)
{
    double vr = impulse_relative_normal_velocity(b1, b2, r1, r2, n);
    double k = impulse_inverse_effective_mass(b1, b2, r1, r2, n);
    if (!(vr < 0.0) || !(k > 0.0)) return 0.0;
    return -(1.0 + e) * vr / k;
}

vec3 impulse_friction(const impulse_body *b1, const impulse_body *b2, vec3 r1, vec3 r2, vec3 n, double mu, double jn,
                      vec3 *slip_dir)
{
    vec3 vr = v3_sub(impulse_point_velocity(b1, r1), impulse_point_velocity(b2, r2));
    /* t = ((n x vr) x n) / |...|: the slip direction in the contact plane */
    vec3 t = v3_cross(v3_cross(n, vr), n);
    double slip = v3_normalize_len(&t);
    if (slip_dir) *slip_dir = t;
    if (!(slip > 0.0) || !(jn > 0.0) || !(mu > 0.0)) return v3_zero();
    double k = impulse_inverse_effective_mass(b1, b2, r1, r2, t);
    if (!(k > 0.0)) return v3_zero();
    /* what stops the slip exactly (static friction), capped by Coulomb's mu J */
    double stop = slip / k;
    double jt = fmin(stop, mu * jn);
    return v3_scale(t, -jt);
}

double impulse_collide(impulse_body *b1, impulse_body *b2, vec3 r1, vec3 r2, vec3 n, double e, double mu,
                       vec3 *tangent_impulse)
{
    double j = impulse_normal(b1, b2, r1, r2, n, e);
    impulse_apply(b1, b2, r1, r2, v3_scale(n, j));
    vec3 jt = impulse_friction(b1, b2, r1, r2, n, mu, j, NULL);
    impulse_apply(b1, b2, r1, r2, jt);
    if (tangent_impulse) *tangent_impulse = jt;
    return j;
}

double impulse_average_force(double impulse, double contact_time)
{
    return contact_time > 0.0 ? impulse / contact_time : 0.0;
}

double kinetic_energy(double mass, mat3 inertia_world, vec3 v, vec3 w)
{
    return 0.5 * mass * v3_dot(v, v) + 0.5 * v3_dot(w, m3_mulv(inertia_world, w));
}

vec3 angular_momentum_about(double mass, mat3 inertia_world, vec3 center, vec3 v, vec3 w, vec3 o)
{
    return v3_add(m3_mulv(inertia_world, w), v3_cross(v3_sub(center, o), v3_scale(v, mass)));
}
