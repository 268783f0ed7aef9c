/* block_ldl.h - the small dense LDL^T (n <= 4, no square roots) that the
 * block solves of contact normal rows share: one manifold's
 * (contact_solver.c) and a column of manifolds' (column_solve.c). */
#ifndef CAROM_BLOCK_LDL_H
#define CAROM_BLOCK_LDL_H

#if defined(__GNUC__)
#define BLOCK_INLINE static inline __attribute__((always_inline))
#else
#define BLOCK_INLINE static inline
#endif

/* The compliance added to every row of a block, times the row's own K_ii:
 * keeps a face held rigidly (K singular for 4 coplanar points) positive
 * definite (contact_solver.c, the block solve's comment). */
#define BLOCK_EPS 1e-9

/* LDL^T factor of an n x n positive definite A: L (unit diagonal) below the
 * diagonal, 1 / D_ii on it; 0 when a pivot is not positive. */
BLOCK_INLINE int block_factor_n(int n, double A[4][4], double L[4][4])
{
    double d[4], u[4][4]; /* u[i][k] = L_ik D_kk */
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < i; j++) {
            double sum = A[i][j];
            for (int k = 0; k < j; k++) sum -= u[i][k] * L[j][k];
            u[i][j] = sum;
            L[i][j] = sum * L[j][j];
        }
        double sum = A[i][i];
        for (int k = 0; k < i; k++) sum -= u[i][k] * L[i][k];
        if (!(sum > 0.0)) return 0;
        d[i] = sum;
        L[i][i] = 1.0 / d[i];
    }
    return 1;
}

/* block_factor_n for 4 rows (faces, the common case) spelled out, the same
 * arithmetic in the same order: GCC at -O2 left the loops rolled (the
 * 10-box stack at default spent 2.5M of its 135.6M instructions in them,
 * callgrind). */
BLOCK_INLINE int block_factor4(double A[4][4], double L[4][4])
{
    double d0 = A[0][0];
    if (!(d0 > 0.0)) return 0;
    double l00 = L[0][0] = 1.0 / d0;
    double u10 = A[1][0];
    double l10 = L[1][0] = u10 * l00;
    double d1 = A[1][1] - u10 * l10;
    if (!(d1 > 0.0)) return 0;
    double l11 = L[1][1] = 1.0 / d1;
    double u20 = A[2][0];
    double l20 = L[2][0] = u20 * l00;
    double u21 = A[2][1] - u20 * l10;
    double l21 = L[2][1] = u21 * l11;
    double d2 = A[2][2] - u20 * l20 - u21 * l21;
    if (!(d2 > 0.0)) return 0;
    double l22 = L[2][2] = 1.0 / d2;
    double u30 = A[3][0];
    double l30 = L[3][0] = u30 * l00;
    double u31 = A[3][1] - u30 * l10;
    double l31 = L[3][1] = u31 * l11;
    double u32 = A[3][2] - u30 * l20 - u31 * l21;
    double l32 = L[3][2] = u32 * l22;
    double d3 = A[3][3] - u30 * l30 - u31 * l31 - u32 * l32;
    if (!(d3 > 0.0)) return 0;
    L[3][3] = 1.0 / d3;
    return 1;
}

/* x = A^-1 r from block_factor's L. */
BLOCK_INLINE void block_apply_n(int n, double L[4][4], const double r[4], double x[4])
{
    double y[4];
    for (int i = 0; i < n; i++) {
        double sum = r[i];
        for (int k = 0; k < i; k++) sum -= L[i][k] * y[k];
        y[i] = sum;
    }
    for (int i = n - 1; i >= 0; i--) {
        double sum = y[i] * L[i][i];
        for (int k = i + 1; k < n; k++) sum -= L[k][i] * x[k];
        x[i] = sum;
    }
}

/* block_apply_n for 4 rows (faces, the common case) spelled out: GCC at
 * -O2 left the loops rolled. */
BLOCK_INLINE void block_apply4(double L[4][4], const double r[4], double x[4])
{
    double y0 = r[0];
    double y1 = r[1] - L[1][0] * y0;
    double y2 = r[2] - L[2][0] * y0 - L[2][1] * y1;
    double y3 = r[3] - L[3][0] * y0 - L[3][1] * y1 - L[3][2] * y2;
    x[3] = y3 * L[3][3];
    x[2] = y2 * L[2][2] - L[3][2] * x[3];
    x[1] = y1 * L[1][1] - L[2][1] * x[2] - L[3][1] * x[3];
    x[0] = y0 * L[0][0] - L[1][0] * x[1] - L[2][0] * x[2] - L[3][0] * x[3];
}

#endif
