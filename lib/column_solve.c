/* column_solve.c - the normal rows of a column of stacked manifolds solved
 * together and exactly, in place of one Gauss-Seidel visit per manifold.
 *
 * A column is a chain of scalar, unlocked manifolds of 4 points (faces) in which
 * each body between two of them is dynamic and touches nothing else (a
 * tower of boxes on the ground). Its normal rows' matrix is block
 * tridiagonal: the 4 x 4 diagonal blocks are the manifolds' own K + C + E
 * (contact_solver.c, solve_normals_block), the off-diagonal block between
 * neighbours i, j is sa sb (m_s n_i.n_j + (r_i x n_i).I_s^-1 (r_j x n_j))
 * through the shared body s (sa, sb: +1 where s is the manifold's b, -1
 * where it is its a). Its LDL^T (Schur complements S_k = D_k - B^T S^-1 B,
 * G_k = S_k^-1 B_k) is made once a step for the soft rows and once for the
 * rigid ones, at the first pass that reads it; a pass then costs one
 * forward and one backward substitution, O(rows).
 *
 * Why: one sweep over a column's manifolds does not hold a spring past a
 * quarter of the sub-step rate (contact_solver.c, block_loaded_softness),
 * and at that cap a column of n boxes sags as n^2 (20 boxes at default:
 * 2.77 cm, 40: 11.05 cm). Solved exactly, the soft step's spring is the
 * implicit one, stable at any stiffness, so a column's manifolds may take
 * the stiffer loaded springs at one iteration too. */
#include <stdlib.h>
#include "column_solve.h"
#include "contact_solver.h"
#include "block_ldl.h"
#include "array.h"

void column_memory_free(column_memory *m)
{
    free(m->links);
    free(m->start);
    free(m->scratch);
    m->links = m->start = m->scratch = NULL;
    m->links_capacity = m->start_capacity = m->scratch_capacity = m->count = 0;
}

/* The shortest column solved directly. With two iterations or more
 * (accurate) any column of two manifolds or more, where the direct solve
 * replaces the sweeps the stiffer springs would need (contact_solver.c;
 * stack and mass_ratio at accurate: 865.1M -> 486.6M instructions,
 * callgrind). With one iteration, a column that would sag more than
 * COLUMN_MAX_SAG on the springs its manifolds hold alone, because below
 * that the direct solve is extra work (columns of every length at default:
 * the 10-box stack 134.0M -> 147.3M instructions, +9.9 %; its twisted
 * columns walk 3.59 -> 0.28 cm, 32 seeds). Alone a loaded face springs at
 * f' = min(2 f, 1/(4h)) (block_loaded_softness; f the setting's, already
 * at most 1/(4h)), and a column of n equal boxes sags n^2 g / omega'^2
 * there (2 k g / omega'^2 under k boxes, n g / omega'^2 on the ground at
 * the same f'; test_column_sag_loaded_softness): the 10-column 0.69 cm
 * at dt 1/60-1/240 (60 Hz; the 11-column 0.84), 2.76 cm at 1/30 (30 Hz;
 * measured 2.55), 11.0 cm at 1/15 (15 Hz; measured 10.2, the ground's
 * spring is stiffer there). The bound is three quarters of the 1 cm the
 * 10-column must hold (issue #16), the rest left for what the equal-box
 * model leaves out (unequal boxes, a heavier one on top): columns from 11
 * manifolds at dt 1/60-1/240, from 6 at 1/30, from 3 at 1/15. The same
 * lengths at fast, although there a face alone keeps the setting's spring
 * (the 10-column sags 2.55 cm at dt 1/60): its columns take a relax pass
 * of their own (solver.c, relax_columns), which for the 10-box stack at
 * fast would cost +56 % (94.7M -> 147.6M instructions). */
#define COLUMN_MIN_ACCURATE 2
#define COLUMN_MAX_SAG 0.0075

/* A column's sag per manifold squared (n^2 unit for n manifolds) on the
 * springs a loaded face holds alone; 0 where every column counts (without
 * gravity column_find finds none). */
static double column_unit_sag(const step_context *ctx)
{
    if (ctx->iterations >= 2) return 0.0;
    double omega = 2.0 * 3.141592653589793 * dmin(2.0 * ctx->contact_hertz, 0.25 * ctx->inv_h);
    return ctx->gravity_length / (omega * omega);
}

