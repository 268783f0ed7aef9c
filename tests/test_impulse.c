/* test_impulse.c - the seed's collision response (lib/impulse.c) against the
 * worked examples of seed/DIGEST.md and against conservation laws and the
 * Coulomb bounds over 10,000 random rigid-body pairs.
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

#define REL4 5e-4 /* four significant figures */

static void check_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want))) {
        print_error("%s: got %.9g, expected %.9g (rel %.3g)\n", what, got, want, rel);
        fail();
    }
}

static void check_abs(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) {
        print_error("%s: got %.9g, expected %.9g (abs %.3g)\n", what, got, want, tol);
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
    check_rel(J, 25.49, REL4, "bullet impulse (lb s)");
    check_rel(J, m * v, 1e-14, "impulse = m v");
    check_rel(impulse_average_force(J, dt), 3186.0, REL4, "average force (lb)");
    vec3 after = v3_madd(v3(v, 0, 0), J / m, n);
    check_abs(after.x, 0.0, 1e-12 * v, "e = 0 stops the bullet");
    /* SI: 0.15 kg at 2480 ft/s = 755.904 m/s */
    double Jsi = impulse_normal_particle(1.0 / 0.15, 0.0, -v * 0.3048, 0.0);
    check_rel(Jsi, 113.39, REL4, "SI impulse (N s)");
    check_rel(impulse_average_force(Jsi, dt), 14173.0, REL4, "SI average force (N)");
    assert_true(impulse_average_force(1.0, 0.0) == 0.0);
    assert_true(impulse_average_force(1.0, -1.0) == 0.0);
}

/* ---- 2. billiard balls ------------------------------------------------------ */

static void check_billiard(vec3 v1, vec3 v2, double m, const char *how)
{
    char what[96];
    snprintf(what, sizeof what, "%s v1+ x", how);
    check_rel(v1.x, 5.7500, REL4, what);
    snprintf(what, sizeof what, "%s v1+ y", how);
    check_rel(v1.y, 8.2272, REL4, what);
    snprintf(what, sizeof what, "%s v2+ x", how);
    check_rel(v2.x, 14.2500, REL4, what);
    snprintf(what, sizeof what, "%s v2+ y", how);
    check_rel(v2.y, -8.2272, REL4, what);
    snprintf(what, sizeof what, "%s momentum x", how);
    check_rel(m * v1.x + m * v2.x, m * 20.0, 1e-12, what);
    snprintf(what, sizeof what, "%s momentum y", how);
    check_abs(m * v1.y + m * v2.y, 0.0, 1e-12 * m * 20.0, what);
    double ke = 0.5 * m * (v3_len2(v1) + v3_len2(v2));
    snprintf(what, sizeof what, "%s KE ratio", how);
    check_rel(ke / (0.5 * m * 400.0), 0.92875, REL4, what);
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
    check_rel(vr, -17.3205, REL4, "vrn");
    double Jp = impulse_normal_particle(1 / m, 1 / m, vr, e);
    vec3 v1 = v3_madd(u1, Jp / m, n), v2 = v3_madd(u2, -Jp / m, n);
    check_billiard(v1, v2, m, "particle");
    check_rel(v3_dot(v2, n0), 16.4545, REL4, "v2n+");
    check_rel(v3_dot(v1, n0), 0.8660, REL4, "v1n+");

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
    /* DIGEST's n = (0.87545, 0.48330) points from the bat to the ball
     * (the bat moving +x gives it a positive vrn = 205.73); with the bat as
     * body 1 the convention's normal is its negation */
    vec3 nd = v3(sqrt(rs * rs - rb * rb) / rs, rb / rs, 0.0);
    check_rel(nd.x, 0.87545, REL4, "n x");
    check_rel(nd.y, 0.48330, REL4, "n y");
    vec3 n = v3_neg(nd);
    vec3 u1 = v3(103, 0, 0), u2 = v3(-132, 0, 0);
    double vr = v3_dot(v3_sub(u1, u2), n);
    check_rel(vr, -205.73, REL4, "vrn");
    double J = impulse_normal_particle(1 / m1, 1 / m2, vr, e);
    check_rel(J, 2.6177, REL4, "normal impulse on the ball (lb s)");

    impulse_body bat = particle(m1, u1), ball = particle(m2, u2);
    double Jc = impulse_collide(&bat, &ball, v3_scale(nd, rb), v3_scale(nd, -rl), n, e, 0.0, NULL);
    check_rel(Jc, J, 1e-12, "collide J");
    check_rel(bat.v.x, 70.230, REL4, "bat v+ x");
    check_rel(bat.v.y, -18.091, REL4, "bat v+ y");
    check_rel(ball.v.x, 98.188, REL4, "ball v+ x");
    check_rel(ball.v.y, 127.078, REL4, "ball v+ y");
    check_rel(v3_dot(bat.v, nd), 52.740, REL4, "bat v1n+");
    check_rel(v3_dot(ball.v, nd), 147.376, REL4, "ball v2n+");
    vec3 t = v3(-nd.y, nd.x, 0);
    check_rel(fabs(v3_dot(bat.v, t)), 49.780, REL4, "bat tangential kept");
    check_rel(fabs(v3_dot(ball.v, t)), 63.796, REL4, "ball tangential kept");
    /* the impulse on the ball is -J n = J nd: along nd, magnitude J */
    check_rel(m2 * v3_dot(v3_sub(ball.v, u2), nd), 2.6177, REL4, "ball momentum change");
    check_rel(m1 * u1.x + m2 * u2.x, m1 * bat.v.x + m2 * ball.v.x, 1e-12, "momentum x");
    check_abs(m1 * bat.v.y + m2 * ball.v.y, 0.0, 1e-12, "momentum y");
}

