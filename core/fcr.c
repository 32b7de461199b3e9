/* Fixed-corotated elasticity: energy, stress and (projected) stress
 * derivative. See fcr.h; formulas from HOT reference §2 (Stomakhin et al.
 * 2012 model) and the singular-value-space Hessian of Teran et al. 2005,
 * "Robust quasistatic finite elements and flesh simulation" (HOT reference
 * §1.7 for the definiteness fix). */
#include "core/fcr.h"

#include "core/mat3.h"
#include "core/svd3.h"

#include <math.h>

void fcr_lame(double E, double nu, double *mu, double *lambda)
{
    *mu = E / (2.0 * (1.0 + nu));
    *lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
}

double fcr_psi(const double F[9], double mu, double lambda)
{
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    double J = s[0] * s[1] * s[2];
    double d0 = s[0] - 1.0, d1 = s[1] - 1.0, d2 = s[2] - 1.0;
    /* |F - R|^2 = sum (sigma_k - 1)^2 for R = U V^T */
    return mu * (d0 * d0 + d1 * d1 + d2 * d2) + 0.5 * lambda * (J - 1.0) * (J - 1.0);
}

double fcr_psi_P(const double F[9], double mu, double lambda, double P[9])
{
    double U[9], s[3], V[9], R[9], C[9];
    svd3(F, U, s, V);
    double J = s[0] * s[1] * s[2];
    m3_mul_bt(U, V, R);
    m3_cofactor(F, C);
    double lj = lambda * (J - 1.0);
    for (int k = 0; k < 9; ++k) P[k] = 2.0 * mu * (F[k] - R[k]) + lj * C[k];
    double d0 = s[0] - 1.0, d1 = s[1] - 1.0, d2 = s[2] - 1.0;
    return mu * (d0 * d0 + d1 * d1 + d2 * d2) + 0.5 * lambda * (J - 1.0) * (J - 1.0);
}

double fcr_rest_stiffness(double mu, double lambda)
{
    double a = 2.0 * mu + lambda;
    return sqrt(3.0 * a * a + 6.0 * lambda * lambda + 12.0 * mu * mu);
}

/* Positive definite input (Sylvester: leading principal minors > 0) is
 * returned unchanged; otherwise cyclic Jacobi eigendecomposition. */
void fcr_sym3_clamp_psd(double A[3][3])
{
    double m2 = A[0][0] * A[1][1] - A[0][1] * A[0][1];
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[1][2]) -
                 A[0][1] * (A[0][1] * A[2][2] - A[1][2] * A[0][2]) +
                 A[0][2] * (A[0][1] * A[1][2] - A[1][1] * A[0][2]);
    if (A[0][0] > 0.0 && m2 > 0.0 && det > 0.0) return;

    double a[3][3], q[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a[i][j] = A[i][j];
    static const int P[3] = {0, 0, 1}, Q[3] = {1, 2, 2}, Rr[3] = {2, 1, 0};
    for (int sweep = 0; sweep < 32; ++sweep) {
        double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        double dia = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (!(off > 1e-34 * (dia + off))) break;
        for (int e = 0; e < 3; ++e) {
            int p = P[e], r = Rr[e], qq = Q[e];
            double apq = a[p][qq];
            if (apq == 0.0) continue;
            /* A' = J^T A J with J_pp = J_qq = c, J_pq = s, J_qp = -s, a'_pq = 0:
             * t = tan = sgn(theta)/(|theta| + sqrt(theta^2 + 1)),
             * theta = (a_qq - a_pp)/(2 a_pq). */
            double theta = (a[qq][qq] - a[p][p]) / (2.0 * apq);
            double t = copysign(1.0, theta) / (fabs(theta) + sqrt(theta * theta + 1.0));
            double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
            a[p][p] -= t * apq;
            a[qq][qq] += t * apq;
            a[p][qq] = a[qq][p] = 0.0;
            double arp = a[r][p], arq = a[r][qq];
            a[r][p] = a[p][r] = c * arp - s * arq;
            a[r][qq] = a[qq][r] = s * arp + c * arq;
            for (int k = 0; k < 3; ++k) {
                double x = q[k][p], y = q[k][qq];
                q[k][p] = c * x - s * y;
                q[k][qq] = s * x + c * y;
            }
        }
    }
    double lam[3];
    for (int k = 0; k < 3; ++k) lam[k] = a[k][k] > 0.0 ? a[k][k] : 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            double v = q[i][0] * lam[0] * q[j][0] + q[i][1] * lam[1] * q[j][1] + q[i][2] * lam[2] * q[j][2];
            A[i][j] = A[j][i] = v;
        }
}