/* Whether a column of n manifolds is solved directly. */
static int column_counts(int n, double unit_sag)
{
    if (n < COLUMN_MIN_ACCURATE) return 0;
    return unit_sag == 0.0 || (double)n * n * unit_sag > COLUMN_MAX_SAG;
}

/* The manifold after c through body s, or -1 where the column ends there. */
static int next_of(const step_context *ctx, const int *first, const int *second, const int *deg, const int *elig,
                   int c, int s)
{
    if (!(ctx->bodies[s].inv_mass > 0.0) || deg[s] != 2) return -1;
    int o = first[s] == c ? second[s] : first[s];
    if (o < 0 || o == c || !elig[o]) return -1;
    const contact_constraint *cc = ctx->constraints;
    int far_c = cc[c].a == s ? cc[c].b : cc[c].a, far_o = cc[o].a == s ? cc[o].b : cc[o].a;
    return far_c == far_o ? -1 : o; /* two manifolds between one pair: no column */
}

/* How heavy-on-light manifold c is: 0, COLUMN_HEAVY or COLUMN_VERY_HEAVY. */
static int heaviness(const step_context *ctx, const contact_constraint *c)
{
    double ia = ctx->bodies[c->a].inv_mass, ib = ctx->bodies[c->b].inv_mass;
    double lo = dmin(ia, ib), hi = dmax(ia, ib); /* (a static body: lo 0, never heavy-on-light) */
    if (!(lo > 0.0) || hi < SHOCK_MASS_RATIO * lo) return 0;
    return hi >= COLUMN_VERY_HEAVY_RATIO * lo ? COLUMN_VERY_HEAVY : COLUMN_HEAVY;
}

/* The heaviest of links begin .. end - 1, as contact_block.heavy_column:
 * 0 for a column shorter than COLUMN_MIN_HEAVY. */
static int column_heaviness(const step_context *ctx, const column_link *link, int begin, int end)
{
    int heavy = 0;
    for (int i = begin; end - begin >= COLUMN_MIN_HEAVY && i < end; i++) {
        int h = heaviness(ctx, &ctx->constraints[link[i].con]);
        if (h > heavy) heavy = h;
    }
    return heavy;
}

