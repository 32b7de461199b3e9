/* floor: core */
/* Fixed-corotated model: P against psi and dP/dF against P by central finite
 * differences; projected dP/dF symmetric PSD (GSL eigenvalues), equal to the
 * unprojected one where that is already SPD and equal to its eigenvalue clamp
 * elsewhere; the rest stiffness. */
#include "core/fcr.h"
#include "core/mat3.h"
#include "core/svd3.h"
#include "tests/common/testutil.h"

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_matrix.h>
#include <math.h>
#include <string.h>

static unsigned long long rng = 777;
static gsl_eigen_symmv_workspace *ws;

static void random_rotation(double R[9])
{
    double w[3];
    for (int k = 0; k < 3; ++k) w[k] = test_uniform(&rng, -3.2, 3.2);
    m3_rotation(w, R);
}

static void compose(const double s[3], double F[9])
{
    double R1[9], R2[9], D[9] = {s[0], 0, 0, 0, s[1], 0, 0, 0, s[2]}, T[9];
    random_rotation(R1);
    random_rotation(R2);
    m3_mul(R1, D, T);
    m3_mul_bt(T, R2, F);
}

static double norm9(const double *a, int n)
{
    double s = 0;
    for (int k = 0; k < n; ++k) s += a[k] * a[k];
    return sqrt(s);
}

/* Eigen-decomposition of a symmetric 9x9 (GSL reads the lower triangle). */
static void eig9(const double A[81], double lam[9], double vec[81])
{
    double tmp[81];
    memcpy(tmp, A, sizeof tmp);
    gsl_matrix_view m = gsl_matrix_view_array(tmp, 9, 9);
    gsl_vector_view ev = gsl_vector_view_array(lam, 9);
    gsl_matrix_view evec = gsl_matrix_view_array(vec, 9, 9);
    gsl_eigen_symmv(&m.matrix, &ev.vector, &evec.matrix, ws);
}

/* Checks one F: FD of P and dP/dF (if `fd`), projected tangent properties. */
static void check_F(const double F[9], double mu, double lambda, int fd, const char *what)
{
    double P[9], A[81], Ap[81];
    double psi = fcr_psi_P(F, mu, lambda, P);
    CHECK(rel_diff(psi, fcr_psi(F, mu, lambda), 1e-300) <= 1e-13, "%s: psi_P vs psi", what);
    fcr_dPdF(F, mu, lambda, 0, A);
    fcr_dPdF(F, mu, lambda, 1, Ap);
    double scale = mu + fabs(lambda);

    if (fd) {
        double fn = sqrt(m3_frob2(F)), h = 1e-6 * fmax(1.0, fn);
        double Pfd[9], err = 0.0;
        for (int x = 0; x < 9; ++x) {
            double Fp[9], Fm[9];
            m3_copy(Fp, F);
            m3_copy(Fm, F);
            Fp[x] += h;
            Fm[x] -= h;
            Pfd[x] = (fcr_psi(Fp, mu, lambda) - fcr_psi(Fm, mu, lambda)) / (2 * h);
            err += (Pfd[x] - P[x]) * (Pfd[x] - P[x]);
        }
        err = sqrt(err);
        double pn = norm9(P, 9);
        CHECK(err <= 1e-6 * fmax(pn, 1e-3 * scale), "%s: P vs FD(psi): err %g |P| %g", what, err, pn);

        double Afd[81];
        for (int y = 0; y < 9; ++y) {
            double Fp[9], Fm[9], Pp[9], Pm[9];
            m3_copy(Fp, F);
            m3_copy(Fm, F);
            Fp[y] += h;
            Fm[y] -= h;
            fcr_psi_P(Fp, mu, lambda, Pp);
            fcr_psi_P(Fm, mu, lambda, Pm);
            for (int x = 0; x < 9; ++x) Afd[9 * x + y] = (Pp[x] - Pm[x]) / (2 * h);
        }
        double e2 = 0.0;
        for (int k = 0; k < 81; ++k) e2 += (Afd[k] - A[k]) * (Afd[k] - A[k]);
        e2 = sqrt(e2);
        double an = norm9(A, 81);
        CHECK(e2 <= 1e-6 * an, "%s: dPdF vs FD(P): err %g |A| %g", what, e2, an);
    }

    /* Symmetry (exact by construction) and PSD of the projected tangent. */
    int sym = 1;
    for (int i = 0; i < 9; ++i)
        for (int j = 0; j < 9; ++j) sym &= Ap[9 * i + j] == Ap[9 * j + i] && A[9 * i + j] == A[9 * j + i];
    CHECK(sym, "%s: dPdF not symmetric", what);
    double lam[9], vec[81], lamp[9], vecp[81];
    eig9(Ap, lamp, vecp);
    double lmin = lamp[0], lmax = fabs(lamp[0]);
    for (int k = 1; k < 9; ++k) {
        lmin = fmin(lmin, lamp[k]);
        lmax = fmax(lmax, fabs(lamp[k]));
    }
    CHECK(lmin >= -1e-9 * lmax, "%s: projected min eig %g (max %g)", what, lmin, lmax);

    /* Projected == eigenvalue clamp of the unprojected 9x9 (valid whenever the
     * p_kl denominators are not clamped, i.e. |sigma_k + sigma_l| >= 1e-6). */
    eig9(A, lam, vec);
    double Ac[81] = {0};
    for (int e = 0; e < 9; ++e) {
        double l = lam[e] > 0 ? lam[e] : 0;
        for (int i = 0; i < 9; ++i)
            for (int j = 0; j < 9; ++j) Ac[9 * i + j] += l * vec[9 * i + e] * vec[9 * j + e];
    }
    double d = 0.0, an = 0.0;
    for (int k = 0; k < 81; ++k) {
        d += (Ac[k] - Ap[k]) * (Ac[k] - Ap[k]);
        an += A[k] * A[k];
    }
    CHECK(sqrt(d) <= 1e-10 * sqrt(an), "%s: projected vs clamp(unprojected): %g (|A| %g)", what, sqrt(d),
          sqrt(an));
}

