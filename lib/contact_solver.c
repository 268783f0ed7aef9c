/* contact_solver.c - the scalar passes over one manifold: prepare, warm
 * start, solve / relax and the shock pass. The wide passes
 * (solver_wide.c) do the same four manifolds at a time; the formulas they
 * share are in constraint.h. */
#include "contact_solver.h"
#include "penalty.h"
#include "block_ldl.h"
#include "column_solve.h"

#if defined(__GNUC__)
#define SOLVE_OUTLINE static __attribute__((noinline))
#else
#define SOLVE_OUTLINE static
#endif


/* Rolling resistance c: a torque against the bodies' relative rolling,
 * capped at c R N. A body of mass m and inertia I_t about the rolling axis,
 * its centre r above the contact, rolling on still ground slows at
 * T r / (I_t + m r^2) under a torque T: R = r + I_t / (m r) makes that c g,
 * as a block sliding with friction c would (the larger R of two bodies). */
static void prepare_rolling(contact_constraint *c, const impulse_body *A, const impulse_body *B)
{
    constraint_extra *x = c->x;
    if (!x) return; /* no rolling rows (every reader checks c->rolling first) */
    x->rolling_impulse[0] = x->rolling_impulse[1] = 0.0;
    x->rolling_mass[0] = x->rolling_mass[1] = 0.0;
    x->rolling_radius = 0.0;
    if (!(c->rolling > 0.0) || c->count < 1) return;
    vec3 t[2] = {c->t1, c->t2};
    for (int q = 0; q < 2; q++) {
        double k = v3_dot(t[q], m3_mulv(A->inv_inertia, t[q])) + v3_dot(t[q], m3_mulv(B->inv_inertia, t[q]));
        x->rolling_mass[q] = k > 0.0 ? 1.0 / k : 0.0;
    }
    vec3 mid = v3_zero();
    for (int j = 0; j < c->count; j++) mid = v3_add(mid, c->m->points[j].point);
    mid = v3_scale(mid, 1.0 / c->count);
    const impulse_body *body[2] = {A, B};
    vec3 centre[2] = {c->center_a, c->center_b};
    for (int i = 0; i < 2; i++) {
        const impulse_body *X = body[i];
        double r = fabs(v3_dot(c->n, v3_sub(mid, centre[i])));
        double inv_it = 0.5 * (v3_dot(t[0], m3_mulv(X->inv_inertia, t[0])) + v3_dot(t[1], m3_mulv(X->inv_inertia, t[1])));
        if (!(X->inv_mass > 0.0 && inv_it > 0.0 && r > 0.0)) continue;
        x->rolling_radius = dmax(x->rolling_radius, r + X->inv_mass / (inv_it * r));
    }
}

static void solve_rolling(contact_constraint *c, vec3 *wA, vec3 *wB, const impulse_body *A, const impulse_body *B)
{
    double normal = 0.0;
    for (int j = 0; j < c->count; j++) normal += c->p[j].normal_impulse;
    constraint_extra *x = c->x;
    vec3 rel = v3_sub(*wB, *wA);
    double o1 = x->rolling_impulse[0], o2 = x->rolling_impulse[1];
    double n1 = o1 - x->rolling_mass[0] * v3_dot(c->t1, rel);
    double n2 = o2 - x->rolling_mass[1] * v3_dot(c->t2, rel);
    coulomb_clamp(&n1, &n2, c->rolling * x->rolling_radius * normal);
    x->rolling_impulse[0] = n1;
    x->rolling_impulse[1] = n2;
    vec3 L = v3_add(v3_scale(c->t1, n1 - o1), v3_scale(c->t2, n2 - o2));
    *wA = v3_sub(*wA, m3_mulv(A->inv_inertia, L));
    *wB = v3_add(*wB, m3_mulv(B->inv_inertia, L));
}

/* ---- block solve of a manifold's normal rows ------------------------------
 * A manifold's points are solved together, not one after the other: one
 * Gauss-Seidel sweep over the points of a face leaves the first point
 * solved holding more than its share, a torque that rocks a symmetric stack
 * and walks it sideways (a 10-box column at default walked 3.4 mm in 10 s,
 * a 2-box stack at fast on a box ground 3.6 cm, and the 20-tower at default
 * leaned 0.34 m). The soft row of point i (make_softness:
 * lambda = -(s_m / K_ii)(vn + bias) - s_i acc) is the exact solution of
 * (K_ii + c_i) lambda + vn + bias + c_i acc = 0 with the compliance
 * c_i = K_ii s_i / s_m (0 for a rigid row), so the block version for all
 * points is the linear complementarity problem on the totals x:
 *     w = A x + b >= 0,  x >= 0,  x.w = 0,
 *     A = K + C,  b = vn + bias - K acc,
 * K_ij = 1/mA + 1/mB + (IA^-1 (ra_i x n)).(ra_j x n) + (IB^-1 (rb_i x n)).(rb_j x n)
 * (Box2D v2 solved its 2-point case by enumeration; here 2 to 4 points).
 * K is singular for 4 coplanar points held rigidly (a relax pass): a
 * compliance of BLOCK_EPS K_ii more keeps A positive definite and, for a
 * consistent right-hand side, picks the least-norm totals (the even split
 * of a symmetric load); it changes a row's velocity by BLOCK_EPS of its own
 * response. A is positive definite, so the problem has one solution. K is
 * built once a step (contact_prepare), and A's LDL^T factor (no square
 * roots) for every row soft and for every row rigid at the first solve that
 * reads it; a solve whose rows all touch or all are rigid is
 * Delta = -A^-1 (vn + bias + (C + E) acc), and when a total would go
 * negative, or the rows mix, the active sets are tried from all points
 * down, the first feasible one is it.
 *
 * The compliance is one spring per point. It gives a face's tilt modes more
 * than the rows' frequency (a cube's 1.22 times: their inverse mass is 1.5
 * diag(K)). Tried and taken back (8d293a7): the modal compliance
 * C = (s_i / s_m) K (every mode at the setting's frequency), which stopped
 * columns of turned boxes swaying at fast (10 boxes offset up to 2 mm and
 * turned up to 1.1 degrees, mean sideways walk after 10 s, 64 seeds:
 * 4.70 -> 0.53 cm); but its springs couple the points, so a point that
 * lifts off or lands changes the others' forces at once, and boxes resting
 * tilted on a point or two that toggled between touching and apart never
 * settled: of 48 random piles of 30 boxes, 23 still moved after 20 s at
 * default (3 with this), 6 at accurate (1). */
