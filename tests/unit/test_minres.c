/* floor: solvers */
/* MINRES (solvers/krylov/minres.c) on small dense symmetric INDEFINITE systems
 * A = Q diag(lambda) Q^T (eigenvalues of both signs, Q a random orthogonal
 * matrix), against a dense Gaussian-elimination solve:
 *  - unpreconditioned and with an SPD diagonal preconditioner, the solution
 *    agrees with the dense one to 1e-9 and needs at most N + 2 iterations;
 *  - the reported residual |eta| is the true ||b - A x||_{M^-1} and never
 *    grows with the iteration count;
 *  - with a projection (a "Dirichlet" node) it solves the reduced system;
 *  - the cap (capped), a zero right-hand side (x = 0, no iteration), and an
 *    indefinite preconditioner (MPM_ENUMERIC);
 *  - PCG on the same system stops at the first non-positive curvature with
 *    its indefiniteness flag set (why the semi-implicit method needs MINRES). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/minres.h"
#include "solvers/krylov/pcg.h"
#include "tests/common/testutil.h"

#define NODES 5
#define N (3 * NODES)

typedef struct {
    double a[N * N];
} Dense;

static void dense_apply(const void *ctx, const double *x, double *y)
{
    const Dense *A = ctx;
    for (int i = 0; i < N; ++i) {
        double s = 0.0;
        for (int j = 0; j < N; ++j) s += A->a[i * N + j] * x[j];
        y[i] = s;
    }
}

/* A = Q diag(lambda) Q^T with Q from Gram-Schmidt on random vectors */
static void build(Dense *A, const double *lambda, unsigned long long seed)
{
    double Q[N * N];
    for (int k = 0; k < N; ++k) {
        double *q = Q + k * N;
        for (int i = 0; i < N; ++i) q[i] = test_uniform(&seed, -1, 1);
        for (int j = 0; j < k; ++j) {
            double d = vec_dot(N, q, Q + j * N);
            vec_axpy(N, -d, Q + j * N, q);
        }
        vec_scale(N, 1.0 / vec_norm(N, q), q);
    }
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
            double s = 0.0;
            for (int k = 0; k < N; ++k) s += Q[k * N + i] * lambda[k] * Q[k * N + j];
            A->a[i * N + j] = s;
        }
}

/* Gaussian elimination with partial pivoting on the first m unknowns listed
 * in idx (the free ones); x gets zeros elsewhere. */
static void dense_solve(const Dense *A, const double *b, const int *idx, int m, double *x)
{
    double M[N * (N + 1)];
    for (int r = 0; r < m; ++r) {
        for (int c = 0; c < m; ++c) M[r * (m + 1) + c] = A->a[idx[r] * N + idx[c]];
        M[r * (m + 1) + m] = b[idx[r]];
    }
    for (int c = 0; c < m; ++c) {
        int piv = c;
        for (int r = c + 1; r < m; ++r)
            if (fabs(M[r * (m + 1) + c]) > fabs(M[piv * (m + 1) + c])) piv = r;
        for (int k = 0; k <= m; ++k) {
            double t = M[c * (m + 1) + k];
            M[c * (m + 1) + k] = M[piv * (m + 1) + k];
            M[piv * (m + 1) + k] = t;
        }
        for (int r = c + 1; r < m; ++r) {
            double f = M[r * (m + 1) + c] / M[c * (m + 1) + c];
            for (int k = c; k <= m; ++k) M[r * (m + 1) + k] -= f * M[c * (m + 1) + k];
        }
    }
    memset(x, 0, sizeof(double) * N);
    for (int r = m - 1; r >= 0; --r) {
        double s = M[r * (m + 1) + m];
        for (int k = r + 1; k < m; ++k) s -= M[r * (m + 1) + k] * x[idx[k]];
        x[idx[r]] = s / M[r * (m + 1) + r];
    }
}

static double rel_err(const double *x, const double *y)
{
    double d[N];
    for (int i = 0; i < N; ++i) d[i] = x[i] - y[i];
    return vec_norm(N, d) / vec_norm(N, y);
}

static void zero_node0(const void *ctx, double *v)
{
    (void)ctx;
    v[0] = v[1] = v[2] = 0.0;
}

/* scalar Jacobi set up from a given positive (or not) diagonal */
static InvApprox *diagonal_preconditioner(const double *d)
{
    static double blocks[9 * NODES];
    memset(blocks, 0, sizeof blocks);
    for (int i = 0; i < NODES; ++i)
        for (int k = 0; k < 3; ++k) blocks[9 * i + 4 * k] = d[3 * i + k];
    InvApprox *M = NULL;
    int st = inv_create(&inv_scalar_jacobi_ops, NULL, &M);
    InvSetupInput in = {.n_nodes = NODES, .diag = blocks};
    if (!st) st = inv_setup(M, &in);
    CHECK(st == MPM_OK, "diagonal preconditioner: %s", mpm_last_error());
    return M;
}

