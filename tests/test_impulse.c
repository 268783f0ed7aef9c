/* test_impulse.c - the seed's collision response (lib/impulse.c) against the
 * worked examples of docs/physics.md section 9 (to 4 significant figures) and against
 * conservation laws, restitution and the Coulomb bounds over 10,000 random
 * rigid-body pairs, each approaching along n and separating along -n.
 *
 * Convention (impulse.h): n points from body 2 towards body 1,
 * vr = (vP1 - vP2).n < 0 when approaching, J n acts on body 1, -J n on body 2. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "vecmath.h"
#include "impulse.h"
#include "helpers.h"

/* |got - want| within half a unit of want's 4th significant figure: the value
 * rounds to the same 4 figures as docs/physics.md's (or straddles it by rounding) */
static void check_sig4(double got, double want, const char *what)
{
    double tol = 0.5 * pow(10.0, floor(log10(fabs(want))) - 3.0);
    if (!(fabs(got - want) <= tol)) {
        print_error("%s: got %.9g, worked example %.9g (4 significant figures: within %.3g)\n", what, got, want, tol);
        fail();
    }
}

static impulse_body particle(double m, vec3 v)
{
    impulse_body b;
    memset(&b, 0, sizeof b);
    b.v = v;
    b.w = v3_zero();
    b.inv_mass = m > 0 ? 1.0 / m : 0.0;
    b.inv_inertia = m3_zero();
    return b;
}

static impulse_body solid_sphere(double m, double r, vec3 v, vec3 w)
{
    impulse_body b = particle(m, v);
    double i = 0.4 * m * r * r;
    b.w = w;
    b.inv_inertia = m3_diag(v3(1 / i, 1 / i, 1 / i));
    return b;
}

