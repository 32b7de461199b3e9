/* floor: core */
/* svd3: reconstruction, orthogonality, det +1, sort/sign convention, on random,
 * inverted, rank-deficient, repeated, near-degenerate and extreme-scale inputs. */
#include "core/mat3.h"
#include "core/svd3.h"
#include "tests/common/testutil.h"

#include <math.h>
#include <stdio.h>

static unsigned long long rng = 12345;

static void random_rotation(double R[9])
{
    double w[3];
    for (int k = 0; k < 3; ++k) w[k] = test_uniform(&rng, -3.2, 3.2);
    m3_rotation(w, R);
}

/* F = R1 diag(s) R2^T */
static void compose(const double s[3], const double R1[9], const double R2[9], double F[9])
{
    double D[9] = {s[0], 0, 0, 0, s[1], 0, 0, 0, s[2]}, T[9];
    m3_mul(R1, D, T);
    m3_mul_bt(T, R2, F);
}

static double orth_err(const double Q[9])
{
    double QtQ[9], e = 0.0;
    m3_mul_at(Q, Q, QtQ);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) e = fmax(e, fabs(QtQ[3 * r + c] - (r == c ? 1.0 : 0.0)));
    return e;
}

/* Checks every invariant; `expect` (sorted, signed) may be NULL. Returns 1 if ok. */
static int check_svd(const double F[9], const double *expect, double sv_tol, const char *what)
{
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    int fails0 = g_test_failures;
    double fn = sqrt(m3_frob2(F));
    double D[9] = {s[0], 0, 0, 0, s[1], 0, 0, 0, s[2]}, T[9], G[9];
    m3_mul(U, D, T);
    m3_mul_bt(T, V, G);
    double err = 0.0;
    for (int k = 0; k < 9; ++k) {
        err += (G[k] - F[k]) * (G[k] - F[k]);
        CHECK(isfinite(U[k]) && isfinite(V[k]), "%s: non-finite U/V", what);
    }
    err = sqrt(err);
    CHECK(err <= 1e-12 * fn, "%s: reconstruction %g (|F| %g)", what, err, fn);
    CHECK(orth_err(U) <= 1e-13, "%s: U not orthogonal (%g)", what, orth_err(U));
    CHECK(orth_err(V) <= 1e-13, "%s: V not orthogonal (%g)", what, orth_err(V));
    CHECK(fabs(m3_det(U) - 1.0) <= 1e-13, "%s: det U = %.17g", what, m3_det(U));
    CHECK(fabs(m3_det(V) - 1.0) <= 1e-13, "%s: det V = %.17g", what, m3_det(V));
    CHECK(s[0] >= s[1] && s[1] >= fabs(s[2]) && s[1] >= 0.0, "%s: order %g %g %g", what, s[0], s[1],
          s[2]);
    CHECK(isfinite(s[0]) && isfinite(s[1]) && isfinite(s[2]), "%s: non-finite sigma", what);
    if (expect)
        for (int k = 0; k < 3; ++k)
            CHECK(fabs(s[k] - expect[k]) <= sv_tol * fabs(expect[k]) + 1e-15 * fn,
                  "%s: sigma[%d] = %.17g, expected %.17g", what, k, s[k], expect[k]);
    return g_test_failures == fails0;
}

/* Sorted/signed singular values of R1 diag(s) R2^T. */
static void expected_sv(const double s[3], double e[3])
{
    double a[3] = {fabs(s[0]), fabs(s[1]), fabs(s[2])};
    double sign = (s[0] < 0) ^ (s[1] < 0) ^ (s[2] < 0) ? -1.0 : 1.0;
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            if (a[j] > a[i]) {
                double t = a[i];
                a[i] = a[j];
                a[j] = t;
            }
    e[0] = a[0];
    e[1] = a[1];
    e[2] = sign * a[2];
}

static void check_known(const double s[3], double tol, const char *what)
{
    double R1[9], R2[9], F[9], e[3];
    random_rotation(R1);
    random_rotation(R2);
    compose(s, R1, R2, F);
    expected_sv(s, e);
    check_svd(F, e, tol, what);
}

