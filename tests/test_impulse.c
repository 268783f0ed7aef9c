/* test_impulse.c - the seed's collision response (lib/impulse.c) against the
 * worked examples of seed/DIGEST.md and against conservation laws over
 * 10,000 random pairs. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include "impulse.h"

#define REL4 5e-4 /* four significant figures */

static void expect_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want) + 1e-12)) {
        print_error("%s: got %.6f, expected %.6f\n", what, got, want);
        fail();
    }
}

static impulse_body particle(double m, vec3 v)
{
    impulse_body b;
    memset(&b, 0, sizeof b);
    b.v = v;
    b.inv_mass = m > 0 ? 1.0 / m : 0.0;
    b.inv_inertia = m3_zero();
    return b;
}

static impulse_body solid_sphere(double m, double r, vec3 v)
{
    impulse_body b = particle(m, v);
    double i = 0.4 * m * r * r;
    b.inv_inertia = m3_diag(v3(1 / i, 1 / i, 1 / i));
    return b;
}

/* Bullet: the impulse that stops (or launches) 0.010278 slug at 2480 ft/s. */
static void test_bullet_impulse_and_force(void **state)
{
    (void)state;
    double m = 0.010278, v = 2480.0;
    /* a particle against an immovable wall, e = 0: J = -(1+e) vr / (1/m) */
    double J = impulse_normal_particle(1.0 / m, 0.0, -v, 0.0);
    expect_rel(J, 25.49, REL4, "bullet impulse (lb s)");
    expect_rel(impulse_average_force(J, 0.008), 3186.0, REL4, "average force (lb)");
    double Jsi = impulse_normal_particle(1.0 / 0.15, 0.0, -2480.0 * 0.3048, 0.0);
    expect_rel(Jsi, 113.39, REL4, "SI impulse (N s)");
    expect_rel(impulse_average_force(Jsi, 0.008), 14173.0, REL4, "SI force (N)");
    assert_true(impulse_average_force(1.0, 0.0) == 0.0);
}

/* Billiard balls, e = 0.9, n = (sqrt3/2, -1/2) from ball 1 towards ball 2. */
static void test_billiard_balls(void **state)
{
    (void)state;
    double m = 0.0106, r = 1.125 / 12.0;
    vec3 n12 = v3(sqrt(3.0) / 2.0, -0.5, 0.0);
    /* the seed's convention puts n from body 2 to body 1: body 1 = ball 2 */
    impulse_body b2 = solid_sphere(m, r, v3(0, 0, 0)), b1 = solid_sphere(m, r, v3(20, 0, 0));
    vec3 r_on_2 = v3_scale(n12, -r), r_on_1 = v3_scale(n12, r);
    double J = impulse_collide(&b2, &b1, r_on_2, r_on_1, n12, 0.9, 0.0, NULL);
    assert_true(J > 0);
    expect_rel(b1.v.x, 5.7500, REL4, "v1+ x");
    expect_rel(b1.v.y, 8.2272, REL4, "v1+ y");
    expect_rel(b2.v.x, 14.2500, REL4, "v2+ x");
    expect_rel(b2.v.y, -8.2272, REL4, "v2+ y");
    assert_true(fabs(m * (b1.v.x + b2.v.x) - m * 20) < 1e-12 && fabs(b1.v.y + b2.v.y) < 1e-12);
    double ke = kinetic_energy(m, m3_zero(), b1.v, b1.w) + kinetic_energy(m, m3_zero(), b2.v, b2.w);
    expect_rel(ke / (0.5 * m * 400), 0.92875, REL4, "kinetic energy ratio");
    assert_true(v3_len(b1.w) == 0 && v3_len(b2.w) == 0); /* central: no spin */
    /* the particle form gives the same impulse */
    double vr = v3_dot(v3_sub(v3(0, 0, 0), v3(20, 0, 0)), n12);
    expect_rel(impulse_normal_particle(1 / m, 1 / m, vr, 0.9), J, 1e-12, "particle form");
}

/* Baseball and bat, e = 0.46, frictionless. */
static void test_baseball_and_bat(void **state)
{
    (void)state;
    double r1 = 1.375 / 12, r2 = 1.47 / 12, rs = r1 + r2;
    vec3 n = v3(sqrt(rs * rs - r1 * r1) / rs, r1 / rs, 0); /* from the bat towards the ball */
    impulse_body bat = particle(0.069932, v3(103, 0, 0)), ball = particle(0.0099556, v3(-132, 0, 0));
    /* body 1 = ball (n points from body 2, the bat, to body 1) */
    double J = impulse_collide(&ball, &bat, v3_scale(n, -r2), v3_scale(n, r1), n, 0.46, 0.0, NULL);
    expect_rel(bat.v.x, 70.230, REL4, "bat v+ x");
    expect_rel(bat.v.y, -18.091, REL4, "bat v+ y");
    expect_rel(ball.v.x, 98.188, REL4, "ball v+ x");
    expect_rel(ball.v.y, 127.078, REL4, "ball v+ y");
    expect_rel(J, 2.6177, REL4, "impulse on the ball");
}