int column_find(column_memory *m, const step_context *ctx, const int *scalar, int scalar_count, int heavy_on_light)
{
    m->count = 0;
    if (!ctx->blocks || ctx->penalty || scalar_count < 1) return 1;
    /* no stiffer springs without gravity or warm starting
     * (block_loaded_softness): the manifolds' own solves hold the setting's;
     * without relax passes (fast) the columns' manifolds take one of their
     * own (solver.c, relax_columns) */
    int stiffens = ctx->warm_starting && ctx->gravity_length > 0.0;
    const contact_constraint *cc = ctx->constraints;
    int nb = ctx->body_count, ncon = ctx->constraint_count;
    for (int k = 0; k < scalar_count; k++) {
        contact_block *blk = &ctx->blocks[scalar ? scalar[k] : k];
        blk->column = blk->heavy_column = 0;
    }
    double unit_sag = column_unit_sag(ctx);
    heavy_on_light = heavy_on_light && scalar_count >= COLUMN_MIN_HEAVY;
    if (!stiffens || (!heavy_on_light && !column_counts(scalar_count, unit_sag))) return 1;
    if (!array_reserve(&m->scratch, &m->scratch_capacity, 3 * nb + 2 * ncon, sizeof(int))) return 0;
    int *first = (int *)m->scratch, *second = first + nb, *deg = second + nb, *elig = deg + nb, *seen = elig + ncon;
    for (int b = 0; b < nb; b++) first[b] = second[b] = -1, deg[b] = 0;
    for (int c = 0; c < ncon; c++) {
        elig[c] = seen[c] = 0;
        int body[2] = {cc[c].a, cc[c].b};
        for (int e = 0; e < 2; e++) {
            int s = body[e];
            deg[s]++;
            if (first[s] < 0) first[s] = c;
            else if (second[s] < 0) second[s] = c;
        }
    }
    for (int k = 0; k < scalar_count; k++) {
        int c = scalar ? scalar[k] : k;
        elig[c] = !cc[c].locked && cc[c].count == 4; /* faces (the blocks' sizes are constants here) */
    }
    int links = 0;
    for (int k = 0; k < scalar_count; k++) {
        int c = scalar ? scalar[k] : k;
        if (!elig[c] || seen[c]) continue;
        int na = next_of(ctx, first, second, deg, elig, c, cc[c].a);
        int nbb = next_of(ctx, first, second, deg, elig, c, cc[c].b);
        if (na >= 0 && nbb >= 0) continue; /* inside a column: reached from an end */
        seen[c] = 1;
        if (na < 0 && nbb < 0) continue;   /* alone: its own block solve */
        int begin = links, cur = c, s = na >= 0 ? cc[c].a : cc[c].b;
        for (;;) {
            if (!array_reserve(&m->links, &m->links_capacity, links + 1, sizeof(column_link))) return 0;
            column_link *l = (column_link *)m->links + links++;
            l->con = cur;
            l->shared = -1;
            seen[cur] = 1;
            int o = next_of(ctx, first, second, deg, elig, cur, s);
            if (o < 0 || seen[o]) break;
            l->shared = s;
            s = cc[o].a == s ? cc[o].b : cc[o].a;
            cur = o;
        }
        int heavy = heavy_on_light ? column_heaviness(ctx, (const column_link *)m->links, begin, links) : 0;
        if (!heavy && !column_counts(links - begin, unit_sag)) {
            links = begin;
            continue;
        }
        for (int i = begin; i < links; i++) {
            contact_block *blk = &ctx->blocks[((const column_link *)m->links)[i].con];
            blk->column = 1;
            blk->heavy_column = heavy;
        }
        if (!array_reserve(&m->start, &m->start_capacity, m->count + 2, sizeof(int))) return 0;
        int *start = (int *)m->start;
        start[m->count] = begin;
        start[++m->count] = links;
    }
    return 1;
}

/* The rows' angular arm at body s and its response I_s^-1 (r x n) there. */
static vec3 arm_at(const contact_constraint *c, int i, int s) { return c->b == s ? c->r[i].rb_n : c->r[i].ra_n; }
static vec3 response_at(const contact_constraint *c, int i, int s) { return c->b == s ? c->r[i].ib_n : c->r[i].ia_n; }

int column_keep_heavy_scalar(column_memory *m, const step_context *ctx)
{
    if (!column_find(m, ctx, NULL, ctx->constraint_count, 1)) return 0;
    for (int k = 0; ctx->blocks && k < ctx->constraint_count; k++) {
        contact_block *blk = &ctx->blocks[k];
        if (blk->heavy_column) ctx->constraints[k].keep_scalar = 1;
        blk->column = blk->heavy_column = 0; /* (column_find marks the scalar ones again) */
    }
    m->count = 0;
    return 1;
}

int column_prepare(column_memory *m, const step_context *ctx)
{
    int held = 0;
    const int *start = (const int *)m->start;
    column_link *link = (column_link *)m->links;
    for (int k = 0; k < m->count; k++) {
        column_link *head = &link[start[k]];
        head->valid = 1;
        head->bouncy = 0;
        head->factored[0] = head->factored[1] = 0;
        for (int i = start[k]; i < start[k + 1]; i++) {
            column_link *l = &link[i];
            l->c = &ctx->constraints[l->con];
            head->valid &= ctx->blocks[l->con].ready;
            head->bouncy |= l->c->restitution > 0.0;
        }
        if (!head->valid) continue;
        for (int i = start[k]; i < start[k + 1]; i++) held += ctx->blocks[link[i].con].stiff;
        for (int i = start[k]; i < start[k + 1] - 1; i++) {
            column_link *l = &link[i];
            const contact_constraint *c = &ctx->constraints[l->con], *o = &ctx->constraints[link[i + 1].con];
            int s = l->shared;
            double sign = (c->b == s) == (o->b == s) ? 1.0 : -1.0;
            double lin = ctx->bodies[s].inv_mass * v3_dot(c->n, o->n);
            for (int r = 0; r < c->count; r++) {
                vec3 arm = arm_at(c, r, s);
                for (int q = 0; q < o->count; q++) l->B[r][q] = sign * (lin + v3_dot(arm, response_at(o, q, s)));
            }
        }
    }
    return held;
}

