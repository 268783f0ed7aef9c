/* vecmath.h - inline double-precision vec3 / quat / mat3 used by every module.
 * (Not named math.h: with -Ilib it would shadow the C library's <math.h>.) */
#ifndef CAROM_VECMATH_H
#define CAROM_VECMATH_H

#include <math.h>

/* min/max that compile to one instruction (libm's fmin/fmax are calls) */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

typedef struct vec3 { double x, y, z; } vec3;
typedef struct quat { double w, x, y, z; } quat;          /* unit, w first */
typedef struct mat3 { vec3 c0, c1, c2; } mat3;             /* column major */
typedef struct xform { vec3 p; quat q; } xform;            /* body origin frame */

static inline vec3 v3(double x, double y, double z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3_zero(void) { return v3(0, 0, 0); }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline vec3 v3_scale(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
/* a + s * b */
static inline vec3 v3_madd(vec3 a, double s, vec3 b) { return v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z); }
static inline double v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_len2(vec3 a) { return v3_dot(a, a); }
static inline double v3_len(vec3 a) { return sqrt(v3_dot(a, a)); }
static inline vec3 v3_abs(vec3 a) { return v3(fabs(a.x), fabs(a.y), fabs(a.z)); }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(dmin(a.x, b.x), dmin(a.y, b.y), dmin(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(dmax(a.x, b.x), dmax(a.y, b.y), dmax(a.z, b.z)); }
static inline vec3 v3_lerp(vec3 a, vec3 b, double t) { return v3_madd(a, t, v3_sub(b, a)); }
static inline double v3_get(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }
static inline int v3_is_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Unit vector, or the zero vector when a is (numerically) zero: never NaN. */
static inline vec3 v3_normalize(vec3 a)
{
    double l = v3_len(a);
    return l > 1e-300 ? v3_scale(a, 1.0 / l) : v3_zero();
}
static inline double v3_normalize_len(vec3 *a)
{
    double l = v3_len(*a);
    *a = l > 1e-300 ? v3_scale(*a, 1.0 / l) : v3_zero();
    return l;
}
/* Two unit vectors t1, t2 completing n to a right-handed orthonormal basis. */
static inline void v3_basis(vec3 n, vec3 *t1, vec3 *t2)
{
    /* Pixar's branchless construction (Duff et al. 2017) */
    double s = copysign(1.0, n.z);
    double a = -1.0 / (s + n.z);
    double b = n.x * n.y * a;
    *t1 = v3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    *t2 = v3(b, s + n.y * n.y * a, -n.y);
}

static inline quat q_identity(void) { quat q = {1, 0, 0, 0}; return q; }
static inline quat q_mul(quat a, quat b)
{
    quat r = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
              a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
              a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
              a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
    return r;
}
static inline quat q_conj(quat a) { quat r = {a.w, -a.x, -a.y, -a.z}; return r; }
static inline double q_len(quat a) { return sqrt(a.w * a.w + a.x * a.x + a.y * a.y + a.z * a.z); }
static inline quat q_normalize(quat a)
{
    double l = q_len(a);
    if (!(l > 1e-300) || !isfinite(l)) return q_identity();
    quat r = {a.w / l, a.x / l, a.y / l, a.z / l};
    return r;
}
static inline vec3 q_rotate(quat q, vec3 v)
{
    vec3 u = v3(q.x, q.y, q.z);
    vec3 t = v3_scale(v3_cross(u, v), 2.0);
    return v3_add(v3_madd(v, q.w, t), v3_cross(u, t));
}
static inline vec3 q_inv_rotate(quat q, vec3 v) { return q_rotate(q_conj(q), v); }
static inline quat q_axis_angle(vec3 axis, double angle)
{
    vec3 a = v3_normalize(axis);
    double s = sin(0.5 * angle);
    quat r = {cos(0.5 * angle), a.x * s, a.y * s, a.z * s};
    return r;
}
/* The rotation by rotation vector r (axis r/|r|, angle |r|): the exact
 * exponential map (sin(x)/x by its series near 0, so tiny angles lose nothing). */
static inline quat q_exp(vec3 r)
{
    double angle = v3_len(r), half = 0.5 * angle;
    double k = half < 1e-4 ? 0.5 - angle * angle / 48.0 : sin(half) / angle; /* sin(angle/2)/angle */
    quat q = {cos(half), r.x * k, r.y * k, r.z * k};
    return q;
}
/* q advanced by angular velocity w (world frame) over h, renormalised. */
static inline quat q_integrate(quat q, vec3 w, double h)
{
    quat dq = {0, w.x, w.y, w.z};
    quat d = q_mul(dq, q);
    quat r = {q.w + 0.5 * h * d.w, q.x + 0.5 * h * d.x, q.y + 0.5 * h * d.y, q.z + 0.5 * h * d.z};
    return q_normalize(r);
}

static inline mat3 m3_cols(vec3 a, vec3 b, vec3 c) { mat3 m = {a, b, c}; return m; }
static inline mat3 m3_zero(void) { return m3_cols(v3_zero(), v3_zero(), v3_zero()); }
static inline mat3 m3_diag(vec3 d) { return m3_cols(v3(d.x, 0, 0), v3(0, d.y, 0), v3(0, 0, d.z)); }
static inline mat3 m3_identity(void) { return m3_diag(v3(1, 1, 1)); }
static inline vec3 m3_mulv(mat3 m, vec3 v)
{
    return v3_add(v3_add(v3_scale(m.c0, v.x), v3_scale(m.c1, v.y)), v3_scale(m.c2, v.z));
}
static inline mat3 m3_transpose(mat3 m)
{
    return m3_cols(v3(m.c0.x, m.c1.x, m.c2.x), v3(m.c0.y, m.c1.y, m.c2.y), v3(m.c0.z, m.c1.z, m.c2.z));
}
static inline vec3 m3_tmulv(mat3 m, vec3 v) { return v3(v3_dot(m.c0, v), v3_dot(m.c1, v), v3_dot(m.c2, v)); }
static inline mat3 m3_mul(mat3 a, mat3 b) { return m3_cols(m3_mulv(a, b.c0), m3_mulv(a, b.c1), m3_mulv(a, b.c2)); }
static inline mat3 m3_add(mat3 a, mat3 b) { return m3_cols(v3_add(a.c0, b.c0), v3_add(a.c1, b.c1), v3_add(a.c2, b.c2)); }
static inline mat3 m3_scale(mat3 a, double s) { return m3_cols(v3_scale(a.c0, s), v3_scale(a.c1, s), v3_scale(a.c2, s)); }
static inline mat3 m3_from_quat(quat q)
{
    return m3_cols(q_rotate(q, v3(1, 0, 0)), q_rotate(q, v3(0, 1, 0)), q_rotate(q, v3(0, 0, 1)));
}
static inline double m3_det(mat3 m) { return v3_dot(m.c0, v3_cross(m.c1, m.c2)); }
/* Inverse; the zero matrix when singular (so an infinite inertia stays infinite). */
static inline mat3 m3_inverse(mat3 m)
{
    double d = m3_det(m);
    if (!(fabs(d) > 1e-300)) return m3_zero();
    mat3 r = m3_cols(v3_cross(m.c1, m.c2), v3_cross(m.c2, m.c0), v3_cross(m.c0, m.c1));
    return m3_scale(m3_transpose(r), 1.0 / d);
}
/* R * D * R^T for a body-frame tensor D and rotation R. */
static inline mat3 m3_rotate_tensor(mat3 r, mat3 d) { return m3_mul(m3_mul(r, d), m3_transpose(r)); }
/* Tensor of a point mass m at offset d: m (d.d I - d d^T) (parallel axis). */
static inline mat3 m3_parallel_axis(double m, vec3 d)
{
    double dd = v3_dot(d, d);
    return m3_cols(v3(m * (dd - d.x * d.x), -m * d.y * d.x, -m * d.z * d.x),
                   v3(-m * d.x * d.y, m * (dd - d.y * d.y), -m * d.z * d.y),
                   v3(-m * d.x * d.z, -m * d.y * d.z, m * (dd - d.z * d.z)));
}

static inline vec3 xf_point(xform t, vec3 p) { return v3_add(t.p, q_rotate(t.q, p)); }
static inline vec3 xf_inv_point(xform t, vec3 p) { return q_inv_rotate(t.q, v3_sub(p, t.p)); }
static inline int xf_is_finite(xform t)
{
    return v3_is_finite(t.p) && isfinite(t.q.x) && isfinite(t.q.y) && isfinite(t.q.z) && isfinite(t.q.w);
}

typedef struct aabb { vec3 lo, hi; } aabb;
static inline int aabb_overlap(aabb a, aabb b)
{
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}
static inline aabb aabb_union(aabb a, aabb b) { aabb r = {v3_min(a.lo, b.lo), v3_max(a.hi, b.hi)}; return r; }
static inline int aabb_contains(aabb outer, aabb inner)
{
    return outer.lo.x <= inner.lo.x && outer.lo.y <= inner.lo.y && outer.lo.z <= inner.lo.z &&
           inner.hi.x <= outer.hi.x && inner.hi.y <= outer.hi.y && inner.hi.z <= outer.hi.z;
}
static inline double aabb_area(aabb a)
{
    vec3 d = v3_sub(a.hi, a.lo);
    return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}
static inline aabb aabb_fatten(aabb a, double m)
{
    aabb r = {v3_sub(a.lo, v3(m, m, m)), v3_add(a.hi, v3(m, m, m))};
    return r;
}

#endif