/* The two above with n a constant in each case, so the loops unroll. */
static int block_factor(int n, double A[4][4], double L[4][4])
{
    switch (n) {
    case 2: return block_factor_n(2, A, L);
    case 3: return block_factor_n(3, A, L);
    default: return block_factor4(A, L);
    }
}

static void block_apply(int n, double L[4][4], const double r[4], double x[4])
{
    /* spelled out for 4 points (faces, the common case): GCC at -O2 left the loops rolled */
    if (n == 4) {
        block_apply4(L, r, x);
        return;
    }
    block_apply_n(n, L, r, x);
}

/* Solve of the principal subsystem `mask` of A x = r (n <= 4); 0 when a
 * pivot is not positive. x gets 0 outside the mask. */
static int block_solve_subset(int n, double A[4][4], const double r[4], int mask, double x[4])
{
    int idx[4], m = 0;
    for (int i = 0; i < n; i++) {
        x[i] = 0.0;
        if (mask & (1 << i)) idx[m++] = i;
    }
    double S[4][4], L[4][4], rs[4], xs[4];
    for (int i = 0; i < m; i++) {
        rs[i] = r[idx[i]];
        for (int j = 0; j < m; j++) S[i][j] = A[idx[i]][idx[j]];
    }
    if (!block_factor_n(m, S, L)) return 0;
    block_apply_n(m, L, rs, xs);
    for (int i = 0; i < m; i++) x[idx[i]] = xs[i];
    return 1;
}

/* The LCP w = A x + b by enumeration of the active sets, largest first
 * (from_size points down); 0 when none is feasible to rounding (the caller
 * sweeps the rows instead). */
static int block_lcp(int n, double A[4][4], const double b[4], double x[4], int from_size)
{
    double r[4];
    for (int i = 0; i < n; i++) r[i] = -b[i];
    int full = (1 << n) - 1;
    for (int size = from_size; size >= 1; size--) {
        for (int mask = full; mask > 0; mask--) {
            int bits = 0;
            for (int i = 0; i < n; i++) bits += (mask >> i) & 1;
            if (bits != size || !block_solve_subset(n, A, r, mask, x)) continue;
            int ok = 1;
            for (int i = 0; i < n && ok; i++) {
                if (mask & (1 << i)) {
                    ok = x[i] >= 0.0;
                } else {
                    double w = b[i], scale = fabs(b[i]);
                    for (int j = 0; j < n; j++) {
                        w += A[i][j] * x[j];
                        scale += fabs(A[i][j] * x[j]);
                    }
                    ok = w >= -1e-12 * scale;
                }
            }
            if (ok) return 1;
        }
    }
    /* no point active: every row separates by itself */
    for (int i = 0; i < n; i++) {
        x[i] = 0.0;
        if (b[i] < 0.0) return 0;
    }
    return 1;
}

/* A block-solved manifold carrying more than its pair's weight springs up
 * to twice the setting's frequency (four times as stiff), where
 * loaded_softness (solver.c) stops at sqrt 2 for the manifolds swept point
 * after point: the same f' = f min(sqrt(1 + m_load / m), cap), never past
 * max(f, 1/(4h)), with the cap 2 here; with two iterations or more
 * (accurate) the cap is 4 and the limit max(f, 1/(2h)). A manifold past
 * 1/(4h) is marked
 * stiff: the pass that solves it is followed by BLOCK_STIFF_SWEEPS sweeps
 * of the stiff manifolds' normal rows alone (solver.c), unless its column's
 * direct solve (column_solve.c) took its normal rows this pass. A manifold
 * of such a column takes the same rule at one iteration (default): the
 * direct solve holds the stiffer springs (the sweeps stay the fallback for
 * a pass it leaves to the manifolds). Without them one
 * Gauss-Seidel pass does not hold such a spring: past 1/(4h) every tower
 * walked sideways (a stack's tilt modes, each point its own spring, swing at
 * 1.22 f and grew from rounding: 1.25/(4h) held, 1.5/(4h) walked the
 * 20-tower 25 cm at default, 1/(2h) 0.55 m), at any damping ratio (1-40)
 * and with any share of last step's load taken off the spring's rest length
 * (the 40-tower fell). One more whole pass held 1.5/(4h) (the cost of a
 * second iteration); the normal rows of the stiff manifolds alone, three
 * times, hold 1/(2h) (two: the 40-tower leaned 1e-6 m and growing; 3/(4h)
 * did not hold even with five: leaned 2 cm to 1.7 m). Measured (top box, 10 s, dt 1/60, sag; default if
 * it were allowed there / accurate): the 20-tower 2.77 -> 0.76 cm / 0.69 ->
 * 0.19 cm, the 40-tower 11.05 -> 2.83 cm / 2.76 -> 0.71 cm. Only with relax passes, as
 * loaded_softness (at fast the stiffer spring set the 40-tower bouncing, up
 * 8.8 cm, fallen by 15 s), or in a column solved directly, whose manifolds
 * take a relax pass of their own at fast (solver.c, relax_columns; the
 * 20-tower at fast 10.63 -> 0.76 cm). Returns 0 when the setting's softness
 * stays (the caller keeps c->soft). */