/* The column's factor for its soft (kind 1) or rigid (0) rows: 1 made, -1
 * not positive. */
static int column_factor(column_link *link, int begin, int end, const step_context *ctx, int kind)
{
    for (int k = begin; k < end; k++) {
        column_link *l = &link[k];
        const contact_block *blk = &ctx->blocks[l->con];
        double e = (kind ? contact_block_gamma(l->c, ctx) : 0.0) + BLOCK_EPS, D[4][4];
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 4; j++) D[i][j] = blk->K[i][j];
            l->ek[kind][i] = e * blk->K[i][i];
            D[i][i] += l->ek[kind][i];
        }
        if (k > begin) {
            const double(*B)[4] = (const double(*)[4])link[k - 1].B;
            const double(*G)[4] = (const double(*)[4])link[k - 1].SiB[kind];
            for (int i = 0; i < 4; i++)
                for (int j = 0; j <= i; j++) {
                    D[i][j] -= B[0][i] * G[0][j] + B[1][i] * G[1][j] + B[2][i] * G[2][j] + B[3][i] * G[3][j];
                    D[j][i] = D[i][j];
                }
        }
        if (!block_factor4(D, l->S[kind])) return -1;
        if (k + 1 < end) {
            for (int j = 0; j < 4; j++) {
                double col[4] = {l->B[0][j], l->B[1][j], l->B[2][j], l->B[3][j]}, x[4];
                block_apply4(l->S[kind], col, x);
                l->SiB[kind][0][j] = x[0]; l->SiB[kind][1][j] = x[1]; l->SiB[kind][2][j] = x[2]; l->SiB[kind][3][j] = x[3];
            }
        }
    }
    return 1;
}

/* The right-hand sides r = vb + e K_ii acc of one manifold's rows from the
 * velocities before any of the column's impulses (as solve_normals_block);
 * counts its soft rows. */
BLOCK_INLINE int column_rhs(column_link *l, const step_context *ctx, int push, int soft)
{
    const contact_constraint *c = l->c;
    const impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
    vec3 n = c->n, dv = v3_sub(B->v, A->v), wA = A->w, wB = B->w;
    vec3 dpab = v3_sub(ctx->dp[c->b], ctx->dp[c->a]);
    vec3 dqa = ctx->dq[c->a], dqb = ctx->dq[c->b];
    double ndp = v3_dot(n, dpab), ndv = v3_dot(n, dv);
    int soft_rows = 0;
    for (int i = 0; i < 4; i++) {
        const constraint_rows *r = &c->r[i];
        double s = c->an[i].base_separation + ndp + v3_dot(dqb, r->rb_n) - v3_dot(dqa, r->ra_n);
        double bias = 0.0;
        if (s > 0.0) {
            bias = CONTACT_SPECULATIVE_BIAS(s, ctx->inv_h);
        } else if (push) {
            bias = CONTACT_PUSH_BIAS(soft, s, c->soft.bias_rate, ctx->baumgarte_rate, ctx->slop, -ctx->push_max, 0.0,
                                     dmax, dmin);
            soft_rows++;
        }
        l->acc[i] = c->p[i].normal_impulse;
        l->z[i] = ndv + v3_dot(wB, r->rb_n) - v3_dot(wA, r->ra_n) + bias;
    }
    return soft_rows;
}

/* z -= M^T y (forward) and z -= M y (backward) for 4 x 4 blocks, spelled out. */
#define MT_Y(M, y, i) ((M)[0][i] * (y)[0] + (M)[1][i] * (y)[1] + (M)[2][i] * (y)[2] + (M)[3][i] * (y)[3])
#define M_Y(M, y, i) ((M)[i][0] * (y)[0] + (M)[i][1] * (y)[1] + (M)[i][2] * (y)[2] + (M)[i][3] * (y)[3])

/* The forward and backward substitutions; z holds r in, the increments y
 * out. 0 when a row's total would pull. */