/* ---- 4. golf: spin from friction --------------------------------------------- */

static void test_golf_spin(void **state)
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
    assert_true(v3_same(dir, v3(1, 0, 0)));
    assert_true(f.x == -(mu * J) && f.y == 0.0 && f.z == 0.0); /* Coulomb limit exactly */
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

/* ---- 5. properties over random pairs ------------------------------------------ */

static uint64_t xorshift64(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static double rnd(uint64_t *s) { return (double)(xorshift64(s) >> 11) / 9007199254740992.0; }
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
    mat3 inertia;  /* world frame */
    vec3 c;
} rigid;

static rigid random_body(uint64_t *s, int is_static)
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
    r.inertia = m3_rotate_tensor(rot, m3_diag(d));
    r.c = rvec(s, 2.0);
    r.b.v = rvec(s, 5.0);
    r.b.w = rvec(s, 5.0);
    if (is_static) {
        r.m = 0;
        r.b.inv_mass = 0;
        r.b.inv_inertia = m3_zero();
    } else {
        r.b.inv_mass = 1.0 / r.m;
        r.b.inv_inertia = m3_inverse(r.inertia);
    }
    return r;
}

static vec3 rel_velocity(const rigid *a, const rigid *b, vec3 ra, vec3 rb)
{
    return v3_sub(impulse_point_velocity(&a->b, ra), impulse_point_velocity(&b->b, rb));
}

static vec3 tangential(vec3 v, vec3 n) { return v3_sub(v, v3_scale(n, v3_dot(v, n))); }

static double energy(const rigid *a, const rigid *b)
{
    return kinetic_energy(a->m, a->inertia, a->b.v, a->b.w) + kinetic_energy(b->m, b->inertia, b->b.v, b->b.w);
}

#define PROP_FAIL(...)                                                                                   \
    do {                                                                                                  \
        print_error("seed 0x%llx case %d: ", (unsigned long long)seed, k);                                \
        print_error(__VA_ARGS__);                                                                         \
        fail();                                                                                           \
    } while (0)