/* Golf: friction spins the ball, w+ = w- + J mu r / I while it still slides. */
static void test_golf_spin_from_friction(void **state)
{
    (void)state;
    double m = 0.0459, r = 0.02135, mu = 0.1, e = 0.8, I = 0.4 * m * r * r;
    vec3 n = v3(0, 0, 1); /* from the club face (body 2) to the ball (body 1) */
    impulse_body ball = solid_sphere(m, r, v3(30, 0, -30)), club = particle(0, v3(0, 0, 0));
    vec3 tangent;
    double J = impulse_collide(&ball, &club, v3(0, 0, -r), v3(0, 0, 0), n, e, mu, &tangent);
    expect_rel(J, (1 + e) * m * 30, 1e-12, "normal impulse");
    expect_rel(v3_len(tangent), mu * J, 1e-12, "kinetic friction is mu J");
    expect_rel(ball.w.y, J * mu * r / I, 1e-12, "spin w+ = J mu r / I");
    expect_rel(ball.v.x, 30 - mu * J / m, 1e-12, "tangential speed loses mu J / m");
    /* small slip: static friction stops it exactly instead of reversing it */
    impulse_body slow = solid_sphere(m, r, v3(0.01, 0, -30));
    impulse_collide(&slow, &club, v3(0, 0, -r), v3(0, 0, 0), n, e, mu, &tangent);
    vec3 slip = impulse_point_velocity(&slow, v3(0, 0, -r));
    assert_true(fabs(slip.x) < 1e-12 && fabs(slip.y) < 1e-12);
    assert_true(v3_len(tangent) < mu * J);
}

/* ---- properties over random pairs --------------------------------------------- */

static double rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static vec3 rvec(uint64_t *s, double scale)
{
    return v3(scale * (2 * rnd(s) - 1), scale * (2 * rnd(s) - 1), scale * (2 * rnd(s) - 1));
}

typedef struct rigid {
    impulse_body b;
    double m;
    mat3 inertia;
    vec3 c;
} rigid;

static rigid random_body(uint64_t *s)
{
    rigid r;
    r.m = pow(10.0, -3.0 + 6.0 * rnd(s));
    vec3 d = v3(r.m * pow(10.0, -1 + 2 * rnd(s)), r.m * pow(10.0, -1 + 2 * rnd(s)), r.m * pow(10.0, -1 + 2 * rnd(s)));
    quat q = q_normalize((quat){rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5, rnd(s) - 0.5});
    mat3 rot = m3_from_quat(q);
    r.inertia = m3_rotate_tensor(rot, m3_diag(d));
    r.b.inv_mass = 1 / r.m;
    r.b.inv_inertia = m3_rotate_tensor(rot, m3_diag(v3(1 / d.x, 1 / d.y, 1 / d.z)));
    r.b.v = rvec(s, 5);
    r.b.w = rvec(s, 5);
    r.c = rvec(s, 2);
    return r;
}

static vec3 momentum(const rigid *a, const rigid *b)
{
    return v3_add(v3_scale(a->b.v, a->m), v3_scale(b->b.v, b->m));
}

static vec3 ang_momentum(const rigid *a, const rigid *b, vec3 o)
{
    return v3_add(angular_momentum_about(a->m, a->inertia, a->c, a->b.v, a->b.w, o),
                  angular_momentum_about(b->m, b->inertia, b->c, b->b.v, b->b.w, o));
}

static double energy(const rigid *a, const rigid *b)
{
    return kinetic_energy(a->m, a->inertia, a->b.v, a->b.w) + kinetic_energy(b->m, b->inertia, b->b.v, b->b.w);
}

