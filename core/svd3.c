/* 3x3 SVD by one-sided (Hestenes) Jacobi, rotation variant (see svd3.h).
 *
 * The columns of C = F V are rotated pairwise until they are mutually
 * orthogonal; V accumulates the plane rotations, so det V = +1 throughout.
 * Then the column norms are the singular values and the normalised columns
 * form U. One-sided Jacobi gives singular values to high relative accuracy
 * (each rotation is computed from the columns themselves, never from F^T F's
 * rounded entries; Demmel & Veselic 1992). The sign convention of HOT's
 * ImplicitQRSVD (HOT reference §2: sigma sorted by decreasing magnitude, only
 * sigma[2] negative, U and V proper rotations) comes from building
 * u2 = u0 x u1 and giving sigma[2] the sign of u2 . c2.
 *
 * Robustness:
 *  - inputs with max |F_ij| outside [2^-128, 2^128] are scaled by an exact
 *    power of two first, so squared column norms neither overflow nor lose
 *    precision in the subnormal range;
 *  - a column whose norm vanishes (rank deficiency) gets a direction
 *    orthogonal to the previous ones, so U stays a rotation;
 *  - the sweep count is capped, so the routine terminates for any input. */
#include "core/svd3.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Rotates columns ci, cj (and vi, vj of V) so that ci . cj = 0.
 * Returns 1 if a rotation was applied. */
static inline int jacobi_pair(double ci[3], double cj[3], double vi[3], double vj[3])
{
    double a = ci[0] * ci[0] + ci[1] * ci[1] + ci[2] * ci[2];
    double b = cj[0] * cj[0] + cj[1] * cj[1] + cj[2] * cj[2];
    double g = ci[0] * cj[0] + ci[1] * cj[1] + ci[2] * cj[2];
    if (!(g * g > (SVD3_TOL * SVD3_TOL) * (a * b))) return 0; /* also a or b == 0 */
    /* ci' = c ci - s cj, cj' = s ci + c cj; ci'.cj' = cs(a-b) + (c^2-s^2) g = 0
     * <=> t^2 + 2 zeta t - 1 = 0 with t = s/c, zeta = (b-a)/(2g). The root of
     * smaller magnitude (angle <= pi/4) is t = 2g sgn(b-a) / (|b-a| + r) with
     * r = sqrt((b-a)^2 + 4g^2), and cos(2 theta) = |b-a|/r gives
     * c^2 = (1 + cos 2theta)/2 = (r + |b-a|)/(2r) in [1/2, 1] without
     * cancellation. This keeps the dependent chain at sqrt, div, sqrt. */
    double d = b - a, ad = fabs(d);
    double r = sqrt(d * d + 4.0 * g * g);
    double t = copysign(1.0, d) * (2.0 * g) / (ad + r);
    double c = sqrt((r + ad) / (2.0 * r)), s = t * c;
    for (int k = 0; k < 3; ++k) {
        double x = ci[k], y = cj[k];
        ci[k] = c * x - s * y;
        cj[k] = s * x + c * y;
        x = vi[k];
        y = vj[k];
        vi[k] = c * x - s * y;
        vj[k] = s * x + c * y;
    }
    return 1;
}

/* Swaps columns i and j of C and V and negates the new j-th ones, which keeps
 * det V = +1 and C = F V. */
static inline void swap_cols(double c[3][3], double v[3][3], double n2[3], int i, int j)
{
    for (int k = 0; k < 3; ++k) {
        double t = c[i][k];
        c[i][k] = c[j][k];
        c[j][k] = -t;
        t = v[i][k];
        v[i][k] = v[j][k];
        v[j][k] = -t;
    }
    double t = n2[i];
    n2[i] = n2[j];
    n2[j] = t;
}