#define BLOCK_STIFFENING_MAX 4.0
static int block_loaded_softness(const contact_constraint *c, const step_context *ctx, double mA, double mB,
                                 int column, int heavy_column, softness *out, int *stiff)
{
    *stiff = 0;
    if (!((ctx->relax_iterations > 0 || column) && ctx->warm_starting && ctx->gravity_length > 0.0 && mA + mB > 0.0)) return 0;
    if (c->soft.mass_scale == 1.0 && c->soft.impulse_scale == 0.0) return 0; /* held rigidly (touching impact) */
    double load = 0.0;
    for (int j = 0; j < c->count; j++) load += c->p[j].normal_impulse; /* last step's (warm starting on) */
    double ratio = load * (mA + mB) / (ctx->h * ctx->gravity_length);
    /* past 1/(4h) only where something holds it: a column's direct solve
     * (column_solve.c), or with two iterations or more the sweeps; at one
     * iteration sweeps would run nearly everywhere (the 10-box stack at
     * default: 137.6M -> 258.5M instructions, callgrind, for a column it
     * already holds to 0.69 cm). Not in a column under a heavy body whose
     * masses differ less than COLUMN_VERY_HEAVY_RATIO (column_solve.h): on
     * the stiffer springs its tilt grew from rounding (an e-fold in 0.7 s:
     * 10 kg on two 1 kg boxes at fast walked 1.4 cm in 120 s, at default
     * 3.8 cm), on the setting's it holds, and sags at most the heavy body's
     * share of the load on them (about 1.4 cm at 50:1, dt 1/60) */
    int past = ctx->iterations >= 2 || (column && heavy_column != COLUMN_HEAVY);
    double f = dmin(sqrt(1.0 + ratio), past ? BLOCK_STIFFENING_MAX : 2.0);
    if (!(f > 1.4142135623730951)) return 0; /* loaded_softness's own answer */
    double hertz = (mA == 0.0 || mB == 0.0 ? 2.0 : 1.0) * ctx->contact_hertz;
    double quarter = 0.25 * ctx->inv_h;
    double stiffened = dmin(hertz * f, dmax(hertz, past ? 2.0 * quarter : quarter));
    *stiff = stiffened > dmax(hertz, quarter);
    *out = make_softness(stiffened, ctx->contact_damping_ratio, ctx->h);
    return 1;
}

/* A point sticks while its friction is below this share of its cone. */
#define STICKING_SHARE 0.999

/* K of an unlocked manifold of 2-4 points (after its rows); the factors
 * wait for the first solve that reads them (block_inverse). */
static void block_prepare(contact_constraint *c, contact_block *blk, const step_context *ctx, double mA, double mB,
                          int sticking)
{
    const int count = c->count;
    double lin = mA + mB;
    blk->ready = 0;
    blk->factored[0] = blk->factored[1] = 0;
    blk->shock_ready = 0;
    blk->stiff = 0;
    blk->column_done = 0;
    blk->friction_first = 0;
    if (count < 2 || c->locked) return;
    softness setting = c->soft; /* kept for a manifold that ends up swept */
    int stiff;
    block_loaded_softness(c, ctx, mA, mB, blk->column, blk->heavy_column, &c->soft, &stiff);
    for (int i = 0; i < count; i++) {
        const constraint_rows *p = &c->r[i];
        if (!(p->normal_mass > 0.0)) {
            c->soft = setting;
            return;
        }
        for (int j = 0; j <= i; j++) {
            const constraint_rows *q = &c->r[j];
            blk->K[i][j] = blk->K[j][i] = lin + v3_dot(p->ia_n, q->ra_n) + v3_dot(p->ib_n, q->rb_n);
        }
    }
    blk->ready = 1;
    blk->stiff = stiff;
    blk->friction_first = sticking;
}

/* The factor of K + (gamma + BLOCK_EPS) diag(K) (soft 1: every row soft) or
 * K + BLOCK_EPS diag(K) (soft 0: every row rigid), made at its first use;
 * NULL when it cannot be (the block is then solved by enumeration). The
 * factoring is out of line (twice a step) and the test inline (every
 * solve), so the solve's two callers (contact_solve, contact_solve_normals)
 * each keep it inline. */
SOLVE_OUTLINE void block_make_factor(const contact_constraint *c, contact_block *blk, const step_context *ctx, int soft)
{
    const int count = c->count;
    double e = (soft ? contact_block_gamma(c, ctx) : 0.0) + BLOCK_EPS, A[4][4];
    if (count == 4) { /* faces: the sizes constants, so the loops unroll */
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 4; j++) A[i][j] = blk->K[i][j];
            A[i][i] += e * blk->K[i][i];
        }
        blk->factored[soft] = block_factor4(A, blk->inv[soft]) ? 1 : -1;
        return;
    }
    for (int i = 0; i < count; i++) {
        for (int j = 0; j < count; j++) A[i][j] = blk->K[i][j];
        A[i][i] += e * blk->K[i][i];
    }
    blk->factored[soft] = block_factor(count, A, blk->inv[soft]) ? 1 : -1;
}

BLOCK_INLINE double (*block_inverse(const contact_constraint *c, contact_block *blk, const step_context *ctx, int soft))[4]
{
    if (!blk->factored[soft]) block_make_factor(c, blk, ctx, soft);
    return blk->factored[soft] > 0 ? blk->inv[soft] : NULL;
}

/* Solves the block for the totals x (see above) given each row's vn + bias
 * in vb, its compliance factor e_i (c_i = e_i K_ii, BLOCK_EPS included) and
 * the inverse for a uniform factor (NULL: mixed). 0: sweep instead. */