/* dP/dF in singular-value space (Teran et al. 2005, §5; HOT reference §2):
 * with F = U diag(sigma) V^T, dF^ = U^T dF V and dP^ = U^T dP V,
 *   dP^_kk = sum_l Ahat_kl dF^_ll,                 Ahat_kl = d2 psihat / dsigma_k dsigma_l
 *   [dP^_kl, dP^_lk] = B_kl [dF^_kl, dF^_lk],     B_kl = 1/2 [[m+p, m-p], [m-p, m+p]]
 * where m = (psihat_k - psihat_l)/(sigma_k - sigma_l) and
 * p = (psihat_k + psihat_l)/(sigma_k + sigma_l). B_kl has eigenvalue m on the
 * symmetric ("flip") mode (e_k e_l^T + e_l e_k^T)/sqrt2 and p on the
 * antisymmetric ("twist") mode (e_k e_l^T - e_l e_k^T)/sqrt2, so clamping the
 * 2x2 block at eigenvalue 0 is clamping m and p. With the orthonormal basis
 * matrices M^kl = u_k v_l^T (vectorised row-major: M^kl_ij = U_ik V_jl):
 *   A = sum_kl Ahat_kl M^kk M^ll^T
 *     + sum_(k<l) [ m/2 (M^kl + M^lk)(M^kl + M^lk)^T + p/2 (M^kl - M^lk)(M^kl - M^lk)^T ].
 * Since the 9x9 map vec(dF) -> vec(dF^) is orthogonal, clamping the blocks is
 * the same as clamping the eigenvalues of A itself. */
void fcr_dPdF(const double F[9], double mu, double lambda, int projected, double A[81])
{
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    double J = s[0] * s[1] * s[2];
    double Sk[3] = {s[1] * s[2], s[0] * s[2], s[0] * s[1]}; /* J / sigma_k */
    double lj = lambda * (J - 1.0);
    double ph[3];
    for (int k = 0; k < 3; ++k) ph[k] = 2.0 * mu * (s[k] - 1.0) + lj * Sk[k];

    /* HOT reference §2: psihat_kk = 2mu + lambda S_k^2,
     * psihat_kl = lambda (J-1) sigma_m + lambda S_k S_l. */
    double Ah[3][3];
    for (int k = 0; k < 3; ++k) Ah[k][k] = 2.0 * mu + lambda * Sk[k] * Sk[k];
    Ah[0][1] = Ah[1][0] = lj * s[2] + lambda * Sk[0] * Sk[1];
    Ah[0][2] = Ah[2][0] = lj * s[1] + lambda * Sk[0] * Sk[2];
    Ah[1][2] = Ah[2][1] = lj * s[0] + lambda * Sk[1] * Sk[2];

    /* Pairs (k,l) with third index m. m_kl analytically (no division):
     * (psihat_k - psihat_l)/(sigma_k - sigma_l) = 2mu - lambda (J-1) sigma_m.
     * p_kl's denominator is clamped to magnitude >= 1e-6 keeping its sign. */
    static const int PK[3] = {0, 1, 2}, PL[3] = {1, 2, 0}, PM[3] = {2, 0, 1};
    double mc[3], pc[3];
    for (int e = 0; e < 3; ++e) {
        int k = PK[e], l = PL[e], m = PM[e];
        mc[e] = 2.0 * mu - lj * s[m];
        double den = s[k] + s[l];
        if (fabs(den) < 1e-6) den = copysign(1e-6, den);
        pc[e] = (ph[k] + ph[l]) / den;
    }

    if (projected) {
        fcr_sym3_clamp_psd(Ah);
        for (int e = 0; e < 3; ++e) {
            if (mc[e] < 0.0) mc[e] = 0.0;
            if (pc[e] < 0.0) pc[e] = 0.0;
        }
    }

    /* Rank-9 sum: A = sum_e x_e y_e^T, upper triangle, then mirrored. */
    double X[9][9], Y[9][9];
    double Mkk[3][9];
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) Mkk[k][3 * i + j] = U[3 * i + k] * V[3 * j + k];
    for (int k = 0; k < 3; ++k)
        for (int x = 0; x < 9; ++x) {
            X[k][x] = Mkk[k][x];
            Y[k][x] = Ah[k][0] * Mkk[0][x] + Ah[k][1] * Mkk[1][x] + Ah[k][2] * Mkk[2][x];
        }
    for (int e = 0; e < 3; ++e) {
        int k = PK[e], l = PL[e];
        double hm = 0.5 * mc[e], hp = 0.5 * pc[e];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double kl = U[3 * i + k] * V[3 * j + l], lk = U[3 * i + l] * V[3 * j + k];
                double sp = kl + lk, sm = kl - lk;
                X[3 + 2 * e][3 * i + j] = hm * sp;
                Y[3 + 2 * e][3 * i + j] = sp;
                X[4 + 2 * e][3 * i + j] = hp * sm;
                Y[4 + 2 * e][3 * i + j] = sm;
            }
    }
    for (int i = 0; i < 9; ++i)
        for (int j = i; j < 9; ++j) {
            double v = 0.0;
            for (int e = 0; e < 9; ++e) v += X[e][i] * Y[e][j];
            A[9 * i + j] = v;
        }
    for (int i = 1; i < 9; ++i)
        for (int j = 0; j < i; ++j) A[9 * i + j] = A[9 * j + i];
}