static void test_random_pairs_conserve(void **state)
{
    (void)state;
    const uint64_t seed = 0xC0FFEE1234ULL;
    uint64_t s = seed;
    int approaching = 0;
    for (int k = 0; k < 10000; k++) {
        rigid a = random_body(&s), b = random_body(&s);
        vec3 n = v3_normalize(rvec(&s, 1));
        vec3 P = rvec(&s, 2), o = rvec(&s, 3);
        double e = rnd(&s), mu = rnd(&s);
        int frictionless = k % 3 == 0, elastic = k % 5 == 0;
        if (frictionless) mu = 0;
        if (elastic) e = 1;
        vec3 ra = v3_sub(P, a.c), rb = v3_sub(P, b.c);
        double vr0 = impulse_relative_normal_velocity(&a.b, &b.b, ra, rb, n);
        vec3 p0 = momentum(&a, &b), l0 = ang_momentum(&a, &b, o);
        double ke0 = energy(&a, &b);
        vec3 vrel0 = v3_sub(impulse_point_velocity(&a.b, ra), impulse_point_velocity(&b.b, rb));
        vec3 slip0 = v3_sub(vrel0, v3_scale(n, v3_dot(vrel0, n)));
        vec3 jt;
        double J = impulse_collide(&a.b, &b.b, ra, rb, n, e, mu, &jt);
        vec3 p1 = momentum(&a, &b), l1 = ang_momentum(&a, &b, o);
        double ke1 = energy(&a, &b);
        double pscale = a.m * v3_len(a.b.v) + b.m * v3_len(b.b.v) + 1e-300 + a.m * 5 + b.m * 5;
        double lscale = v3_len(l0) + v3_len(l1) + pscale * 5;
        if (!(v3_len(v3_sub(p1, p0)) <= 1e-9 * pscale && v3_len(v3_sub(l1, l0)) <= 1e-9 * lscale)) {
            print_error("seed %llx case %d: momentum not conserved (%.3g, %.3g)\n", (unsigned long long)seed, k,
                        v3_len(v3_sub(p1, p0)) / pscale, v3_len(v3_sub(l1, l0)) / lscale);
            fail();
        }
        if (vr0 >= 0) {
            assert_true(J == 0.0); /* separating: no impulse */
            continue;
        }
        approaching++;
        if (!(ke1 <= ke0 * (1 + 1e-9))) {
            print_error("seed %llx case %d: energy grew %.12g -> %.12g\n", (unsigned long long)seed, k, ke0, ke1);
            fail();
        }
        if (elastic && frictionless && !(fabs(ke1 - ke0) <= 1e-9 * ke0)) {
            print_error("seed %llx case %d: elastic energy %.12g -> %.12g\n", (unsigned long long)seed, k, ke0, ke1);
            fail();
        }
        if (frictionless) {
            double vr1 = impulse_relative_normal_velocity(&a.b, &b.b, ra, rb, n);
            if (!(fabs(vr1 + e * vr0) <= 1e-9 * fabs(vr0))) {
                print_error("seed %llx case %d: vr after %.12g, expected %.12g\n", (unsigned long long)seed, k, vr1, -e * vr0);
                fail();
            }
        }
        if (!(v3_len(jt) <= mu * J * (1 + 1e-12) + 1e-300)) {
            print_error("seed %llx case %d: friction %.6g above mu J %.6g\n", (unsigned long long)seed, k, v3_len(jt), mu * J);
            fail();
        }
        /* friction never reverses the slip it acts on */
        vec3 vrel1 = v3_sub(impulse_point_velocity(&a.b, ra), impulse_point_velocity(&b.b, rb));
        vec3 slip1 = v3_sub(vrel1, v3_scale(n, v3_dot(vrel1, n)));
        if (v3_len(jt) > 0) {
            vec3 t = v3_normalize(v3_neg(jt));
            /* the slip along the friction direction, measured right after friction */
            double along = v3_dot(slip1, t);
            if (!(along >= -1e-9 * (v3_len(slip0) + v3_len(vrel0)))) {
                print_error("seed %llx case %d: slip reversed (%.6g)\n", (unsigned long long)seed, k, along);
                fail();
            }
        }
    }
    assert_true(approaching > 3000);
}

static void test_static_body_never_moves(void **state)
{
    (void)state;
    uint64_t s = 42;
    for (int k = 0; k < 1000; k++) {
        rigid a = random_body(&s);
        impulse_body wall = particle(0, v3(0, 0, 0));
        vec3 n = v3_normalize(rvec(&s, 1));
        impulse_collide(&a.b, &wall, rvec(&s, 1), rvec(&s, 1), n, rnd(&s), rnd(&s), NULL);
        assert_true(wall.v.x == 0 && wall.v.y == 0 && wall.v.z == 0 && wall.w.x == 0 && wall.w.y == 0 && wall.w.z == 0);
    }
}

static void test_degenerate_inputs(void **state)
{
    (void)state;
    impulse_body a = particle(1, v3(0, 0, 0)), b = particle(1, v3(0, 0, 0));
    vec3 n = v3(0, 0, 1);
    /* zero relative velocity */
    assert_true(impulse_normal(&a, &b, v3_zero(), v3_zero(), n, 0.5) == 0.0);
    /* separating */
    a.v = v3(0, 0, 3);
    assert_true(impulse_normal(&a, &b, v3_zero(), v3_zero(), n, 0.5) == 0.0);
    assert_true(impulse_normal_particle(1, 1, 2.0, 1.0) == 0.0);
    /* zero slip: no friction, no NaN */
    a.v = v3(0, 0, -3);
    vec3 dir;
    vec3 f = impulse_friction(&a, &b, v3_zero(), v3_zero(), n, 0.5, 2.0, &dir);
    assert_true(f.x == 0 && f.y == 0 && f.z == 0 && dir.x == 0 && dir.y == 0 && dir.z == 0);
    /* both static */
    impulse_body s1 = particle(0, v3(0, 0, -1)), s2 = particle(0, v3(0, 0, 0));
    double J = impulse_collide(&s1, &s2, v3(1, 0, 0), v3(0, 1, 0), n, 0.5, 0.5, NULL);
    assert_true(J == 0.0 && isfinite(s1.v.z));
    assert_true(impulse_normal_particle(0, 0, -1, 0.5) == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bullet_impulse_and_force),
        cmocka_unit_test(test_billiard_balls),
        cmocka_unit_test(test_baseball_and_bat),
        cmocka_unit_test(test_golf_spin_from_friction),
        cmocka_unit_test(test_random_pairs_conserve),
        cmocka_unit_test(test_static_body_never_moves),
        cmocka_unit_test(test_degenerate_inputs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