static int block_totals(int count, double K[4][4], double inv[4][4], const double vb[4], const double e[4],
                        const double acc[4], double x[4])
{
    if (inv) {
        double r[4], d[4];
        for (int i = 0; i < count; i++) r[i] = vb[i] + e[i] * K[i][i] * acc[i];
        block_apply(count, inv, r, d);
        int ok = 1;
        for (int i = 0; i < count; i++) {
            x[i] = acc[i] - d[i];
            ok &= x[i] >= 0.0;
        }
        if (ok) return 1;
    }
    double A[4][4], b[4];
    for (int i = 0; i < count; i++) {
        b[i] = vb[i];
        for (int j = 0; j < count; j++) {
            A[i][j] = K[i][j];
            b[i] -= K[i][j] * acc[j];
        }
        A[i][i] += e[i] * K[i][i];
    }
    return block_lcp(count, A, b, x, inv ? count - 1 : count);
}

/* The normal rows of an unlocked manifold of 2-4 points solved as a block;
 * 0 (nothing changed) when the caller must sweep them instead. */
BLOCK_INLINE int solve_normals_block(contact_constraint *c, contact_block *blk, const step_context *ctx, int use_bias,
                               vec3 *vA, vec3 *wA, vec3 *vB, vec3 *wB, double mA, double mB)
{
    const int count = c->count;
    vec3 n = c->n;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    vec3 dqa = ctx->dq[c->a], dqb = ctx->dq[c->b];
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    double gamma = contact_block_gamma(c, ctx) + BLOCK_EPS;
    double vb[4], e[4], x[4], acc[4];
    int soft_rows = 0;
    for (int i = 0; i < count; i++) {
        const constraint_rows *r = &c->r[i];
        double s = c->an[i].base_separation + v3_dot(n, dpab) + v3_dot(dqb, r->rb_n) - v3_dot(dqa, r->ra_n);
        double bias = 0.0;
        e[i] = BLOCK_EPS;
        if (s > 0.0) {
            bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        } else if (push) {
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
            e[i] = gamma;
            soft_rows++;
        }
        vb[i] = v3_dot(n, v3_sub(*vB, *vA)) + v3_dot(*wB, r->rb_n) - v3_dot(*wA, r->ra_n) + bias;
        acc[i] = c->p[i].normal_impulse;
    }
    double(*inv)[4] = soft_rows == count || soft_rows == 0 ? block_inverse(c, blk, ctx, soft_rows == count) : NULL;
    /* a face whose totals all stay pressed (the common case): block_totals'
     * first answer spelled out inline, the same arithmetic (stack at
     * default, with block_make_factor's 4-row case: 137.19M -> 135.65M
     * instructions, callgrind; bit-identical) */
    int fast = 0;
    if (inv && count == 4) {
        double r[4] = {vb[0] + e[0] * blk->K[0][0] * acc[0], vb[1] + e[1] * blk->K[1][1] * acc[1],
                       vb[2] + e[2] * blk->K[2][2] * acc[2], vb[3] + e[3] * blk->K[3][3] * acc[3]}, d[4];
        block_apply4(inv, r, d);
        x[0] = acc[0] - d[0]; x[1] = acc[1] - d[1]; x[2] = acc[2] - d[2]; x[3] = acc[3] - d[3];
        fast = x[0] >= 0.0 && x[1] >= 0.0 && x[2] >= 0.0 && x[3] >= 0.0;
    }
    if (!fast && !block_totals(count, blk->K, inv, vb, e, acc, x)) return 0;
    for (int i = 0; i < count; i++) {
        constraint_point *p = &c->p[i];
        const constraint_rows *r = &c->r[i];
        double lambda = x[i] - acc[i];
        p->normal_impulse = x[i];
        p->total_normal_impulse += lambda;
        *vA = v3_madd(*vA, -mA * lambda, n);
        *wA = v3_madd(*wA, -lambda, r->ia_n);
        *vB = v3_madd(*vB, mB * lambda, n);
        *wB = v3_madd(*wB, lambda, r->ib_n);
    }
    return 1;
}