void svd3(const double F[9], double U[9], double sigma[3], double V[9])
{
    double m = 0.0;
    for (int k = 0; k < 9; ++k) m = fmax(m, fabs(F[k]));
    if (!(m > 0.0) || !isfinite(m)) {
        /* Zero matrix, or an infinite entry (no meaningful SVD; NaN entries
         * are ignored by fmax and propagate through the sweeps instead). */
        memset(U, 0, 9 * sizeof(double));
        memset(V, 0, 9 * sizeof(double));
        U[0] = U[4] = U[8] = V[0] = V[4] = V[8] = 1.0;
        sigma[0] = sigma[1] = sigma[2] = m; /* 0, or inf passed on */
        return;
    }
    /* Power-of-two scaling 2^-e, split in two factors so that neither
     * overflows for subnormal input (e down to -1073). */
    int e = 0;
    double sc1 = 1.0, sc2 = 1.0;
    if (m < 0x1p-128 || m > 0x1p128) {
        frexp(m, &e);
        sc1 = ldexp(1.0, -(e / 2));
        sc2 = ldexp(1.0, -(e - e / 2));
    }

    /* c[k] = column k of F (scaled), v[k] = column k of V. */
    double c[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) c[k][r] = F[3 * r + k] * sc1 * sc2;

    for (int sweep = 0; sweep < SVD3_MAX_SWEEPS; ++sweep) {
        int rot = jacobi_pair(c[0], c[1], v[0], v[1]);
        rot |= jacobi_pair(c[0], c[2], v[0], v[2]);
        rot |= jacobi_pair(c[1], c[2], v[1], v[2]);
        if (!rot) break;
    }

    double n2[3];
    for (int k = 0; k < 3; ++k) n2[k] = c[k][0] * c[k][0] + c[k][1] * c[k][1] + c[k][2] * c[k][2];
    /* Sort by decreasing norm (three-element network). */
    if (n2[0] < n2[1]) swap_cols(c, v, n2, 0, 1);
    if (n2[1] < n2[2]) swap_cols(c, v, n2, 1, 2);
    if (n2[0] < n2[1]) swap_cols(c, v, n2, 0, 1);

    double u[3][3];
    /* u0: the largest column has norm >= max|F_ij| / sqrt(3) > 0 after scaling
     * (rotations keep the Frobenius norm). */
    double s0 = sqrt(n2[0]);
    for (int k = 0; k < 3; ++k) u[0][k] = c[0][k] / s0;

    /* u1: column 1 made orthogonal to u0 (a refinement; Jacobi already made it
     * so to working precision), or any direction orthogonal to u0. */
    double d = u[0][0] * c[1][0] + u[0][1] * c[1][1] + u[0][2] * c[1][2];
    double w[3] = {c[1][0] - d * u[0][0], c[1][1] - d * u[0][1], c[1][2] - d * u[0][2]};
    double wn2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (!(wn2 > SVD3_TINY2)) {
        /* Rank <= 1: take the axis least aligned with u0 and orthogonalise. */
        int ax = 0;
        if (fabs(u[0][1]) < fabs(u[0][ax])) ax = 1;
        if (fabs(u[0][2]) < fabs(u[0][ax])) ax = 2;
        for (int k = 0; k < 3; ++k) w[k] = (k == ax ? 1.0 : 0.0) - u[0][ax] * u[0][k];
        wn2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    }
    double wn = sqrt(wn2);
    for (int k = 0; k < 3; ++k) u[1][k] = w[k] / wn;

    /* u2 = u0 x u1 makes det U = +1; sigma[2] takes the sign of u2 . c2,
     * which is the sign of det F. */
    u[2][0] = u[0][1] * u[1][2] - u[0][2] * u[1][1];
    u[2][1] = u[0][2] * u[1][0] - u[0][0] * u[1][2];
    u[2][2] = u[0][0] * u[1][1] - u[0][1] * u[1][0];
    double proj = u[2][0] * c[2][0] + u[2][1] * c[2][1] + u[2][2] * c[2][2];

    sigma[0] = s0;
    sigma[1] = sqrt(n2[1]);
    sigma[2] = copysign(sqrt(n2[2]), proj);
    if (e != 0)
        for (int k = 0; k < 3; ++k) sigma[k] = ldexp(sigma[k], e);

    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            U[3 * r + k] = u[k][r];
            V[3 * r + k] = v[k][r];
        }
}