static int v3_same(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* ---- 1. bullet -------------------------------------------------------------- */

static void test_bullet(void **state)
{
    (void)state;
    const double m = 0.010278, v = 2480.0, dt = 0.008;
    /* the bullet (body 1) moving +x is stopped by a static body; n from the
     * static body to the bullet is -x, so vr = 2480 * (-1) < 0 */
    vec3 n = v3(-1, 0, 0);
    double vr = v3_dot(v3(v, 0, 0), n);
    double J = impulse_normal_particle(1.0 / m, 0.0, vr, 0.0);
    check_sig4(J, 25.49, "bullet impulse (lb s)");
    check_rel(J, m * v, 1e-14, "impulse = m v");
    check_sig4(impulse_average_force(J, dt), 3186.0, "average force (lb)");
    vec3 after = v3_madd(v3(v, 0, 0), J / m, n);
    check_abs(after.x, 0.0, 1e-12 * v, "e = 0 stops the bullet");
    /* SI: 0.15 kg at 2480 ft/s = 755.904 m/s */
    double Jsi = impulse_normal_particle(1.0 / 0.15, 0.0, -v * 0.3048, 0.0);
    check_sig4(Jsi, 113.39, "SI impulse (N s)");
    check_sig4(impulse_average_force(Jsi, dt), 14173.0, "SI average force (N)");
    print_message("bullet: J = %.6g lb s, F = %.6g lb; SI J = %.6g N s, F = %.6g N\n", J,
                  impulse_average_force(J, dt), Jsi, impulse_average_force(Jsi, dt));
    assert_true(impulse_average_force(1.0, 0.0) == 0.0);
    assert_true(impulse_average_force(1.0, -1.0) == 0.0);
}

/* ---- 2. billiard balls ------------------------------------------------------ */

static void check_billiard(vec3 v1, vec3 v2, double m, const char *how)
{
    char what[96];
    snprintf(what, sizeof what, "%s v1+ x", how);
    check_sig4(v1.x, 5.7500, what);
    snprintf(what, sizeof what, "%s v1+ y", how);
    check_sig4(v1.y, 8.2272, what);
    snprintf(what, sizeof what, "%s v2+ x", how);
    check_sig4(v2.x, 14.2500, what);
    snprintf(what, sizeof what, "%s v2+ y", how);
    check_sig4(v2.y, -8.2272, what);
    snprintf(what, sizeof what, "%s momentum x", how);
    check_rel(m * v1.x + m * v2.x, m * 20.0, 1e-12, what);
    snprintf(what, sizeof what, "%s momentum y", how);
    check_abs(m * v1.y + m * v2.y, 0.0, 1e-12 * m * 20.0, what);
    double ke = 0.5 * m * (v3_len2(v1) + v3_len2(v2));
    snprintf(what, sizeof what, "%s KE ratio", how);
    check_sig4(ke / (0.5 * m * 400.0), 0.92875, what);
    print_message("billiard (%s): v1+ = (%.6g, %.6g), v2+ = (%.6g, %.6g) ft/s, KE ratio %.6g\n", how, v1.x, v1.y, v2.x,
                  v2.y, ke / (0.5 * m * 400.0));
}

static void test_billiard_balls(void **state)
{
    (void)state;
    const double m = 0.0115, R = 1.125 / 12.0, e = 0.9; /* R = 0.09375 ft */
    /* n0 = (sqrt3/2, -1/2) points from ball 1 towards ball 2; ball 1 is body 1,
     * so the convention's normal (from body 2 to body 1) is n = -n0 */
    vec3 n0 = v3(sqrt(3.0) / 2.0, -0.5, 0.0), n = v3_neg(n0);
    vec3 u1 = v3(20, 0, 0), u2 = v3_zero();

    /* particle form */
    double vr = v3_dot(v3_sub(u1, u2), n);
    check_sig4(vr, -17.3205, "vrn");
    double Jp = impulse_normal_particle(1 / m, 1 / m, vr, e);
    vec3 v1 = v3_madd(u1, Jp / m, n), v2 = v3_madd(u2, -Jp / m, n);
    check_billiard(v1, v2, m, "particle");
    check_sig4(v3_dot(v2, n0), 16.4545, "v2n+");
    check_sig4(v3_dot(v1, n0), 0.8660, "v1n+");

    /* rigid spheres: ball 1 centred at the origin, ball 2 at 2R n0, contact at
     * R n0; r vectors along the normal so no torque */
    impulse_body b1 = solid_sphere(m, R, u1, v3_zero()), b2 = solid_sphere(m, R, u2, v3_zero());
    vec3 r1 = v3_scale(n0, R), r2 = v3_scale(n0, -R);
    check_rel(impulse_relative_normal_velocity(&b1, &b2, r1, r2, n), vr, 1e-14, "body vr");
    double J = impulse_normal(&b1, &b2, r1, r2, n, e);
    check_rel(J, Jp, 1e-12, "body J = particle J");
    impulse_apply(&b1, &b2, r1, r2, v3_scale(n, J));
    check_billiard(b1.v, b2.v, m, "body");
    assert_true(v3_len(b1.w) <= 1e-12 && v3_len(b2.w) <= 1e-12); /* central: no spin */

    /* the same with the roles swapped: body 1 = ball 2, normal n0 */
    impulse_body c1 = solid_sphere(m, R, u2, v3_zero()), c2 = solid_sphere(m, R, u1, v3_zero());
    double J2 = impulse_collide(&c1, &c2, r2, r1, n0, e, 0.0, NULL);
    check_rel(J2, Jp, 1e-12, "swapped J");
    check_billiard(c2.v, c1.v, m, "swapped");
}

/* ---- 3. baseball and bat ---------------------------------------------------- */

static void test_baseball_and_bat(void **state)
{
    (void)state;
    const double m1 = 0.069932, m2 = 0.0099556, e = 0.46;
    const double rb = 1.375 / 12.0, rl = 1.47 / 12.0, rs = rb + rl;
    /* The worked example's n = (0.87545, 0.48330) points from the bat to the ball
     * (the bat moving +x gives it a positive vrn = 205.73); with the bat as
     * body 1 the convention's normal is its negation */
    vec3 nd = v3(sqrt(rs * rs - rb * rb) / rs, rb / rs, 0.0);
    check_sig4(nd.x, 0.87545, "n x");
    check_sig4(nd.y, 0.48330, "n y");
    vec3 n = v3_neg(nd);
    vec3 u1 = v3(103, 0, 0), u2 = v3(-132, 0, 0);
    double vr = v3_dot(v3_sub(u1, u2), n);
    check_sig4(vr, -205.73, "vrn");
    double J = impulse_normal_particle(1 / m1, 1 / m2, vr, e);
    check_sig4(J, 2.6177, "normal impulse on the ball (lb s)");

    impulse_body bat = particle(m1, u1), ball = particle(m2, u2);
    double Jc = impulse_collide(&bat, &ball, v3_scale(nd, rb), v3_scale(nd, -rl), n, e, 0.0, NULL);
    check_rel(Jc, J, 1e-12, "collide J");
    check_sig4(bat.v.x, 70.230, "bat v+ x");
    check_sig4(bat.v.y, -18.091, "bat v+ y");
    check_sig4(ball.v.x, 98.188, "ball v+ x");
    check_sig4(ball.v.y, 127.078, "ball v+ y");
    check_sig4(v3_dot(bat.v, nd), 52.740, "bat v1n+");
    check_sig4(v3_dot(ball.v, nd), 147.376, "ball v2n+");
    vec3 t = v3(-nd.y, nd.x, 0);
    check_sig4(fabs(v3_dot(bat.v, t)), 49.780, "bat tangential kept");
    check_sig4(fabs(v3_dot(ball.v, t)), 63.796, "ball tangential kept");
    /* the impulse on the ball is -J n = J nd: along nd, magnitude J */
    check_sig4(m2 * v3_dot(v3_sub(ball.v, u2), nd), 2.6177, "ball momentum change");
    check_rel(m1 * u1.x + m2 * u2.x, m1 * bat.v.x + m2 * ball.v.x, 1e-12, "momentum x");
    check_abs(m1 * bat.v.y + m2 * ball.v.y, 0.0, 1e-12, "momentum y");
    print_message("baseball: bat v+ = (%.6g, %.6g), ball v+ = (%.6g, %.6g) ft/s, impulse on the ball %.6g lb s\n",
                  bat.v.x, bat.v.y, ball.v.x, ball.v.y, J);
}

/* ---- 4. golf: spin from friction --------------------------------------------- */

/* A ball sliding on the ground (the static body 2) while it bounces: the
 * slip at P needs more than mu J to stop, so Coulomb's limit acts. */
static void test_golf_spin_sliding_bounce(void **state)
{
    (void)state;
    const double m = 0.0459, r = 0.02135, mu = 0.3, e = 0.5, I = 0.4 * m * r * r;
    vec3 n = v3(0, 0, 1);          /* from the static surface (body 2) up to the ball */
    vec3 r1 = v3(0, 0, -r), r2 = v3_zero();
    vec3 w0 = v3(0, -50, 0);       /* slip at P: 30 + 50 r, along +x */
    impulse_body ball = solid_sphere(m, r, v3(30, 0, -10), w0);
    impulse_body ground = particle(0, v3_zero());

    /* impulse_friction directly, after the normal impulse */
    impulse_body b = ball, g = ground;
    double J = impulse_normal(&b, &g, r1, r2, n, e);
    check_rel(J, (1 + e) * m * 10, 1e-12, "normal impulse");
    impulse_apply(&b, &g, r1, r2, v3_scale(n, J));
    vec3 dir;
    vec3 f = impulse_friction(&b, &g, r1, r2, n, mu, J, &dir);
    check_abs(v3_len(v3_sub(dir, v3(1, 0, 0))), 0.0, 1e-15, "slip direction +x");
    check_rel(f.x, -mu * J, 1e-15, "friction at the Coulomb limit");
    check_abs(f.y, 0.0, 1e-15 * mu * J, "friction y");
    check_abs(f.z, 0.0, 1e-15 * mu * J, "friction z");
    double k = 1 / m + r * r / I; /* the slip needs more than mu J to stop */
    assert_true(mu * J < (30 + 50 * r) / k);

    /* the whole collision */
    vec3 jt;
    double Jc = impulse_collide(&ball, &ground, r1, r2, n, e, mu, &jt);
    check_rel(Jc, J, 1e-15, "collide J");
    assert_true(v3_same(jt, f));
    /* spin about n x slip = +y grows by J mu r / I */
    vec3 axis = v3_cross(n, dir);
    check_rel(v3_dot(v3_sub(ball.w, w0), axis), J * mu * r / I, 1e-12, "w+ - w- = J mu r / I");
    check_abs(ball.w.x, 0.0, 1e-12, "no spin about x");
    check_abs(ball.w.z, 0.0, 1e-12, "no spin about z");
    check_rel(30 - ball.v.x, mu * J / m, 1e-12, "tangential speed change mu J / m");
    check_rel(ball.v.z, e * 10, 1e-12, "bounce");
    assert_true(v3_same(ground.v, v3_zero()) && v3_same(ground.w, v3_zero()));
    print_message("golf bounce: J = %.6g N s, w+ - w- = %.6g rad/s (J mu r / I = %.6g)\n", J,
                  v3_dot(v3_sub(ball.w, w0), axis), J * mu * r / I);

    /* small slip: static friction, less than mu J, stops it exactly */
    impulse_body slow = solid_sphere(m, r, v3(0.01, 0, -10), v3_zero()), g2 = ground;
    double Js = impulse_normal(&slow, &g2, r1, r2, n, e);
    impulse_apply(&slow, &g2, r1, r2, v3_scale(n, Js));
    vec3 fs = impulse_friction(&slow, &g2, r1, r2, n, mu, Js, NULL);
    assert_true(v3_len(fs) < mu * Js);
    check_rel(v3_len(fs), 0.01 / k, 1e-12, "static friction = slip / k");
    impulse_apply(&slow, &g2, r1, r2, fs);
    vec3 slip = impulse_point_velocity(&slow, r1);
    check_abs(slip.x, 0.0, 1e-12, "slip x after");
    check_abs(slip.y, 0.0, 1e-12, "slip y after");
}

/* A ball at rest struck off-centre by a lofted club face moving at 45 m/s
 * along +x: the face normal n = (cos L, 0, sin L) (from the club, body 2, to
 * the ball, body 1) misses the club's line of motion, the ball slides up the
 * face and friction gives it backspin. */
static void test_golf_spin_club_strike(void **state)
{
    (void)state;
    const double m = 0.0459, r = 0.02135, I = 0.4 * m * r * r, e = 0.8, mu = 0.12;
    const double loft = 45.0 * 3.14159265358979323846 / 180.0, speed = 45.0;
    vec3 n = v3(cos(loft), 0, sin(loft));
    vec3 r1 = v3_scale(n, -r);

    /* (a) an infinitely heavy club (kinematic: inv_mass 0, moving): closed forms
     * J = (1 + e) m vn, |dw| = mu J r / I = mu (1 + e) vn / (0.4 r) */
    {
        vec3 w0 = v3_scale(n, 3.0); /* spin before about n: no slip from it */
        impulse_body ball = solid_sphere(m, r, v3_zero(), w0), club = particle(0, v3(speed, 0, 0));
        vec3 r2 = v3(-0.01, 0.02, 0.005); /* anywhere: the club does not rotate */
        double vn = speed * cos(loft), vt = speed * sin(loft);
        double k = 1 / m + r * r / I;
        assert_true(mu * (1 + e) * m * vn < vt / k); /* sliding: the mu J limit acts */
        vec3 jt;
        double J = impulse_collide(&ball, &club, r1, r2, n, e, mu, &jt);
        check_rel(J, (1 + e) * m * vn, 1e-13, "club J = (1 + e) m vn");
        check_rel(v3_len(jt), mu * J, 1e-13, "|friction| = mu J");
        vec3 up_face = v3(-sin(loft), 0, cos(loft)); /* the ball slides up the face */
        check_rel(v3_dot(jt, up_face), -mu * J, 1e-13, "friction down the face");
        vec3 dw = v3_sub(ball.w, w0);
        double spin = mu * (1 + e) * vn / (0.4 * r);
        check_rel(-dw.y, spin, 1e-13, "backspin = mu J r / I");
        check_abs(dw.x, 0.0, 1e-13 * spin, "no spin change about x");
        check_abs(dw.z, 0.0, 1e-13 * spin, "no spin change about z");
        check_rel(v3_dot(ball.v, n), (1 + e) * vn, 1e-13, "launch speed along n");
        check_rel(v3_dot(ball.v, up_face), -mu * (1 + e) * vn, 1e-13, "launch speed along the face");
        assert_true(club.v.x == speed && v3_same(club.w, v3_zero()));
        print_message("golf club (infinite mass): J = %.6g N s, backspin %.6g rad/s (%.5g rpm)\n", J, -dw.y,
                      -dw.y * 60 / (2 * 3.14159265358979323846));
    }

    /* (b) a real club head (0.2 kg, rotated box-like inertia, spinning) hit
     * off its centre of mass: w+ = w- + J mu r / I about n x slip, checked
     * against impulse_friction / impulse_collide, and momentum conserved */
    {
        vec3 w0 = v3(20, -30, 10); /* any spin before */
        impulse_body ball = solid_sphere(m, r, v3_zero(), w0);
        const double mc = 0.2;
        mat3 rot = m3_from_quat(q_normalize((quat){0.9, 0.1, -0.3, 0.2}));
        mat3 ic = m3_rotate_tensor(rot, m3_diag(v3(4.0e-4, 2.5e-4, 4.6e-4)));
        impulse_body club = particle(mc, v3(speed, 0, 0));
        club.w = v3(0.5, -2.0, 4.0);
        club.inv_inertia = m3_inverse(ic);
        vec3 r2 = v3(-0.02, 0.025, -0.008); /* toe-side, low: off the club's centre */

        impulse_body b = ball, c = club;
        double J = impulse_normal(&b, &c, r1, r2, n, e);
        assert_true(J > 0);
        impulse_apply(&b, &c, r1, r2, v3_scale(n, J));
        vec3 slip = v3_sub(impulse_point_velocity(&b, r1), impulse_point_velocity(&c, r2));
        slip = v3_sub(slip, v3_scale(n, v3_dot(slip, n)));
        vec3 dir;
        vec3 f = impulse_friction(&b, &c, r1, r2, n, mu, J, &dir);
        check_abs(v3_len(v3_sub(dir, v3_scale(slip, 1 / v3_len(slip)))), 0.0, 1e-14, "slip direction");
        assert_true(mu * J < v3_len(slip) / impulse_inverse_effective_mass(&b, &c, r1, r2, dir));
        check_rel(v3_len(f), mu * J, 1e-14, "|friction| = mu J");

        vec3 jt;
        double Jc = impulse_collide(&ball, &club, r1, r2, n, e, mu, &jt);
        assert_true(Jc == J && v3_same(jt, f));
        vec3 dw = v3_sub(ball.w, w0), axis = v3_cross(n, dir);
        double spin = J * mu * r / I;
        check_rel(v3_dot(dw, axis), spin, 1e-12, "w+ - w- = J mu r / I");
        check_abs(v3_len(v3_sub(dw, v3_scale(axis, spin))), 0.0, 1e-12 * spin, "spin only about n x slip");
        assert_true(dw.y < 0); /* backspin */
        /* momentum of ball + club, linear and about the ball's centre */
        vec3 p0 = v3_scale(v3(speed, 0, 0), mc);
        vec3 p1 = v3_add(v3_scale(ball.v, m), v3_scale(club.v, mc));
        check_abs(v3_len(v3_sub(p1, p0)), 0.0, 1e-13 * v3_len(p0), "linear momentum");
        vec3 cc = v3_add(r1, v3_neg(r2)); /* club centre relative to the ball centre: P - r2 */
        mat3 ib = m3_diag(v3(I, I, I));
        vec3 l0 = v3_add(angular_momentum_about(m, ib, v3_zero(), v3_zero(), w0, v3_zero()),
                         angular_momentum_about(mc, ic, cc, v3(speed, 0, 0), v3(0.5, -2.0, 4.0), v3_zero()));
        vec3 l1 = v3_add(angular_momentum_about(m, ib, v3_zero(), ball.v, ball.w, v3_zero()),
                         angular_momentum_about(mc, ic, cc, club.v, club.w, v3_zero()));
        check_abs(v3_len(v3_sub(l1, l0)), 0.0, 1e-12 * v3_len(l0), "angular momentum");
        print_message("golf club (0.2 kg, off-centre): J = %.6g N s, backspin %.6g rad/s = J mu r / I %.6g\n", J,
                      v3_dot(dw, axis), spin);
    }
}

/* ---- 5. properties over random pairs ------------------------------------------ */

static double rsym(uint64_t *s) { return 2.0 * rnd(s) - 1.0; }
static double loguni(uint64_t *s, double lo, double hi) { return lo * pow(hi / lo, rnd(s)); }
static vec3 rvec(uint64_t *s, double scale) { return v3(scale * rsym(s), scale * rsym(s), scale * rsym(s)); }

static vec3 runit(uint64_t *s)
{
    for (;;) {
        vec3 v = rvec(s, 1.0);
        double l = v3_len(v);
        if (l > 0.1 && l <= 1.0) return v3_scale(v, 1.0 / l);
    }
}

typedef struct rigid {
    impulse_body b;
    double m;      /* 0 for static */
    mat3 inertia;  /* world frame, the inverse of b.inv_inertia (zero when static) */
    vec3 c;
} rigid;

/* A body with mass log-uniform in [1e-3, 1e3], principal moments m * [0.1, 10]
 * in a random orientation (R diag R^T). A static body keeps a (kinematic)
 * velocity, and a zero angular velocity when spin is 0. */
static rigid random_body(uint64_t *s, int is_static, int spin)
{
    rigid r;
    memset(&r, 0, sizeof r);
    r.m = loguni(s, 1e-3, 1e3);
    vec3 d = v3(r.m * loguni(s, 0.1, 10), r.m * loguni(s, 0.1, 10), r.m * loguni(s, 0.1, 10));
    quat q = {0, 0, 0, 0};
    double ql = 0;
    while (!(ql > 0.1 && ql <= 1.0)) {
        q.w = rsym(s); q.x = rsym(s); q.y = rsym(s); q.z = rsym(s);
        ql = q_len(q);
    }
    mat3 rot = m3_from_quat(q_normalize(q));
    r.c = rvec(s, 2.0);
    r.b.v = rvec(s, 5.0);
    r.b.w = spin ? rvec(s, 5.0) : v3_zero();
    if (is_static) {
        r.m = 0;
        r.b.inv_mass = 0;
        r.b.inv_inertia = m3_zero();
        r.inertia = m3_zero();
    } else {
        r.b.inv_mass = 1.0 / r.m;
        r.b.inv_inertia = m3_inverse(m3_rotate_tensor(rot, m3_diag(d)));
        r.inertia = m3_inverse(r.b.inv_inertia);
    }
    return r;
}

static vec3 rel_velocity(const rigid *a, const rigid *b, vec3 ra, vec3 rb)
{
    return v3_sub(impulse_point_velocity(&a->b, ra), impulse_point_velocity(&b->b, rb));
}

static vec3 tangential(vec3 v, vec3 n) { return v3_sub(v, v3_scale(n, v3_dot(v, n))); }

/* The size of the terms that make up the point velocities at P (for relative
 * tolerances that do not shrink when the terms cancel). */
static double point_speed_scale(const rigid *a, const rigid *b, vec3 ra, vec3 rb)
{
    return v3_len(a->b.v) + v3_len(a->b.w) * v3_len(ra) + v3_len(b->b.v) + v3_len(b->b.w) * v3_len(rb);
}

/* Kinetic energy of the pair in a frame moving with velocity u (the centre of
 * mass, or a static body that does not rotate): the part a collision can change. */
static double energy_in_frame(const rigid *a, const rigid *b, vec3 u)
{
    return kinetic_energy(a->m, a->inertia, v3_sub(a->b.v, u), a->b.w) +
           kinetic_energy(b->m, b->inertia, v3_sub(b->b.v, u), b->b.w);
}

static double momentum_scale(const rigid *r) { return r->m * v3_len(r->b.v); }

static double angular_momentum_scale(const rigid *r, vec3 o)
{
    return v3_len(m3_mulv(r->inertia, r->b.w)) + r->m * v3_len(v3_cross(v3_sub(r->c, o), r->b.v));
}

static int unchanged(const rigid *x, const rigid *x0)
{
    return v3_same(x->b.v, x0->b.v) && v3_same(x->b.w, x0->b.w);
}

#define PROP_FAIL(...)                                                                                   \
    do {                                                                                                  \
        print_error("seed 0x%llx case %d: ", (unsigned long long)seed, k);                                \
        print_error(__VA_ARGS__);                                                                         \
        fail();                                                                                           \
    } while (0)

/* the worst relative error seen, so the margin under each tolerance shows */
static void track(double *worst, double err) { if (err > *worst) *worst = err; }

static void test_random_pairs(void **state)
{
    (void)state;
    const uint64_t seed = 0x9E3779B97F4A7C15ULL;
    const double tol = 1e-9;
    uint64_t s = seed;
    int statics = 0, limited = 0, sticking = 0, frames = 0;
    double w_lin = 0, w_ang = 0, w_rest = 0, w_elastic = 0, w_grow = 0, w_coulomb = 0, w_reverse = 0, w_stop = 0;
    const int pairs = 10000;
    for (int k = 0; k < pairs; k++) {
        /* ~10% body 1 static, ~10% body 2 static; half the statics do not spin */
        int mode = (int)(xorshift64(&s) % 10), spin = (int)(xorshift64(&s) & 1);
        int stat1 = mode == 0, stat2 = mode == 1, stat = stat1 || stat2;
        rigid a = random_body(&s, stat1, !stat1 || spin), b = random_body(&s, stat2, !stat2 || spin);
        vec3 n = runit(&s), P = rvec(&s, 2.0), o = rvec(&s, 3.0);
        double e = rnd(&s), mu = rnd(&s);
        vec3 ra = v3_sub(P, a.c), rb = v3_sub(P, b.c);
        statics += stat;

        double vr0 = impulse_relative_normal_velocity(&a.b, &b.b, ra, rb, n);
        if (!(vr0 != 0.0)) PROP_FAIL("vr exactly 0 from random input\n");
        if (vr0 > 0) { n = v3_neg(n); vr0 = -vr0; } /* every pair approaches along n ... */
        const rigid a0 = a, b0 = b;
        double scale0 = point_speed_scale(&a0, &b0, ra, rb);

        /* ... and separates along -n: nothing happens */
        {
            rigid as = a0, bs = b0;
            vec3 jt = v3(1, 1, 1);
            double J = impulse_collide(&as.b, &bs.b, ra, rb, v3_neg(n), e, mu, &jt);
            if (J != 0.0 || !v3_same(jt, v3_zero()) || !unchanged(&as, &a0) || !unchanged(&bs, &b0))
                PROP_FAIL("separating contact changed something, J = %g\n", J);
        }

        /* the normal impulse alone: vr after = -e vr before */
        rigid am = a0, bm = b0;
        double Jm = impulse_normal(&am.b, &bm.b, ra, rb, n, e);
        if (!(isfinite(Jm) && Jm > 0)) PROP_FAIL("normal impulse %g for an approaching pair\n", Jm);
        impulse_apply(&am.b, &bm.b, ra, rb, v3_scale(n, Jm));
        double vr1 = impulse_relative_normal_velocity(&am.b, &bm.b, ra, rb, n);
        double scale_mid = point_speed_scale(&am, &bm, ra, rb);
        double err = fabs(vr1 + e * vr0) / (scale0 + scale_mid);
        track(&w_rest, err);
        if (!(err <= tol)) PROP_FAIL("vr after %.17g, expected -e vr = %.17g\n", vr1, -e * vr0);
        vec3 slip_mid = tangential(rel_velocity(&am, &bm, ra, rb), n);
        double slip_len = v3_len(slip_mid);
        vec3 slip_hat = v3_scale(slip_mid, 1.0 / slip_len);

        /* the whole collision with friction */
        vec3 jt;
        double J = impulse_collide(&a.b, &b.b, ra, rb, n, e, mu, &jt);
        if (!(v3_is_finite(jt) && v3_is_finite(a.b.v) && v3_is_finite(a.b.w) && v3_is_finite(b.b.v) &&
              v3_is_finite(b.b.w)))
            PROP_FAIL("non-finite result\n");
        if (J != Jm) PROP_FAIL("collide J %.17g != impulse_normal %.17g\n", J, Jm);

        /* Coulomb: |jt| <= mu J, opposite to the slip it acts on */
        double jtl = v3_len(jt);
        track(&w_coulomb, jtl / (mu * J) - 1);
        if (!(jtl <= mu * J * (1 + 1e-12))) PROP_FAIL("friction %.17g above mu J %.17g\n", jtl, mu * J);
        if (!(v3_len(v3_add(jt, v3_scale(slip_hat, jtl))) <= 1e-12 * jtl))
            PROP_FAIL("friction not opposite the slip\n");
        /* never reverses the slip; where below mu J (static), stops it along t */
        double along = v3_dot(tangential(rel_velocity(&a, &b, ra, rb), n), slip_hat);
        double slip_tol = tol * (scale_mid + point_speed_scale(&a, &b, ra, rb));
        track(&w_reverse, -along / slip_tol * tol);
        if (!(along >= -slip_tol)) PROP_FAIL("slip reversed: %.6g along the slip of %.6g before\n", along, slip_len);
        if (jtl < mu * J * (1 - 1e-12)) {
            sticking++;
            track(&w_stop, fabs(along) / slip_tol * tol);
            if (!(fabs(along) <= slip_tol)) PROP_FAIL("static friction left a slip of %.6g\n", along);
        } else {
            limited++;
        }

        if (stat) {
            const rigid *st = stat1 ? &a : &b, *st0 = stat1 ? &a0 : &b0;
            if (!unchanged(st, st0)) PROP_FAIL("static body's velocity changed\n");
        } else {
            vec3 p0 = v3_add(v3_scale(a0.b.v, a0.m), v3_scale(b0.b.v, b0.m));
            vec3 p1 = v3_add(v3_scale(a.b.v, a.m), v3_scale(b.b.v, b.m));
            double ps = momentum_scale(&a0) + momentum_scale(&b0) + momentum_scale(&a) + momentum_scale(&b);
            err = v3_len(v3_sub(p1, p0)) / ps;
            track(&w_lin, err);
            if (!(err <= tol)) PROP_FAIL("linear momentum off by %.3g relative\n", err);
            vec3 l0 = v3_add(angular_momentum_about(a0.m, a0.inertia, a0.c, a0.b.v, a0.b.w, o),
                             angular_momentum_about(b0.m, b0.inertia, b0.c, b0.b.v, b0.b.w, o));
            vec3 l1 = v3_add(angular_momentum_about(a.m, a.inertia, a.c, a.b.v, a.b.w, o),
                             angular_momentum_about(b.m, b.inertia, b.c, b.b.v, b.b.w, o));
            double ls = angular_momentum_scale(&a0, o) + angular_momentum_scale(&b0, o) +
                        angular_momentum_scale(&a, o) + angular_momentum_scale(&b, o);
            err = v3_len(v3_sub(l1, l0)) / ls;
            track(&w_ang, err);
            if (!(err <= tol)) PROP_FAIL("angular momentum about o off by %.3g relative\n", err);
        }

        /* energy, in the centre-of-mass frame or the frame of a static body
         * that does not rotate (a spinning static body can feed energy in) */
        if (!stat || !spin) {
            vec3 u = stat1 ? a0.b.v
                   : stat2 ? b0.b.v
                           : v3_scale(v3_add(v3_scale(a0.b.v, a0.m), v3_scale(b0.b.v, b0.m)), 1.0 / (a0.m + b0.m));
            frames++;
            double ke0 = energy_in_frame(&a0, &b0, u), ke1 = energy_in_frame(&a, &b, u);
            track(&w_grow, (ke1 - ke0) / ke0);
            if (!(ke1 <= ke0 * (1 + tol))) PROP_FAIL("kinetic energy grew %.17g -> %.17g\n", ke0, ke1);
            rigid ae = a0, be = b0;
            impulse_collide(&ae.b, &be.b, ra, rb, n, 1.0, 0.0, NULL);
            double ke_el = energy_in_frame(&ae, &be, u);
            err = fabs(ke_el - ke0) / ke0;
            track(&w_elastic, err);
            if (!(err <= tol)) PROP_FAIL("elastic frictionless energy %.17g -> %.17g\n", ke0, ke_el);
        }
    }
    print_message("random pairs: seed 0x%llx, %d pairs approaching (and separating along -n), %d with a static body, "
                  "%d at mu J, %d sticking, %d energy frames\n",
                  (unsigned long long)seed, pairs, statics, limited, sticking, frames);
    print_message("worst relative errors (limit %.0e): momentum %.2g, angular momentum %.2g, vr+ + e vr- %.2g, "
                  "elastic energy %.2g, energy growth %.2g, |jt|/(mu J)-1 %.2g, slip reversal %.2g, static slip %.2g\n",
                  tol, w_lin, w_ang, w_rest, w_elastic, w_grow, w_coulomb, w_reverse, w_stop);
    assert_true(statics > 1500);
    assert_true(limited > 1000 && sticking > 1000);
}

/* ---- 6. degenerate inputs ----------------------------------------------------- */

static void test_degenerate(void **state)
{
    (void)state;
    vec3 n = v3(0, 0, 1), r1 = v3(0.1, 0.2, -0.5), r2 = v3(-0.3, 0.1, 0.5);
    /* zero relative velocity at P (spinning bodies, matching point velocities) */
    impulse_body a = solid_sphere(2, 0.5, v3(1, 2, 3), v3(0.5, -1, 2));
    impulse_body b = solid_sphere(3, 0.5, v3_zero(), v3_zero());
    b.v = v3_sub(impulse_point_velocity(&a, r1), v3_cross(b.w, r2));
    assert_true(impulse_relative_normal_velocity(&a, &b, r1, r2, n) == 0.0);
    impulse_body a0 = a, b0 = b;
    vec3 jt = v3(9, 9, 9);
    assert_true(impulse_normal(&a, &b, r1, r2, n, 0.5) == 0.0);
    assert_true(impulse_collide(&a, &b, r1, r2, n, 0.5, 0.7, &jt) == 0.0);
    assert_true(v3_same(jt, v3_zero()));
    assert_true(v3_same(a.v, a0.v) && v3_same(a.w, a0.w) && v3_same(b.v, b0.v) && v3_same(b.w, b0.w));

    /* separating */
    a.v = v3_add(a.v, v3(0.3, 0, 2));
    a0 = a;
    assert_true(impulse_relative_normal_velocity(&a, &b, r1, r2, n) > 0.0);
    assert_true(impulse_normal(&a, &b, r1, r2, n, 1.0) == 0.0);
    assert_true(impulse_collide(&a, &b, r1, r2, n, 1.0, 1.0, &jt) == 0.0);
    assert_true(v3_same(jt, v3_zero()));
    assert_true(v3_same(a.v, a0.v) && v3_same(a.w, a0.w) && v3_same(b.v, b0.v) && v3_same(b.w, b0.w));
    assert_true(impulse_normal_particle(1, 1, 2.0, 1.0) == 0.0);
    assert_true(impulse_normal_particle(1, 1, 0.0, 1.0) == 0.0);

    /* zero slip: friction zero, no NaN, zero slip direction */
    impulse_body p = particle(1, v3(0, 0, -3)), q = particle(1, v3_zero());
    vec3 dir = v3(7, 7, 7);
    vec3 f = impulse_friction(&p, &q, v3_zero(), v3_zero(), n, 0.5, 2.0, &dir);
    assert_true(v3_same(f, v3_zero()) && v3_same(dir, v3_zero()));
    double J = impulse_collide(&p, &q, v3_zero(), v3_zero(), n, 0.5, 0.5, &jt);
    assert_true(J > 0 && v3_same(jt, v3_zero()) && v3_is_finite(p.v) && v3_is_finite(q.v));
    check_rel(J, 2.25, 1e-15, "zero-slip J = 1.5 * 3 / 2");
    check_rel(p.v.z, -0.75, 1e-15, "zero-slip v1+");
    check_rel(q.v.z, -2.25, 1e-15, "zero-slip v2+");

    /* both static: nothing, finite */
    impulse_body s1 = particle(0, v3(0, 0, -1)), s2 = particle(0, v3(0, 0, 1));
    impulse_body s10 = s1, s20 = s2;
    assert_true(impulse_normal(&s1, &s2, r1, r2, n, 0.5) == 0.0);
    dir = v3_zero();
    f = impulse_friction(&s1, &s2, r1, r2, n, 0.5, 1.0, &dir);
    assert_true(v3_same(f, v3_zero()) && v3_is_finite(dir));
    J = impulse_collide(&s1, &s2, r1, r2, n, 0.5, 0.5, &jt);
    assert_true(J == 0.0 && v3_same(jt, v3_zero()));
    assert_true(v3_same(s1.v, s10.v) && v3_same(s1.w, s10.w) && v3_same(s2.v, s20.v) && v3_same(s2.w, s20.w));
    assert_true(impulse_normal_particle(0, 0, -1, 0.5) == 0.0);
    assert_true(impulse_inverse_effective_mass(&s1, &s2, r1, r2, n) == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bullet),
        cmocka_unit_test(test_billiard_balls),
        cmocka_unit_test(test_baseball_and_bat),
        cmocka_unit_test(test_golf_spin_sliding_bounce),
        cmocka_unit_test(test_golf_spin_club_strike),
        cmocka_unit_test(test_random_pairs),
        cmocka_unit_test(test_degenerate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