int main(void)
{
    /* Identity: exact. */
    {
        double I[9], U[9], s[3], V[9];
        m3_identity(I);
        svd3(I, U, s, V);
        CHECK(s[0] == 1.0 && s[1] == 1.0 && s[2] == 1.0, "identity sigma %g %g %g", s[0], s[1], s[2]);
        int eq = 1;
        for (int k = 0; k < 9; ++k) eq &= U[k] == I[k] && V[k] == I[k];
        CHECK(eq, "identity: U = V = I");
    }
    /* Zero matrix. */
    {
        double Z[9] = {0}, U[9], s[3], V[9];
        svd3(Z, U, s, V);
        CHECK(s[0] == 0.0 && s[1] == 0.0 && s[2] == 0.0, "zero sigma");
        CHECK(fabs(m3_det(U) - 1) < 1e-15 && fabs(m3_det(V) - 1) < 1e-15, "zero: rotations");
    }
    /* Diagonal and permuted/negated diagonal inputs. */
    {
        double F[9] = {-2, 0, 0, 0, 3, 0, 0, 0, 1};
        double e[3] = {3, 2, -1};
        check_svd(F, e, 1e-15, "diag(-2,3,1)");
        double G[9] = {0, 0, 5, 0, -1, 0, 2, 0, 0};
        double eg[3] = {5, 2, 1}; /* det = 10 */
        check_svd(G, eg, 1e-15, "permuted");
        double H[9] = {-1, 0, 0, 0, -1, 0, 0, 0, -1};
        double eh[3] = {1, 1, -1};
        check_svd(H, eh, 1e-15, "-I");
    }

    /* Random dense F (both orientations), including values sign checks. */
    for (int n = 0; n < 5000; ++n) {
        double F[9];
        for (int k = 0; k < 9; ++k) F[k] = test_uniform(&rng, -2.0, 2.0);
        double U[9], s[3], V[9];
        check_svd(F, NULL, 0, "random");
        svd3(F, U, s, V);
        double det = m3_det(F), prod = s[0] * s[1] * s[2];
        CHECK(fabs(det - prod) <= 1e-12 * fmax(1.0, fabs(det)) * 10 * m3_frob2(F),
              "random: prod sigma %g vs det %g", prod, det);
        CHECK(det * s[2] >= 0.0 || fabs(det) < 1e-12, "random: sign of sigma2 %g vs det %g", s[2], det);
    }
    /* Known singular values: random, inverted, well separated -> high relative accuracy. */
    for (int n = 0; n < 2000; ++n) {
        double s[3];
        for (int k = 0; k < 3; ++k) s[k] = test_uniform(&rng, 0.05, 3.0);
        if (n % 2) s[n % 3] = -s[n % 3];
        check_known(s, 1e-13, "known");
    }
    /* Near identity. */
    for (int n = 0; n < 2000; ++n) {
        double F[9];
        m3_identity(F);
        double eps = pow(10.0, -test_uniform(&rng, 2, 14));
        for (int k = 0; k < 9; ++k) F[k] += eps * test_uniform(&rng, -1, 1);
        check_svd(F, NULL, 0, "near identity");
    }
    /* Repeated singular values. */
    for (int n = 0; n < 1000; ++n) {
        double a = test_uniform(&rng, 0.1, 3.0), b = test_uniform(&rng, 0.1, 3.0);
        double sets[6][3] = {{a, a, b}, {a, b, b}, {a, a, a}, {a, a, -b}, {a, -a, a}, {2, 2, 0.5}};
        for (int t = 0; t < 6; ++t) check_known(sets[t], 1e-13, "repeated");
    }
    /* Near-degenerate: differences of 1e-10 and 1e-15. */
    for (int n = 0; n < 1000; ++n) {
        double a = test_uniform(&rng, 0.5, 2.0);
        double sets[4][3] = {{a, a + 1e-10, a - 1e-10},
                             {a, a * (1 + 1e-15), 0.3},
                             {a, 0.3, -0.3 * (1 + 1e-10)},
                             {a, a * (1 - 1e-12), -a}};
        for (int t = 0; t < 4; ++t) check_known(sets[t], 1e-13, "near-degenerate");
    }
    /* Rank deficient: rank 2, 1, 0 and tiny singular values (relative accuracy). */
    for (int n = 0; n < 1000; ++n) {
        double a = test_uniform(&rng, 0.1, 3.0), b = test_uniform(&rng, 0.1, 3.0);
        double sets[6][3] = {{a, b, 0}, {a, 0, 0}, {0, 0, 0}, {a, b, 1e-12 * a}, {a, 1e-9, -1e-14},
                             {a, a, 1e-30}};
        for (int t = 0; t < 6; ++t) check_known(sets[t], 1e-12, "rank deficient");
        /* rank-1 outer product u v^T */
        double u[3], v[3], F[9];
        for (int k = 0; k < 3; ++k) {
            u[k] = test_uniform(&rng, -1, 1);
            v[k] = test_uniform(&rng, -1, 1);
        }
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) F[3 * r + c] = u[r] * v[c];
        check_svd(F, NULL, 0, "outer product");
        /* duplicated columns/rows (rank 2 with exact structure) */
        for (int k = 0; k < 9; ++k) F[k] = test_uniform(&rng, -1, 1);
        F[2] = F[0];
        F[5] = F[3];
        F[8] = F[6];
        check_svd(F, NULL, 0, "duplicate column");
    }
    /* Extreme scales. */
    {
        double scales[] = {1e-300, 1e-200, 1e-100, 1e-20, 1e20, 1e100, 1e200, 1e300};
        for (int si = 0; si < 8; ++si)
            for (int n = 0; n < 200; ++n) {
                double s[3];
                for (int k = 0; k < 3; ++k) s[k] = scales[si] * test_uniform(&rng, 0.1, 1.0);
                if (n % 2) s[2] = -s[2];
                check_known(s, 1e-13, "scaled");
                double F[9];
                for (int k = 0; k < 9; ++k) F[k] = scales[si] * test_uniform(&rng, -1, 1);
                check_svd(F, NULL, 0, "scaled random");
            }
        double sub[9] = {4e-320, 0, 0, 0, 1e-321, 0, 0, 0, -3e-322};
        double U[9], s[3], V[9];
        svd3(sub, U, s, V);
        CHECK(s[0] > 0 && s[0] >= s[1] && s[1] >= fabs(s[2]) && s[2] < 0, "subnormal %g %g %g", s[0],
              s[1], s[2]);
    }
    return test_summary("test_svd");
}
