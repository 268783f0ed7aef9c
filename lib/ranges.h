/* ranges.h - the ranges a world supports (docs/ranges.md has the table and
 * the derivation). Every public entry refuses a value outside them at the
 * call that introduces it, naming the value and the limit.
 *
 * Why these numbers: inside them every product the step forms stays below
 * about 1e100 and every divisor above 1e-100, far inside double precision
 * (1.8e308 .. 2.2e-308), with room for sums over millions of bodies:
 *   kinetic energy m v^2 <= 1e15 (1e9)^2 = 1e33; I w^2 <= 1e30 (1e9)^2 = 1e48;
 *   the inertia's determinant (m3_inverse) I^3 in [1e-72, 1e90], and of its
 *   inverse likewise; a contact's r^2 / I <= (2e6)^2 / 1e-24 = 4e36;
 *   a hit's J / dt <= (1e15 * 2e9) / 1e-6 = 2e30; mu N <= 1e3 * 2e24;
 *   the soft contact's h omega in [1.6e-8 * 2 pi 1e-3, 1 * 2 pi 1e6]. */
#ifndef CAROM_RANGES_H
#define CAROM_RANGES_H

#define RANGE_COORDINATE_MAX 1e12   /* m: |position component|, |plane offset| */
/* m: |coordinate| of a body's pose in a world's state (the snapshot reader's
 * bound). The calls refuse a position beyond 1e12, but a step does not stop
 * a body there: one at the edge moves on, at most 1e9 m/s x 1 s a step (a
 * fuzzed body at 1e12 m fell past it and its snapshot was refused). At 1e18
 * (a million steps at the speed ceiling beyond 1e15) squares and products of
 * three coordinates stay below 1e54; the snapshot fuzz harness steps every
 * accepted world and checks it stays finite. A plane-locked body's plane
 * offset n.c has the same bound. */
#define RANGE_STATE_COORDINATE_MAX 1e18
#define RANGE_LENGTH_MIN 1e-6       /* m: radius, half extent, half height */
/* A moving body's half thickness (shape_thickness) over the largest
 * |coordinate| of its position: contacts are found in world coordinates,
 * where a point carries half an ulp of them (1.1e-16 |x|) and a sub-step's
 * motion is rounded to it. Measured on a tilted plane at 1e12 m (ulp 1.2e-4
 * m), sliding 10 s, every preset, dt 1/12 to 1/1000: any sphere sank up to
 * 2.2 mm (0.07 mm at the origin); a 1 cm one 8.7 mm, a 1 mm one 3.5 mm
 * past its radius, a fuzzed 3.45 um hull 0.1 m (its impulses went into spin
 * about lever arms 35 times its size). At 1e-13 (10 cm there, 450 ulps) the
 * overlap stays within 2.2 % of the thickness. It binds only beyond 1e7 m
 * (there 1e-6 m, the smallest length). */
#define RANGE_THICKNESS_PER_COORDINATE 1e-13
#define RANGE_LENGTH_MAX 1e6        /* m: the same, and |hull point component| */
#define RANGE_MASS_MIN 1e-9         /* kg: a dynamic body's mass, given or from density */
#define RANGE_MASS_MAX 1e15         /* kg */
#define RANGE_DENSITY_MIN 1e-6      /* kg/m^3 (0 = not used) */
#define RANGE_DENSITY_MAX 1e9       /* kg/m^3 */
#define RANGE_INERTIA_MIN 1e-24     /* kg m^2: smallest principal moment (a lower bound of it) */
#define RANGE_INERTIA_MAX 1e30      /* kg m^2: largest principal moment (an upper bound of it) */
/* trace^3 / det of the inertia: 27 for a sphere, about 8 I_max / I_min for a
 * needle (always between I_max / I_min and 27 times it). The world-frame
 * inverse inertia R diag(1/I) R^T carries a rounding of a few ulps of 1/I_min
 * in every term, and its smallest true value is 1/I_max: above about 1e15
 * (1/eps) the tensor is noise along the stiff axes, indefinite, and impacts
 * add energy (a 2.6e-5 m x 84 km capsule, ratio 1.7e18: its transverse
 * 1/I of 1.3e-6 computed as -1.1e-5, rounding of 5e-18 of 1/I_min; it went
 * 9.6e166 m into the ground in 17 steps). At 1e12 (ratio <= 1.25e11 for a
 * needle) that rounding is 6e-7 of 1/I_max (2.8e-5 at a whole ulp). */
#define RANGE_ANISOTROPY_MAX 1e12
#define RANGE_SPEED_MAX 1e9         /* m/s and rad/s: ceiling of max_linear/angular_speed */
/* m/s and rad/s: floor of max_linear/angular_speed (an explicit one): the
 * smallest length over the longest step, 1e-6 m / 1 s; a slower cap holds
 * every body below what the lengths resolve */
#define RANGE_SPEED_MIN 1e-6
#define RANGE_ACCELERATION_MAX 1e9  /* m/s^2: |gravity| x |gravity_scale|, |force| / mass */
#define RANGE_GRAVITY_MAX 1e4       /* m/s^2: |world gravity| */
#define RANGE_GRAVITY_SCALE_MAX 1e4 /* |gravity_scale| */
#define RANGE_FRICTION_MAX 1e3      /* Coulomb mu */
#define RANGE_DAMPING_MAX 1e6       /* 1/s */
#define RANGE_DT_MIN 1e-6           /* s: carom_world_step */
#define RANGE_DT_MAX 1.0            /* s */
#define RANGE_HERTZ_MIN 1e-3        /* contact_hertz */
#define RANGE_HERTZ_MAX 1e6
#define RANGE_RATIO_MAX 1e6         /* contact_damping_ratio */
#define RANGE_PENALTY_MAX 1e20      /* penalty_stiffness (N/m), penalty_damping (N s/m) */
/* N s: a contact point's warm-start normal impulse (the tangent's parts within
 * RANGE_FRICTION_MAX times it): 1e6 times the largest change of momentum of
 * one body, 1e15 kg x 2e9 m/s = 2e24, leaving room for the weight of a deep
 * stack; the solver never stores a negative normal impulse */
#define RANGE_IMPULSE_MAX 1e30
#define RANGE_NORMAL_MIN 1e-12      /* length of a plane normal or a lock_to_plane normal */

#endif