static int substitute(column_link *link, int begin, int end, int kind)
{
    for (int k = begin + 1; k < end; k++) {
        column_link *l = &link[k];
        const double(*G)[4] = (const double(*)[4])link[k - 1].SiB[kind];
        const double *pz = link[k - 1].z;
        double z0 = MT_Y(G, pz, 0), z1 = MT_Y(G, pz, 1), z2 = MT_Y(G, pz, 2), z3 = MT_Y(G, pz, 3);
        l->z[0] -= z0; l->z[1] -= z1; l->z[2] -= z2; l->z[3] -= z3;
    }
    int ok = 1;
    for (int k = end - 1; k >= begin; k--) {
        column_link *l = &link[k];
        double y[4];
        block_apply4(l->S[kind], l->z, y);
        if (k + 1 < end) {
            const double(*G)[4] = (const double(*)[4])l->SiB[kind];
            const double *x = link[k + 1].z;
            y[0] -= M_Y(G, x, 0); y[1] -= M_Y(G, x, 1); y[2] -= M_Y(G, x, 2); y[3] -= M_Y(G, x, 3);
        }
        for (int i = 0; i < 4; i++) {
            l->z[i] = y[i];
            ok &= l->acc[i] - y[i] >= 0.0;
        }
    }
    return ok;
}

/* One column's normal rows; 0 (nothing changed) when its manifolds must solve them. */
static int solve_column(column_link *link, int begin, int end, const step_context *ctx, int use_bias, int hold_bounces)
{
    int soft = ctx->correction == CAROM_CORRECTION_SOFT;
    int push = use_bias && (soft || ctx->correction == CAROM_CORRECTION_BAUMGARTE);
    int soft_rows = 0, rows = 0;
    column_link *head = &link[begin];
    if (hold_bounces && head->bouncy) return 0;
    for (int k = begin; k < end; k++) {
        soft_rows += column_rhs(&link[k], ctx, push, soft);
        rows += 4;
    }
    if (soft_rows != 0 && soft_rows != rows) return 0;
    int kind = soft_rows != 0;
    if (!head->factored[kind]) head->factored[kind] = column_factor(link, begin, end, ctx, kind);
    if (head->factored[kind] < 0) return 0;
    for (int k = begin; k < end; k++) {
        column_link *l = &link[k];
        for (int i = 0; i < 4; i++) l->z[i] += l->ek[kind][i] * l->acc[i];
    }
    if (!substitute(link, begin, end, kind)) return 0;
    for (int k = begin; k < end; k++) {
        column_link *l = &link[k];
        contact_constraint *c = l->c;
        impulse_body *A = &ctx->bodies[c->a], *B = &ctx->bodies[c->b];
        vec3 vA = A->v, wA = A->w, vB = B->v, wB = B->w, n = c->n;
        double mA = A->inv_mass, mB = B->inv_mass;
        for (int i = 0; i < 4; i++) {
            constraint_point *p = &c->p[i];
            const constraint_rows *r = &c->r[i];
            double lambda = -l->z[i];
            p->normal_impulse = l->acc[i] + lambda;
            p->total_normal_impulse += lambda;
            vA = v3_madd(vA, -mA * lambda, n);
            wA = v3_madd(wA, -lambda, r->ia_n);
            vB = v3_madd(vB, mB * lambda, n);
            wB = v3_madd(wB, lambda, r->ib_n);
        }
        A->v = vA; A->w = wA;
        B->v = vB; B->w = wB;
    }
    return 1;
}

int column_solve_pass(column_memory *m, const step_context *ctx, int use_bias, int hold_bounces)
{
    const int *start = (const int *)m->start;
    column_link *link = (column_link *)m->links;
    int left = 0;
    for (int k = 0; k < m->count; k++) {
        int begin = start[k], end = start[k + 1];
        if (!link[begin].valid) continue; /* its stiff manifolds are counted by column_prepare */
        int done = solve_column(link, begin, end, ctx, use_bias, hold_bounces);
        for (int i = begin; i < end; i++) {
            contact_block *blk = &ctx->blocks[link[i].con];
            blk->column_done = done;
            left += !done && blk->stiff;
        }
    }
    return left;
}

int column_manifold_count(const column_memory *m) { return m->count > 0 ? ((const int *)m->start)[m->count] : 0; }

int column_manifold(const column_memory *m, int i) { return ((const column_link *)m->links)[i].con; }