double contact_prepare(contact_constraint *c, const step_context *ctx)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    vec3 ca = c->center_a, cb = c->center_b;
    double ws = ctx->warm_starting ? 1.0 : 0.0;
    double deepest = 0.0;
    /* the linear share of each row's inverse effective mass: a plane-locked
     * body's 1/m counts only the row's part in its plane (its inverse inertia
     * is already the reduced n n^T / (n.I n)) */
    double free_inv_mass = A->inv_mass + B->inv_mass;
    double lin_n = free_inv_mass, lin_1 = lin_n, lin_2 = lin_n;
    if (c->locked) {
        vec3 la = constraint_lock_a(c), lb = constraint_lock_b(c);
        lin_n = locked_inv_mass(A->inv_mass, c->n, la) + locked_inv_mass(B->inv_mass, c->n, lb);
        lin_1 = locked_inv_mass(A->inv_mass, c->t1, la) + locked_inv_mass(B->inv_mass, c->t1, lb);
        lin_2 = locked_inv_mass(A->inv_mass, c->t2, la) + locked_inv_mass(B->inv_mass, c->t2, lb);
    }
    int sticking = 1;
    for (int j = 0; j < c->count; j++) {
        const manifold_point *mp = &c->m->points[j];
        constraint_point *p = &c->p[j];
        constraint_anchor *q = &c->an[j];
        constraint_rows *r = &c->r[j];
        q->ra = v3_sub(mp->point, ca);
        q->rb = v3_sub(mp->point, cb);
        r->ra_n = v3_cross(q->ra, c->n);
        r->rb_n = v3_cross(q->rb, c->n);
        r->ia_n = m3_mulv(A->inv_inertia, r->ra_n);
        r->ib_n = m3_mulv(B->inv_inertia, r->rb_n);
        r->ra_t[0] = v3_cross(q->ra, c->t1);
        r->rb_t[0] = v3_cross(q->rb, c->t1);
        r->ra_t[1] = v3_cross(q->ra, c->t2);
        r->rb_t[1] = v3_cross(q->rb, c->t2);
        for (int q = 0; q < 2; q++) {
            r->ia_t[q] = m3_mulv(A->inv_inertia, r->ra_t[q]);
            r->ib_t[q] = m3_mulv(B->inv_inertia, r->rb_t[q]);
        }
        /* the seed's denominator 1/m1 + 1/m2 + n.((I1^-1 (r1 x n)) x r1) + ..., from the
         * rows above: n.((I^-1 (r x n)) x r) = (I^-1 (r x n)).(r x n) */
        double kn = lin_n + v3_dot(r->ia_n, r->ra_n) + v3_dot(r->ib_n, r->rb_n);
        double k1 = lin_1 + v3_dot(r->ia_t[0], r->ra_t[0]) + v3_dot(r->ib_t[0], r->rb_t[0]);
        double k2 = lin_2 + v3_dot(r->ia_t[1], r->ra_t[1]) + v3_dot(r->ib_t[1], r->rb_t[1]);
        r->normal_mass = row_mass(kn, free_inv_mass);
        r->tangent_mass[0] = row_mass(k1, free_inv_mass);
        r->tangent_mass[1] = row_mass(k2, free_inv_mass);
        q->base_separation = mp->separation;
        p->relative_velocity = contact_approach_velocity(impulse_relative_normal_velocity(B, A, q->rb, q->ra, c->n),
                                                         c->gravity_closing, mp->separation);
        p->normal_impulse = ws * p->normal_impulse; /* last step's, in place (constraint.h) */
        p->tangent_impulse[0] = ws * p->tangent_impulse[0];
        p->tangent_impulse[1] = ws * p->tangent_impulse[1];
        p->total_normal_impulse = 0.0;
        /* pressed, and inside the cone (solve_manifold's friction order) */
        double stick = STICKING_SHARE * c->friction * p->normal_impulse;
        sticking &= p->normal_impulse > 0.0 &&
                    p->tangent_impulse[0] * p->tangent_impulse[0] + p->tangent_impulse[1] * p->tangent_impulse[1] < stick * stick;
        if (ctx->penalty) penalty_prepare_point(p, r, &c->spring[j], ctx);
        if (-mp->separation > deepest) deepest = -mp->separation;
    }
    prepare_rolling(c, A, B);
    if (ctx->blocks && !ctx->penalty) block_prepare(c, &ctx->blocks[c - ctx->constraints], ctx, A->inv_mass, B->inv_mass, sticking);
    return deepest;
}

void contact_warm_start(contact_constraint *c, impulse_body *bodies)
{
    impulse_body *A = &bodies[c->a], *B = &bodies[c->b];
    /* the velocities and the basis in locals: the stores to the points'
     * doubles would otherwise reload them at every point (same arithmetic,
     * in impulse_apply's order) */
    vec3 vA = A->v, wA = A->w, vB = B->v, wB = B->w;
    const vec3 n = c->n, t1 = c->t1, t2 = c->t2;
    const double mA = A->inv_mass, mB = B->inv_mass;
    const int count = c->count, locked = c->locked != 0;
    for (int i = 0; i < count; i++) {
        constraint_point *p = &c->p[i];
        vec3 P = v3_add(v3_scale(n, p->normal_impulse),
                        v3_add(v3_scale(t1, p->tangent_impulse[0]), v3_scale(t2, p->tangent_impulse[1])));
        p->total_normal_impulse += p->normal_impulse;
        /* seed convention: body 1 = B receives +P (n points from A to B) */
        vB = v3_madd(vB, mB, P);
        wB = v3_add(wB, m3_mulv(B->inv_inertia, v3_cross(c->an[i].rb, P)));
        vA = v3_madd(vA, -mA, P);
        wA = v3_sub(wA, m3_mulv(A->inv_inertia, v3_cross(c->an[i].ra, P)));
        if (locked) {
            vA = keep_in_plane(vA, constraint_lock_a(c));
            vB = keep_in_plane(vB, constraint_lock_b(c));
        }
    }
    A->v = vA; A->w = wA;
    B->v = vB; B->w = wB;
    if (c->rolling > 0.0) {
        vec3 L = v3_add(v3_scale(c->t1, c->x->rolling_impulse[0]), v3_scale(c->t2, c->x->rolling_impulse[1]));
        A->w = v3_sub(A->w, m3_mulv(A->inv_inertia, L));
        B->w = v3_add(B->w, m3_mulv(B->inv_inertia, L));
    }
}

/* A manifold's two bodies' velocities, in the solve's locals. */
typedef struct pair_velocity {
    vec3 vA, wA, vB, wB;
} pair_velocity;

/* One manifold's friction rows, point after point, for a face that solves
 * them first (solve_manifold). The sweep after the normal rows is the same
 * loop written inline there: called for both, GCC kept the velocities in
 * memory (callgrind, stack at default: +0.3M instructions). */
BLOCK_INLINE pair_velocity solve_friction(contact_constraint *c, pair_velocity u, double mA, double mB, vec3 lock_a,
                                          vec3 lock_b, const int locked)
{
    vec3 dv = v3_sub(u.vB, u.vA);
    const int count = c->count;
    for (int i = 0; i < count; i++) {
        constraint_point *p = &c->p[i];
        const constraint_rows *r = &c->r[i];
        double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
        double v1 = v3_dot(dv, c->t1) + v3_dot(u.wB, r->rb_t[0]) - v3_dot(u.wA, r->ra_t[0]);
        double v2 = v3_dot(dv, c->t2) + v3_dot(u.wB, r->rb_t[1]) - v3_dot(u.wA, r->ra_t[1]);
        double n1 = o1 - r->tangent_mass[0] * v1;
        double n2 = o2 - r->tangent_mass[1] * v2;
        double limit = c->friction * p->normal_impulse;
        if (n1 * n1 + n2 * n2 > limit * limit)
            coulomb_over_cone(&n1, &n2, o1, o2, v1, v2, r->tangent_mass[0], r->tangent_mass[1], limit);
        p->tangent_impulse[0] = n1;
        p->tangent_impulse[1] = n2;
        double d1 = n1 - o1, d2 = n2 - o2;
        vec3 P = v3_add(v3_scale(c->t1, d1), v3_scale(c->t2, d2));
        u.vA = v3_madd(u.vA, -mA, P);
        u.vB = v3_madd(u.vB, mB, P);
        u.wA = v3_sub(u.wA, v3_add(v3_scale(r->ia_t[0], d1), v3_scale(r->ia_t[1], d2)));
        u.wB = v3_add(u.wB, v3_add(v3_scale(r->ib_t[0], d1), v3_scale(r->ib_t[1], d2)));
        if (locked) { u.vA = keep_in_plane(u.vA, lock_a); u.vB = keep_in_plane(u.vB, lock_b); }
        dv = v3_sub(u.vB, u.vA);
    }
    return u;
}