int main(void)
{
    /* eigenvalues of both signs, magnitudes 0.3 .. 40 */
    double lambda[N];
    for (int k = 0; k < N; ++k) lambda[k] = (k % 3 == 0 ? -1.0 : 1.0) * (0.3 + 2.8 * k);
    Dense A;
    build(&A, lambda, 11);
    LinearOp op = {NODES, dense_apply, &A};
    unsigned long long seed = 5;
    double b[N], x[N], xs[N], r[N];
    for (int i = 0; i < N; ++i) b[i] = test_uniform(&seed, -1, 1);
    int all[N];
    for (int i = 0; i < N; ++i) all[i] = i;
    dense_solve(&A, b, all, N, xs);
    MinresWork w = {0};
    MinresResult res;

    /* 1. unpreconditioned */
    MinresOptions o = {.rel_tol = 1e-12, .max_iters = 1000};
    int st = minres_solve(&op, NULL, NULL, b, x, &o, &w, &res);
    CHECK(st == MPM_OK && !res.capped, "minres: %s", mpm_last_error());
    CHECK(rel_err(x, xs) < 1e-9, "indefinite system: relative error %.3e against the dense solve", rel_err(x, xs));
    CHECK(res.iters <= N + 2, "%d iterations for %d unknowns", res.iters, N);
    dense_apply(&A, x, r);
    for (int i = 0; i < N; ++i) r[i] = b[i] - r[i];
    CHECK(fabs(vec_norm(N, r) - res.res) <= 1e-9 * vec_norm(N, b), "reported residual %.3e, true %.3e", res.res,
          vec_norm(N, r));
    printf("indefinite %dx%d: %d iterations, relative error %.2e\n", N, N, res.iters, rel_err(x, xs));

    /* 2. the residual never grows, and equals the true one at every cap */
    double last = INFINITY;
    for (int k = 1; k <= N; ++k) {
        MinresOptions ok = {.rel_tol = 1e-14, .max_iters = k};
        st = minres_solve(&op, NULL, NULL, b, x, &ok, &w, &res);
        dense_apply(&A, x, r);
        for (int i = 0; i < N; ++i) r[i] = b[i] - r[i];
        CHECK(st == MPM_OK && res.res <= last * (1 + 1e-12), "iteration %d: residual %.6e after %.6e", k, res.res,
              last);
        CHECK(fabs(vec_norm(N, r) - res.res) <= 1e-9 * vec_norm(N, b), "iteration %d: reported %.6e, true %.6e", k,
              res.res, vec_norm(N, r));
        if (k < N - 1) CHECK(res.capped && res.iters == k, "cap %d: capped %d after %d", k, res.capped, res.iters);
        last = res.res;
    }

    /* 3. SPD diagonal preconditioner: same solution, residual in the M^-1 norm */
    double d[N];
    for (int i = 0; i < N; ++i) d[i] = fabs(A.a[i * N + i]) + 1.0 + i;
    InvApprox *M = diagonal_preconditioner(d);
    st = minres_solve(&op, M, NULL, b, x, &o, &w, &res);
    /* N iterations in exact arithmetic; finite-precision Lanczos loses
       orthogonality and needs a few more (19 for this system), while a broken
       recurrence runs to the cap of 1000 */
    CHECK(st == MPM_OK && rel_err(x, xs) < 1e-9 && res.iters <= 2 * N,
          "preconditioned: st %d, relative error %.3e, %d iterations", st, rel_err(x, xs), res.iters);
    dense_apply(&A, x, r);
    double rr = 0.0;
    for (int i = 0; i < N; ++i) rr += (b[i] - r[i]) * (b[i] - r[i]) / d[i];
    CHECK(fabs(sqrt(rr) - res.res) <= 1e-9 * res.res0, "preconditioned residual: reported %.3e, ||r||_{M^-1} %.3e",
          res.res, sqrt(rr));
    inv_destroy(M);

    /* 4. projection: node 0 fixed, the reduced system */
    Projection proj = {zero_node0, NULL};
    dense_solve(&A, b, all + 3, N - 3, xs);
    st = minres_solve(&op, NULL, &proj, b, x, &o, &w, &res);
    CHECK(st == MPM_OK && rel_err(x, xs) < 1e-9 && x[0] == 0.0 && x[1] == 0.0 && x[2] == 0.0,
          "projected: relative error %.3e, x0 = (%g %g %g)", rel_err(x, xs), x[0], x[1], x[2]);

    /* 5. cap and zero right-hand side */
    MinresOptions o3 = {.rel_tol = 1e-12, .max_iters = 3};
    st = minres_solve(&op, NULL, NULL, b, x, &o3, &w, &res);
    CHECK(st == MPM_OK && res.capped && res.iters == 3, "cap 3: capped %d after %d", res.capped, res.iters);
    double zero[N] = {0};
    st = minres_solve(&op, NULL, NULL, zero, x, &o, &w, &res);
    CHECK(st == MPM_OK && res.iters == 0 && vec_norm(N, x) == 0.0, "zero rhs: %d iterations", res.iters);

    /* 6. an indefinite preconditioner is a breakdown, not a wrong answer */
    d[4] = -d[4];
    M = diagonal_preconditioner(d);
    mpm_clear_error();
    st = minres_solve(&op, M, NULL, b, x, &o, &w, &res);
    CHECK(st == MPM_ENUMERIC, "indefinite preconditioner: status %d (%s)", st, mpm_last_error());
    mpm_clear_error();
    inv_destroy(M);

    /* 7. CG on the same system meets non-positive curvature and says so;
     *    its iterate is downhill for the quadratic model (b . x > 0) */
    PcgWork pw = {0};
    PcgResult pr;
    PcgOptions po = {.stop = PCG_RELATIVE_L2, .rel_tol = 1e-12, .max_iters = 1000};
    st = pcg_solve(&op, NULL, NULL, b, x, &po, &pw, &pr);
    CHECK(st == MPM_OK && pr.indefinite && vec_dot(N, b, x) > 0.0,
          "pcg on an indefinite system: indefinite flag %d after %d iterations, b.x %g", pr.indefinite, pr.iters,
          vec_dot(N, b, x));
    pcg_work_free(&pw);

    minres_work_free(&w);
    return test_summary("test_minres");
}