static int fd_ok(const double F[9])
{
    /* Avoid F where P is not smooth (sigma_k + sigma_l ~ 0, R jumps) or where
     * FD steps would cross into that region. */
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    return fabs(s[1] + s[2]) > 0.05 && fabs(s[2]) > 1e-3;
}

int main(void)
{
    ws = gsl_eigen_symmv_alloc(9);
    double mu, lambda;
    fcr_lame(1e6, 0.3, &mu, &lambda);
    CHECK(rel_diff(mu, 1e6 / 2.6, 0) < 1e-15, "mu %g", mu);
    CHECK(rel_diff(lambda, 0.3e6 / (1.3 * 0.4), 0) < 1e-15, "lambda %g", lambda);

    /* Rest stiffness = ||dP/dF(I)||_F; 3.0346e6 for E = 1e6, nu = 0.3. */
    {
        double I[9], A[81], Ap[81];
        m3_identity(I);
        fcr_dPdF(I, mu, lambda, 0, A);
        fcr_dPdF(I, mu, lambda, 1, Ap);
        double k = fcr_rest_stiffness(mu, lambda);
        CHECK(rel_diff(k, norm9(A, 81), 0) < 1e-13, "rest stiffness %g vs |A(I)| %g", k, norm9(A, 81));
        CHECK(fabs(k - 3.0346e6) < 0.00005e6, "rest stiffness %g", k);
        CHECK(rel_diff(k, norm9(Ap, 81), 0) < 1e-13, "projected at I %g", norm9(Ap, 81));
        double P[9];
        CHECK(fcr_psi_P(I, mu, lambda, P) == 0.0 && norm9(P, 9) == 0.0, "P(I) = 0");
    }

    /* Several parameter sets (incl. lambda >> mu and lambda = 0). */
    double params[4][2] = {{1.0, 1.0}, {mu, lambda}, {1.0, 40.0}, {2.0, 0.0}};
    for (int pi = 0; pi < 4; ++pi) {
        double m = params[pi][0], l = params[pi][1];
        /* Near identity. */
        for (int n = 0; n < 200; ++n) {
            double F[9];
            m3_identity(F);
            for (int k = 0; k < 9; ++k) F[k] += test_uniform(&rng, -0.2, 0.2);
            check_F(F, m, l, fd_ok(F), "near identity");
        }
        /* Far from identity, both orientations. */
        for (int n = 0; n < 300; ++n) {
            double F[9];
            for (int k = 0; k < 9; ++k) F[k] = test_uniform(&rng, -1.5, 1.5);
            check_F(F, m, l, fd_ok(F), "random");
        }
        /* Inverted with controlled singular values. */
        for (int n = 0; n < 100; ++n) {
            double s[3] = {test_uniform(&rng, 0.5, 2.0), test_uniform(&rng, 0.3, 0.5),
                           -test_uniform(&rng, 0.05, 0.2)};
            double F[9];
            compose(s, F);
            check_F(F, m, l, 1, "inverted");
        }
        /* Near-degenerate: repeated singular values, a singular value near 0,
         * sigma_1 + sigma_2 near 0 (no FD there). */
        for (int n = 0; n < 100; ++n) {
            double a = test_uniform(&rng, 0.3, 2.0), b = test_uniform(&rng, 0.3, 2.0);
            double sets[6][3] = {{a, a, b}, {a, b, b}, {a, a, a}, {a, b, 1e-9},
                                 {a, b, -1e-9}, {a, b * (1 + 1e-12), -b}};
            for (int t = 0; t < 6; ++t) {
                double F[9];
                compose(sets[t], F);
                int fd = t < 3;
                if (t == 5) {
                    /* Denominator clamp: only PSD (not the clamp identity). */
                    double Ap[81], lam[9], vec[81];
                    fcr_dPdF(F, m, l, 1, Ap);
                    eig9(Ap, lam, vec);
                    double lmax = 0;
                    for (int k = 0; k < 9; ++k) lmax = fmax(lmax, fabs(lam[k]));
                    CHECK(lam[0] >= -1e-9 * lmax && isfinite(lmax), "sigma1+sigma2=0: eig %g", lam[0]);
                    continue;
                }
                check_F(F, m, l, fd, "near-degenerate");
            }
        }
    }

    /* Already-SPD tangent: projected must equal unprojected to round-off. */
    int n_spd = 0;
    for (int n = 0; n < 200; ++n) {
        double s[3] = {1.05, 0.98, 1.01}, F[9], A[81], Ap[81], lam[9], vec[81];
        if (n % 2) {
            s[0] = test_uniform(&rng, 0.95, 1.1);
            s[1] = test_uniform(&rng, 0.95, 1.1);
            s[2] = test_uniform(&rng, 0.95, 1.1);
        }
        compose(s, F);
        fcr_dPdF(F, mu, lambda, 0, A);
        fcr_dPdF(F, mu, lambda, 1, Ap);
        eig9(A, lam, vec);
        double lmin = lam[0];
        for (int k = 1; k < 9; ++k) lmin = fmin(lmin, lam[k]);
        if (lmin <= 0) continue; /* stretch enough to make a mode indefinite */
        ++n_spd;
        double d = 0, an = 0;
        for (int k = 0; k < 81; ++k) {
            d = fmax(d, fabs(A[k] - Ap[k]));
            an = fmax(an, fabs(A[k]));
        }
        CHECK(d <= 1e-14 * an, "SPD case: projected differs from unprojected by %g (max %g)", d, an);
    }
    CHECK(n_spd >= 100, "only %d SPD cases exercised", n_spd);
    /* The fixed example must indeed be SPD. */
    {
        double s[3] = {1.05, 0.98, 1.01}, F[9], A[81], lam[9], vec[81];
        compose(s, F);
        fcr_dPdF(F, mu, lambda, 0, A);
        eig9(A, lam, vec);
        double lmin = lam[0];
        for (int k = 1; k < 9; ++k) lmin = fmin(lmin, lam[k]);
        CHECK(lmin > 0, "R diag(1.05,0.98,1.01) tangent SPD: min eig %g", lmin);
    }

    /* Strongly compressed / stretched: projection must actually clamp something
     * and stay PSD. */
    {
        double s[3] = {0.3, 0.25, 0.2}, F[9], A[81], lam[9], vec[81];
        compose(s, F);
        fcr_dPdF(F, 1.0, 1.0, 0, A);
        eig9(A, lam, vec);
        double lmin = lam[0];
        for (int k = 1; k < 9; ++k) lmin = fmin(lmin, lam[k]);
        CHECK(lmin < 0, "compressed F: unprojected tangent should be indefinite (min eig %g)", lmin);
        check_F(F, 1.0, 1.0, 1, "compressed");
    }

    gsl_eigen_symmv_free(ws);
    return test_summary("test_fcr");
}