static void test_random_pairs(void **state)
{
    (void)state;
    const uint64_t seed = 0x9E3779B97F4A7C15ULL;
    uint64_t s = seed;
    int approaching = 0, statics = 0, limited = 0, sticking = 0;
    for (int k = 0; k < 10000; k++) {
        int stat = (xorshift64(&s) % 10) == 0; /* body 2 static in ~10% */
        rigid a = random_body(&s, 0), b = random_body(&s, stat);
        vec3 n = runit(&s), P = rvec(&s, 2.0), o = rvec(&s, 3.0);
        double e = rnd(&s), mu = rnd(&s);
        vec3 ra = v3_sub(P, a.c), rb = v3_sub(P, b.c);
        statics += stat;

        const rigid a0 = a, b0 = b;
        double vr0 = impulse_relative_normal_velocity(&a.b, &b.b, ra, rb, n);
        double vscale = v3_len(impulse_point_velocity(&a.b, ra)) + v3_len(impulse_point_velocity(&b.b, rb));

        /* the slip friction acts on: after the normal impulse alone */
        rigid am = a, bm = b;
        double Jm = impulse_normal(&am.b, &bm.b, ra, rb, n, e);
        impulse_apply(&am.b, &bm.b, ra, rb, v3_scale(n, Jm));
        vec3 slip_mid = tangential(rel_velocity(&am, &bm, ra, rb), n);
        double mid_scale = v3_len(impulse_point_velocity(&am.b, ra)) + v3_len(impulse_point_velocity(&bm.b, rb));

        vec3 jt;
        double J = impulse_collide(&a.b, &b.b, ra, rb, n, e, mu, &jt);
        if (!(isfinite(J) && J >= 0 && v3_is_finite(jt) && v3_is_finite(a.b.v) && v3_is_finite(a.b.w)))
            PROP_FAIL("non-finite or negative result J=%g\n", J);
        if (J != Jm) PROP_FAIL("collide J %.17g != impulse_normal %.17g\n", J, Jm);

        if (stat) {
            if (!v3_same(b.b.v, b0.b.v) || !v3_same(b.b.w, b0.b.w)) PROP_FAIL("static body moved\n");
        } else {
            /* linear momentum */
            vec3 p0 = v3_add(v3_scale(a0.b.v, a0.m), v3_scale(b0.b.v, b0.m));
            vec3 p1 = v3_add(v3_scale(a.b.v, a.m), v3_scale(b.b.v, b.m));
            double ps = a0.m * v3_len(a0.b.v) + b0.m * v3_len(b0.b.v) + a.m * v3_len(a.b.v) + b.m * v3_len(b.b.v);
            if (!(v3_len(v3_sub(p1, p0)) <= 1e-9 * ps))
                PROP_FAIL("linear momentum off by %.3g relative\n", v3_len(v3_sub(p1, p0)) / ps);
            /* angular momentum about o */
            vec3 l0 = v3_add(angular_momentum_about(a0.m, a0.inertia, a0.c, a0.b.v, a0.b.w, o),
                             angular_momentum_about(b0.m, b0.inertia, b0.c, b0.b.v, b0.b.w, o));
            vec3 l1 = v3_add(angular_momentum_about(a.m, a.inertia, a.c, a.b.v, a.b.w, o),
                             angular_momentum_about(b.m, b.inertia, b.c, b.b.v, b.b.w, o));
            const rigid *all[4] = {&a0, &b0, &a, &b};
            double ls = 0;
            for (int i = 0; i < 4; i++)
                ls += v3_len(m3_mulv(all[i]->inertia, all[i]->b.w)) +
                      all[i]->m * v3_len(v3_cross(v3_sub(all[i]->c, o), all[i]->b.v));
            if (!(v3_len(v3_sub(l1, l0)) <= 1e-9 * ls))
                PROP_FAIL("angular momentum off by %.3g relative\n", v3_len(v3_sub(l1, l0)) / ls);
            /* kinetic energy never increases */
            double ke0 = energy(&a0, &b0), ke1 = energy(&a, &b);
            if (!(ke1 <= ke0 * (1 + 1e-9))) PROP_FAIL("kinetic energy grew %.17g -> %.17g\n", ke0, ke1);
        }

        if (!(vr0 < 0)) {
            if (J != 0.0 || !v3_same(a.b.v, a0.b.v) || !v3_same(a.b.w, a0.b.w) || !v3_same(b.b.v, b0.b.v) ||
                !v3_same(b.b.w, b0.b.w))
                PROP_FAIL("separating contact (vr %.6g) changed something, J=%g\n", vr0, J);
            continue;
        }
        approaching++;

        /* Coulomb bound */
        double jtl = v3_len(jt);
        if (!(jtl <= mu * J * (1 + 1e-12))) PROP_FAIL("friction %.17g above mu J %.17g\n", jtl, mu * J);
        if (jtl >= mu * J * (1 - 1e-12)) limited++;
        else sticking++;
        /* friction never reverses the slip it acts on */
        vec3 slip1 = tangential(rel_velocity(&a, &b, ra, rb), n);
        double sm = v3_len(slip_mid);
        if (!(v3_dot(slip1, slip_mid) >= -1e-9 * sm * (sm + mid_scale)))
            PROP_FAIL("slip reversed: dot %.6g, |slip before| %.6g\n", v3_dot(slip1, slip_mid), sm);

        /* frictionless: restitution along the normal exactly -e vr */
        rigid af = a0, bf = b0;
        impulse_collide(&af.b, &bf.b, ra, rb, n, e, 0.0, &jt);
        if (!v3_same(jt, v3_zero())) PROP_FAIL("mu = 0 gave friction\n");
        double vr1 = impulse_relative_normal_velocity(&af.b, &bf.b, ra, rb, n);
        double sc = fabs(vr0) + vscale + v3_len(impulse_point_velocity(&af.b, ra)) +
                    v3_len(impulse_point_velocity(&bf.b, rb));
        if (!(fabs(vr1 + e * vr0) <= 1e-9 * sc)) PROP_FAIL("vr after %.17g, expected %.17g\n", vr1, -e * vr0);

        /* elastic frictionless: kinetic energy conserved */
        if (!stat) {
            rigid ae = a0, be = b0;
            impulse_collide(&ae.b, &be.b, ra, rb, n, 1.0, 0.0, NULL);
            double ke0 = energy(&a0, &b0), ke1 = energy(&ae, &be);
            if (!(fabs(ke1 - ke0) <= 1e-9 * ke0)) PROP_FAIL("elastic energy %.17g -> %.17g\n", ke0, ke1);
        }
    }
    print_message("random pairs: seed 0x%llx, %d approaching, %d with a static body, %d at mu J, %d sticking\n",
                  (unsigned long long)seed, approaching, statics, limited, sticking);
    assert_true(approaching > 3000);
    assert_true(statics > 500);
    assert_true(limited > 100 && sticking > 100);
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
        cmocka_unit_test(test_golf_spin),
        cmocka_unit_test(test_random_pairs),
        cmocka_unit_test(test_degenerate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