/* Normal and friction rows of one manifold; use_bias selects the solve pass
 * (position error fed back) over the relax pass (velocity only).
 *
 * A face whose normal rows are one block (a block-ready manifold) solves
 * its friction rows first, so that the pass ends with its normal rows exact
 * (Box2D v2's order). The other way round, the friction impulses at points
 * below the centres of mass turned the boxes after their normal rows were
 * solved, and a symmetric stack's tilt mode grew from rounding (about one
 * e-fold a second) and walked it sideways once it slid (120 s, top box): a
 * 3-stack of unit boxes at fast, dt 1/60, 29 cm; at default, dt 1/30, 3-,
 * 4- and 5-stacks 33, 32 and 11 cm; with the friction rows first they stay
 * on their axis to 1e-15 m. Not first:
 * - a face with a point not warm-started with a normal impulse: its cone
 *   would be 0 in the first pass (a spinning cylinder, whose cap points are
 *   new every step, slowed 24 % short of Coulomb at fast, dt 1/15);
 * - a face with a point sliding (its friction at STICKING_SHARE of its
 *   cone or more): its cone is the one of the normal impulse just solved
 *   (first, a box sliding over separate floor patches left the plane's
 *   path by 1.4 mm at dt 1/240, 2 um before: test_separate_floors_varied);
 * - a world with a heavy body on a light one (solver.c, prepare_points):
 *   the heavy load's normal impulses turn the light body under it, and the
 *   friction rows must come after them (first, a 1000:1 pair at default
 *   walked 6.5 cm in 120 s; 10 kg on two 1 kg boxes at fast fell);
 * - manifolds swept point after point (locked, 1-point, the wide passes):
 *   the order alone does not hold a swept face (30 3-stacks solved wide,
 *   default, dt 1/30, 60 s: 27 cm, 22 cm with friction first).
 * Fast at dt 1/20-1/30 (springs at a quarter of the sub-step rate) still
 * walks: 3- and 4-stacks 10-34 cm in 120 s. */

/* contact_solve's body, built twice: `locked` (a constant in each build)
 * keeps plane-locked bodies' velocities in their planes after every row; the
 * build for free bodies carries none of it. */
BLOCK_INLINE void solve_manifold(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces,
                                 const int locked)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    vec3 vA = A->v, wA = A->w, vB = B->v, wB = B->w;
    double mA = A->inv_mass, mB = B->inv_mass;
    vec3 n = c->n;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    vec3 dqa = ctx->dq[c->a], dqb = ctx->dq[c->b];
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    const int count = c->count;
    vec3 lock_a = v3_zero(), lock_b = v3_zero();
    if (locked) { lock_a = c->x->lock_a; lock_b = c->x->lock_b; }
    contact_block *blk = ctx->blocks ? &ctx->blocks[c - ctx->constraints] : NULL;
    const int friction = ctx->friction && c->friction > 0;
    const int face = !locked && blk && blk->ready;
    const int first = friction && face && blk->friction_first;
    if (first) {
        pair_velocity u = solve_friction(c, (pair_velocity){vA, wA, vB, wB}, mA, mB, lock_a, lock_b, 0);
        vA = u.vA; wA = u.wA; vB = u.vB; wB = u.wB;
    }
    int blocked = face && (blk->column_done || (!(hold_bounces && c->restitution > 0.0) &&
                                                solve_normals_block(c, blk, ctx, use_bias, &vA, &wA, &vB, &wB, mA, mB)));
    for (int i = 0; i < count && !blocked; i++) {
        constraint_point *p = &c->p[i];
        const constraint_rows *r = &c->r[i];
        /* current separation: small-angle update of the anchors */
        double s = c->an[i].base_separation + v3_dot(n, dpab) + v3_dot(dqb, r->rb_n) - v3_dot(dqa, r->ra_n);
        double bias = 0.0, mass_scale = 1.0, impulse_scale = 0.0;
        if (s > 0.0) {
            bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        } else if (push) {
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
            if (soft) {
                mass_scale = c->soft.mass_scale;
                impulse_scale = c->soft.impulse_scale;
            }
        }
        double vn = v3_dot(n, v3_sub(vB, vA)) + v3_dot(wB, r->rb_n) - v3_dot(wA, r->ra_n);
        double lambda = -r->normal_mass * mass_scale * (vn + bias) - impulse_scale * p->normal_impulse;
        double total = p->normal_impulse + lambda;
        if (total < 0.0) total = 0.0;
        if (hold_bounces && s > 0.0 && c->restitution > 0.0 && total > p->normal_impulse) total = p->normal_impulse;
        lambda = total - p->normal_impulse;
        p->normal_impulse = total;
        p->total_normal_impulse += lambda;
        vA = v3_madd(vA, -mA * lambda, n);
        wA = v3_madd(wA, -lambda, r->ia_n);
        vB = v3_madd(vB, mB * lambda, n);
        wB = v3_madd(wB, lambda, r->ib_n);
        if (locked) { vA = keep_in_plane(vA, lock_a); vB = keep_in_plane(vB, lock_b); }
    }
    if (friction && !first) {
        vec3 dv = v3_sub(vB, vA);
        for (int i = 0; i < count; i++) {
            constraint_point *p = &c->p[i];
            const constraint_rows *r = &c->r[i];
            double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
            double v1 = v3_dot(dv, c->t1) + v3_dot(wB, r->rb_t[0]) - v3_dot(wA, r->ra_t[0]);
            double v2 = v3_dot(dv, c->t2) + v3_dot(wB, r->rb_t[1]) - v3_dot(wA, r->ra_t[1]);
            double n1 = o1 - r->tangent_mass[0] * v1;
            double n2 = o2 - r->tangent_mass[1] * v2;
            double limit = c->friction * p->normal_impulse;
            if (n1 * n1 + n2 * n2 > limit * limit)
                coulomb_over_cone(&n1, &n2, o1, o2, v1, v2, r->tangent_mass[0], r->tangent_mass[1], limit);
            p->tangent_impulse[0] = n1;
            p->tangent_impulse[1] = n2;
            double d1 = n1 - o1, d2 = n2 - o2;
            vec3 P = v3_add(v3_scale(c->t1, d1), v3_scale(c->t2, d2));
            vA = v3_madd(vA, -mA, P);
            vB = v3_madd(vB, mB, P);
            wA = v3_sub(wA, v3_add(v3_scale(r->ia_t[0], d1), v3_scale(r->ia_t[1], d2)));
            wB = v3_add(wB, v3_add(v3_scale(r->ib_t[0], d1), v3_scale(r->ib_t[1], d2)));
            if (locked) { vA = keep_in_plane(vA, lock_a); vB = keep_in_plane(vB, lock_b); }
            dv = v3_sub(vB, vA);
        }
    }
    if (c->rolling > 0.0) solve_rolling(c, &wA, &wB, A, B);
    A->v = vA; A->w = wA;
    B->v = vB; B->w = wB;
}

void contact_solve_normals(contact_constraint *c, const step_context *ctx, int use_bias)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    solve_normals_block(c, &ctx->blocks[c - ctx->constraints], ctx, use_bias, &A->v, &A->w, &B->v, &B->w, A->inv_mass,
                        B->inv_mass);
}

void contact_solve(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces)
{
    if (c->locked) solve_manifold(c, ctx, use_bias, hold_bounces, 1);
    else solve_manifold(c, ctx, use_bias, hold_bounces, 0);
}

/* The shock pass's normal rows of an unlocked manifold of 2-4 points as
 * one block (see solve_normals_block): rigid rows against the immovable
 * lower body, K_ij = fa (1/mA + ...) + fb (1/mB + ...), each total impulse
 * normal_impulse + shock_normal kept >= 0 (the pass pulls back at most what
 * the regular solve pushed): the same problem in x = normal_impulse +
 * shock_normal, with acc = normal_impulse. One point after another, a 1000 kg
 * box on a 1 kg one walked 3 mm in 10 s at default. 0: sweep instead. */
static int shock_normals_block(contact_constraint *c, contact_block *blk, const step_context *ctx, int use_bias,
                               double fa, double fb, double *shock_normal)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    const int count = c->count;
    vec3 n = c->n;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    vec3 ra_n[4], rb_n[4], ia_n[4], ib_n[4];
    double vb[4], e[4], x[4], acc[4];
    for (int i = 0; i < count; i++) {
        const constraint_anchor *q = &c->an[i];
        ra_n[i] = v3_cross(q->ra, n);
        rb_n[i] = v3_cross(q->rb, n);
        ia_n[i] = m3_mulv(A->inv_inertia, ra_n[i]);
        ib_n[i] = m3_mulv(B->inv_inertia, rb_n[i]);
    }
    if (blk->shock_ready < 0) return 0;
    if (!blk->shock_ready) {
        /* the rows and which body is held are fixed over the step: built at the first call */
        double M[4][4];
        double lin = fa * A->inv_mass + fb * B->inv_mass;
        blk->shock_ready = -1;
        for (int i = 0; i < count; i++) {
            for (int j = 0; j <= i; j++)
                blk->shock_K[i][j] = blk->shock_K[j][i] =
                    lin + fa * v3_dot(ia_n[i], ra_n[j]) + fb * v3_dot(ib_n[i], rb_n[j]);
            if (!(blk->shock_K[i][i] > 0.0)) return 0;
        }
        for (int i = 0; i < count; i++) {
            for (int j = 0; j < count; j++) M[i][j] = blk->shock_K[i][j];
            M[i][i] += BLOCK_EPS * blk->shock_K[i][i];
        }
        if (!block_factor(count, M, blk->shock_inv)) return 0;
        blk->shock_ready = 1;
    }
    for (int i = 0; i < count; i++) {
        const constraint_point *p = &c->p[i];
        double s = c->an[i].base_separation + v3_dot(n, dpab) + v3_dot(ctx->dq[c->b], rb_n[i]) - v3_dot(ctx->dq[c->a], ra_n[i]);
        double bias = 0.0;
        if (s > 0.0) bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        else if (push)
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
        vb[i] = v3_dot(n, v3_sub(B->v, A->v)) + v3_dot(B->w, rb_n[i]) - v3_dot(A->w, ra_n[i]) + bias;
        acc[i] = p->normal_impulse;
        e[i] = BLOCK_EPS;
    }
    if (!block_totals(count, blk->shock_K, blk->shock_inv, vb, e, acc, x)) return 0;
    for (int i = 0; i < count; i++) {
        constraint_point *p = &c->p[i];
        double lambda = x[i] - acc[i];
        shock_normal[i] = lambda;
        p->total_normal_impulse += lambda;
        A->v = v3_madd(A->v, -fa * A->inv_mass * lambda, n);
        A->w = v3_madd(A->w, -fa * lambda, ia_n[i]);
        B->v = v3_madd(B->v, fb * B->inv_mass * lambda, n);
        B->w = v3_madd(B->w, fb * lambda, ib_n[i]);
    }
    return 1;
}

/* Shock propagation (Guendelman et al. 2003): the body nearer the ground is
 * treated as immovable, so a heavy body is held by the light body under it
 * instead of slowly crushing it (an iterative solver converges at a rate set
 * by the mass ratio). Constraints arrive sorted bottom-up. */
void contact_solve_shock(contact_constraint *c, const step_context *ctx, int use_bias, int hold_bounces, int lower_is_a)
{
    impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    /* fa, fb scale each body's response: the lower body gets 0 */
    double fa = lower_is_a ? 0.0 : 1.0, fb = lower_is_a ? 1.0 : 0.0;
    vec3 n = c->n;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    vec3 lock_a = constraint_lock_a(c), lock_b = constraint_lock_b(c);
    double shock_normal[MANIFOLD_MAX_POINTS]; /* this pass's normal impulses, never warm-started */
    /* a wide-solved manifold has no block (contact_prepare built none): its points are swept */
    contact_block *blk = ctx->blocks && c->wide_batch < 0 ? &ctx->blocks[c - ctx->constraints] : NULL;
    int blocked = !c->locked && c->count >= 2 && blk && !(hold_bounces && c->restitution > 0.0) &&
                  shock_normals_block(c, blk, ctx, use_bias, fa, fb, shock_normal);
    for (int i = 0; i < c->count && !blocked; i++) {
        constraint_point *p = &c->p[i];
        const constraint_anchor *q = &c->an[i];
        /* rows from the anchors: a wide-solved point keeps only those */
        vec3 ra_n = v3_cross(q->ra, n), rb_n = v3_cross(q->rb, n);
        vec3 ia_n = m3_mulv(A->inv_inertia, ra_n), ib_n = m3_mulv(B->inv_inertia, rb_n);
        double s = q->base_separation + v3_dot(n, dpab) + v3_dot(ctx->dq[c->b], rb_n) - v3_dot(ctx->dq[c->a], ra_n);
        double k = fa * (locked_inv_mass(A->inv_mass, n, lock_a) + v3_dot(ra_n, ia_n)) +
                   fb * (locked_inv_mass(B->inv_mass, n, lock_b) + v3_dot(rb_n, ib_n));
        shock_normal[i] = 0.0;
        if (!(row_mass(k, fa * A->inv_mass + fb * B->inv_mass) > 0.0)) continue;
        /* rigid against an immovable lower body, with the soft push-out rate */
        double bias = 0.0;
        if (s > 0.0) bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        else if (push)
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
        double vn = v3_dot(n, v3_sub(B->v, A->v)) + v3_dot(B->w, rb_n) - v3_dot(A->w, ra_n);
        /* the pass may pull back at most what the regular solve pushed */
        double lambda = dmax(-(vn + bias) / k, -p->normal_impulse);
        if (hold_bounces && s > 0.0 && c->restitution > 0.0 && lambda > 0.0) lambda = 0.0;
        shock_normal[i] = lambda;
        p->total_normal_impulse += lambda;
        A->v = v3_madd(A->v, -fa * A->inv_mass * lambda, n);
        A->w = v3_madd(A->w, -fa * lambda, ia_n);
        B->v = v3_madd(B->v, fb * B->inv_mass * lambda, n);
        B->w = v3_madd(B->w, fb * lambda, ib_n);
        if (c->locked) { A->v = keep_in_plane(A->v, lock_a); B->v = keep_in_plane(B->v, lock_b); }
    }
    if (!ctx->friction || c->friction <= 0) return;
    for (int i = 0; i < c->count; i++) {
        constraint_point *p = &c->p[i];
        const constraint_anchor *q = &c->an[i];
        vec3 vp = v3_sub(v3_add(B->v, v3_cross(B->w, q->rb)), v3_add(A->v, v3_cross(A->w, q->ra)));
        vec3 t[2] = {c->t1, c->t2};
        double nw[2];
        for (int j = 0; j < 2; j++) {
            vec3 rat = v3_cross(q->ra, t[j]), rbt = v3_cross(q->rb, t[j]);
            double k = fa * (locked_inv_mass(A->inv_mass, t[j], lock_a) + v3_dot(rat, m3_mulv(A->inv_inertia, rat))) +
                       fb * (locked_inv_mass(B->inv_mass, t[j], lock_b) + v3_dot(rbt, m3_mulv(B->inv_inertia, rbt)));
            nw[j] = row_mass(k, fa * A->inv_mass + fb * B->inv_mass) > 0.0 ? -v3_dot(vp, t[j]) / k : 0.0;
        }
        /* Coulomb on the total: what the regular pass used plus this pass */
        double o1 = p->tangent_impulse[0], o2 = p->tangent_impulse[1];
        double t1 = o1 + nw[0], t2 = o2 + nw[1];
        coulomb_clamp(&t1, &t2, c->friction * dmax(p->normal_impulse + shock_normal[i], 0.0));
        vec3 P = v3_add(v3_scale(t[0], t1 - o1), v3_scale(t[1], t2 - o2));
        A->v = v3_madd(A->v, -fa * A->inv_mass, P);
        A->w = v3_sub(A->w, v3_scale(m3_mulv(A->inv_inertia, v3_cross(q->ra, P)), fa));
        B->v = v3_madd(B->v, fb * B->inv_mass, P);
        B->w = v3_add(B->w, v3_scale(m3_mulv(B->inv_inertia, v3_cross(q->rb, P)), fb));
        if (c->locked) { A->v = keep_in_plane(A->v, lock_a); B->v = keep_in_plane(B->v, lock_b); }
    }
}
