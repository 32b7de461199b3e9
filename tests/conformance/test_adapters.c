/* floor: adapters */
/* needs: MPM_WITH_CHOLMOD MPM_WITH_HYPRE */
/* Third-party adapters (adapters/): CHOLMOD direct factorisation and one
 * hypre BoomerAMG V-cycle as inverse approximations, on synthetic SPD 3x3-
 * block matrices (tests/common/synthetic.h: spring network on a ball of grid nodes,
 * 125-block stencil, Dirichlet rows decoupled with an identity block).
 *
 * CHOLMOD: exact solves, symbolic analysis reused for an unchanged pattern and
 * redone for a new one, an indefinite matrix fails setup cleanly.
 * BoomerAMG: one V-cycle reduces the A-norm error, the V-cycle operator is
 * symmetric and positive, and as a PCG preconditioner it needs far fewer
 * iterations than block Jacobi; options are validated. The same comparison
 * then runs on a real projected MPM Hessian (tests/common/fixture.h: two fixed-
 * corotated materials 300x apart in stiffness, sticky bottom layer).
 * Trilinos ML (built with MPM_WITH_ML): ML reads exactly the Hessian through
 * getrow, its V-cycle is symmetric and positive and a far better PCG
 * preconditioner than block Jacobi, a re-setup on new values gives the same
 * operator as a fresh object (no stale eigenvalue estimate), options are
 * validated, and the rigid-body modes it is given are null vectors of an
 * unconstrained elastic Hessian at rest. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/cholmod.h"
#include "adapters/boomeramg.h"
#if MPM_WITH_ML
#include "adapters/ml.h"
#endif
#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"
#include "core/problem.h"
#include "tests/common/fixture.h"
#include "tests/common/synthetic.h"
#include "tests/common/testutil.h"

static InvSetupInput input_of(const SynthProblem *p)
{
    InvSetupInput in = {.n_nodes = p->n, .H = &p->A, .diag = p->diag, .coord = p->coord, .coloring = &p->col,
                        .op = &p->op, .proj = &p->proj};
    return in;
}

/* ||b - A x|| / ||b|| (no projection: Dirichlet rows are part of the system) */
static double rel_residual(const Bsr *A, const double *b, const double *x)
{
    size_t len = 3 * (size_t)A->n;
    double *r = malloc(sizeof(double) * len);
    bsr_spmv(A, x, r);
    for (size_t k = 0; k < len; ++k) r[k] = b[k] - r[k];
    double v = vec_norm(len, r) / vec_norm(len, b);
    free(r);
    return v;
}

/* sqrt(e^T A e) */
static double a_norm(const Bsr *A, const double *e)
{
    size_t len = 3 * (size_t)A->n;
    double *Ae = malloc(sizeof(double) * len);
    bsr_spmv(A, e, Ae);
    double v = sqrt(fmax(vec_dot(len, e, Ae), 0.0));
    free(Ae);
    return v;
}

static void add_opt(SolverOptions *o, const char *key, const char *value)
{
    snprintf(o->key[o->n], sizeof o->key[0], "%s", key);
    snprintf(o->value[o->n], sizeof o->value[0], "%s", value);
    o->n++;
}

/* adds s to every diagonal entry: same pattern, new values, still SPD */
static void shift_diagonal(SynthProblem *p, double s)
{
    for (int i = 0; i < p->n; ++i) {
        int64_t k = bsr_find(&p->A, i, i);
        for (int d = 0; d < 3; ++d) p->A.val[9 * k + 4 * d] += s;
    }
    bsr_diagonal(&p->A, p->diag);
}

/* PCG to 1e-8 of the initial preconditioned residual norm */
static PcgResult run_pcg(const SynthProblem *p, InvApprox *M, const double *b, double *x, PcgWork *w)
{
    PcgResult res;
    PcgOptions o = {.stop = PCG_ABSOLUTE, .abs_tol = 0.0, .max_iters = 0};
    pcg_solve(&p->op, M, &p->proj, b, x, &o, w, &res); /* rho0 only */
    o.max_iters = 10000;
    o.abs_tol = 1e-8 * res.rho0;
    int st = pcg_solve(&p->op, M, &p->proj, b, x, &o, w, &res);
    CHECK(st == MPM_OK && !res.capped, "%s PCG: status %d, capped %d: %s", M->ops->name, st, res.capped,
          mpm_last_error());
    return res;
}

/* A chain of n nodes, block-tridiagonal with dense 3x3 blocks: minimum
 * degree ordering eliminates the chain from its ends without fill, so the
 * factor holds exactly the lower triangle, 6 n + 9 (n - 1) entries; a
 * factor that dropped or duplicated blocks of A would not. The solve must
 * be exact too. */
static void test_cholmod_chain(void)
{
    const int n = 40;
    Bsr A;
    memset(&A, 0, sizeof A);
    CHECK(bsr_reserve(&A, n, 3 * n) == MPM_OK, "reserve");
    int64_t k = 0;
    for (int i = 0; i < n; ++i) {
        A.row_ptr[i] = k;
        for (int j = i - 1; j <= i + 1; ++j) {
            if (j < 0 || j >= n) continue;
            A.col[k] = j;
            double *B = A.val + 9 * k;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) /* symmetric: B_ij = B_ji^T, diagonally dominant */
                    B[3 * r + c] = i == j ? (r == c ? 20.0 : 1.0) : -1.0 - 0.1 * (i < j ? 3 * r + c : 3 * c + r);
            ++k;
        }
    }
    A.row_ptr[n] = k;
    A.nnzb = k;
    bsr_update_pattern_id(&A);
    double *diag = malloc(sizeof(double) * 9 * n), *b = malloc(sizeof(double) * 3 * n),
           *x = malloc(sizeof(double) * 3 * n);
    bsr_diagonal(&A, diag);
    for (int i = 0; i < 3 * n; ++i) b[i] = sin(1.0 + i);
    InvApprox *C = NULL;
    int st = inv_cholmod_ops.create(NULL, &C);
    InvSetupInput in = {.n_nodes = n, .H = &A, .diag = diag};
    if (!st) st = C->ops->setup(C, &in);
    double lnz = 0.0;
    if (!st) cholmod_direct_info(C, &lnz, NULL);
    if (!st) st = C->ops->apply(C, b, x);
    CHECK(st == MPM_OK, "chain: %s", mpm_last_error());
    double want = 6.0 * n + 9.0 * (n - 1);
    CHECK(lnz == want, "chain factor nnz %g, expected exactly the lower triangle's %g", lnz, want);
    double res = rel_residual(&A, b, x);
    CHECK(res < 1e-12, "chain solve: ||Ax-b||/||b|| = %g", res);
    if (C) C->ops->destroy(C);
    free(diag);
    free(b);
    free(x);
    bsr_free(&A);
}

static void test_cholmod(SynthProblem *p)
{
    const size_t len = 3 * (size_t)p->n;
    double *b = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len);
    InvApprox *C = NULL;
    int st = inv_create(&inv_cholmod_ops, NULL, &C);
    CHECK(st == MPM_OK && C && strcmp(C->ops->name, "cholmod") == 0, "cholmod create: %s", mpm_last_error());
    if (st) return;
    InvSetupInput in = input_of(p);

    /* first factorisation */
    st = inv_setup(C, &in);
    CHECK(st == MPM_OK, "cholmod setup: %s", mpm_last_error());
    double lnz = 0.0;
    int n_an = -1;
    cholmod_direct_info(C, &lnz, &n_an);
    CHECK(n_an == 1, "one analysis after the first setup, got %d", n_an);
    /* L's pattern holds tril(A)'s: a factor of fewer entries dropped some of A */
    CHECK(lnz >= (double)(9 * p->A.nnzb + 3 * p->n) / 2, "factor nnz %g smaller than the lower triangle", lnz);
    synth_random_vector(p->n, 7, b);
    double t_apply = 0.0;
    st = inv_apply(C, b, x);
    t_apply = C->stats.apply_s;
    double res = rel_residual(&p->A, b, x);
    CHECK(st == MPM_OK && res < 1e-10, "cholmod solve: status %d, ||Ax-b||/||b|| = %g", st, res);
    printf("cholmod: %d nodes, %zu unknowns, factor nnz %.4g (%.1f x nnz(tril A)), setup %.3f s, apply %.4f s, "
           "||Ax-b||/||b|| = %.2e\n",
           p->n, len, lnz, lnz / ((9.0 * (double)p->A.nnzb + 3.0 * p->n) / 2.0), C->stats.setup_s, t_apply, res);

    /* same pattern, new values: numeric refactorisation only */
    shift_diagonal(p, 0.5);
    st = inv_setup(C, &in);
    cholmod_direct_info(C, NULL, &n_an);
    CHECK(st == MPM_OK && n_an == 1, "same pattern must not re-analyse: status %d, analyses %d", st, n_an);
    st = inv_apply(C, b, x);
    res = rel_residual(&p->A, b, x);
    CHECK(st == MPM_OK && res < 1e-10, "refactorised solve: ||Ax-b||/||b|| = %g", res);
    printf("cholmod: refactorisation with the same pattern %.3f s (analyses %d)\n", C->stats.setup_s, n_an);
    shift_diagonal(p, -0.5);

    /* new pattern (27-block stencil, fewer nodes): new analysis */
    {
        SynthProblem q;
        SynthParams sq = {.center = {1, 2, 3}, .radius = 6.0, .reach = 1, .mass = 1.0, .stiff = 100.0,
                          .dirichlet = 1, .seed = 5};
        st = synth_build(&q, &sq);
        CHECK(st == MPM_OK, "synth q: %s", mpm_last_error());
        InvSetupInput iq = input_of(&q);
        st = inv_setup(C, &iq);
        cholmod_direct_info(C, NULL, &n_an);
        CHECK(st == MPM_OK && n_an == 2, "new pattern must re-analyse: status %d, analyses %d", st, n_an);
        double *bq = malloc(sizeof(double) * 3 * (size_t)q.n), *xq = malloc(sizeof(double) * 3 * (size_t)q.n);
        synth_random_vector(q.n, 8, bq);
        st = inv_apply(C, bq, xq);
        res = rel_residual(&q.A, bq, xq);
        CHECK(st == MPM_OK && res < 1e-10, "solve after the pattern change: ||Ax-b||/||b|| = %g", res);
        free(bq);
        free(xq);
        synth_free(&q);
    }

    /* back to the big matrix (storage grows again), made indefinite */
    {
        int node = -1;
        for (int i = p->n / 2; i < p->n && node < 0; ++i)
            if (!p->fixed[i]) node = i;
        int64_t k = bsr_find(&p->A, node, node);
        double saved[9];
        memcpy(saved, p->A.val + 9 * k, sizeof saved);
        for (int d = 0; d < 9; ++d) p->A.val[9 * k + d] = -saved[d]; /* symmetric, not positive definite */
        mpm_clear_error();
        st = inv_setup(C, &in);
        char want[32];
        snprintf(want, sizeof want, "node %d ", node);
        CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "not positive definite") &&
                  strstr(mpm_last_error(), want),
              "indefinite matrix: status %d, message '%s'", st, mpm_last_error());
        printf("cholmod on an indefinite matrix (node %d negated): '%s'\n", node, mpm_last_error());
        cholmod_direct_info(C, NULL, &n_an);
        CHECK(n_an == 3, "pattern back: analyses %d", n_an);
        mpm_clear_error();
        st = inv_apply(C, b, x);
        CHECK(st == MPM_EINTERNAL, "apply after a failed setup must fail, got %d", st);
        mpm_clear_error();
        memcpy(p->A.val + 9 * k, saved, sizeof saved);
        st = inv_setup(C, &in);
        st |= inv_apply(C, b, x);
        res = rel_residual(&p->A, b, x);
        cholmod_direct_info(C, NULL, &n_an);
        CHECK(st == MPM_OK && res < 1e-10 && n_an == 4, "recovery after failure: status %d, residual %g, analyses %d",
              st, res, n_an);
    }
    /* matrix-free input is refused */
    {
        InvSetupInput mf = in;
        mf.H = NULL;
        mpm_clear_error();
        CHECK(inv_setup(C, &mf) == MPM_EINTERNAL, "matrix-free cholmod must fail");
        mpm_clear_error();
    }
    CHECK(cholmod_direct_info(NULL, NULL, NULL) == MPM_EINTERNAL, "info on NULL");
    mpm_clear_error();
    inv_destroy(C);
    free(b);
    free(x);
}

/* A projected random right-hand side b (seed 21) and its exact solution x
 * from CHOLMOD: the reference the multigrid adapters are measured against. */
static int cholmod_reference(const SynthProblem *p, const InvSetupInput *in, double *b, double *x)
{
    InvApprox *C = NULL;
    int st = inv_create(&inv_cholmod_ops, NULL, &C);
    st |= inv_setup(C, in);
    synth_random_vector(p->n, 21, b);
    projection_apply(&p->proj, b);
    st |= inv_apply(C, b, x);
    CHECK(st == MPM_OK, "cholmod reference: %s", mpm_last_error());
    inv_destroy(C);
    return st;
}

static void test_boomeramg(SynthProblem *p)
{
    const size_t len = 3 * (size_t)p->n;
    double *b = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len), *z = malloc(sizeof(double) * len);
    double *y = malloc(sizeof(double) * len), *My = malloc(sizeof(double) * len), *Mx = malloc(sizeof(double) * len);
    InvSetupInput in = input_of(p);

    int st = cholmod_reference(p, &in, b, x);

    InvApprox *M = NULL;
    st = inv_create(&inv_boomeramg_ops, NULL, &M);
    CHECK(st == MPM_OK && M && strcmp(M->ops->name, "boomeramg") == 0, "boomeramg create: %s", mpm_last_error());
    if (st) return;
    st = inv_setup(M, &in);
    CHECK(st == MPM_OK, "boomeramg setup: %s", mpm_last_error());
    if (st) return;
    int levels = 0;
    double cx = 0.0;
    CHECK(boomeramg_info(M, &levels, &cx) == MPM_OK && levels >= 2 && cx >= 1.0, "hierarchy: %d levels, complexity %g",
          levels, cx);
    double t_setup = M->stats.setup_s;

    /* one V-cycle from zero: A-norm error reduction */
    st = inv_apply(M, b, z);
    CHECK(st == MPM_OK, "boomeramg apply: %s", mpm_last_error());
    double t_apply = M->stats.apply_s;
    for (size_t k = 0; k < len; ++k) y[k] = x[k] - z[k];
    double red = a_norm(&p->A, y) / a_norm(&p->A, x);
    CHECK(red < 0.5, "one V-cycle: ||x - Mb||_A / ||x||_A = %g", red);
    int fixed_zero = 1;
    for (int i = 0; i < p->n; ++i)
        if (p->fixed[i] && (fabs(z[3 * i]) + fabs(z[3 * i + 1]) + fabs(z[3 * i + 2])) > 1e-14 * vec_norm(len, z))
            fixed_zero = 0;
    CHECK(fixed_zero, "Dirichlet entries of M b must vanish for a projected b");
    printf("boomeramg: %d levels, operator complexity %.2f, setup %.3f s, one V-cycle %.4f s, "
           "A-norm error after one V-cycle %.3f\n",
           levels, cx, t_setup, t_apply, red);

    /* symmetry and positivity of the V-cycle operator */
    for (int trial = 0; trial < 3; ++trial) {
        synth_random_vector(p->n, 300 + trial, x);
        synth_random_vector(p->n, 400 + trial, y);
        if (trial == 0) { /* one projected pair as PCG sees them */
            projection_apply(&p->proj, x);
            projection_apply(&p->proj, y);
        }
        st = inv_apply(M, x, Mx);
        st |= inv_apply(M, y, My);
        double xMy = vec_dot(len, x, My), yMx = vec_dot(len, y, Mx), xMx = vec_dot(len, x, Mx);
        double scale = sqrt(fabs(xMx) * fabs(vec_dot(len, y, My)));
        CHECK(st == MPM_OK && fabs(xMy - yMx) <= 1e-8 * scale, "symmetry: x^T M y %.17g vs y^T M x %.17g (scale %g)",
              xMy, yMx, scale);
        CHECK(xMx > 0.0, "positivity: x^T M x = %g", xMx);
        if (trial == 0)
            printf("boomeramg: x^T M y = %.15g, y^T M x = %.15g, |diff|/scale = %.2e\n", xMy, yMx,
                   fabs(xMy - yMx) / scale);
    }
    /* deterministic: the same input gives the same output */
    st = inv_apply(M, b, y);
    CHECK(st == MPM_OK && memcmp(y, z, sizeof(double) * len) == 0, "repeated application differs");

    /* PN-AMG-PCG vs PN-PCG (block Jacobi) */
    {
        InvApprox *J = NULL;
        inv_create(&inv_block_jacobi_ops, NULL, &J);
        st = inv_setup(J, &in);
        CHECK(st == MPM_OK, "jacobi setup");
        PcgWork w = {0};
        PcgResult rj = run_pcg(p, J, b, x, &w);
        double resj = rel_residual(&p->A, b, x);
        M->stats.apply_s = 0.0;
        PcgResult ra = run_pcg(p, M, b, x, &w);
        double resa = rel_residual(&p->A, b, x);
        printf("PCG to 1e-8 (preconditioned norm): block Jacobi %d iterations (residual %.1e), BoomerAMG %d "
               "iterations (residual %.1e, %.4f s per V-cycle)\n",
               rj.iters, resj, ra.iters, resa, M->stats.apply_s / (ra.iters + 1));
        CHECK(ra.iters * 4 < rj.iters, "AMG-PCG (%d) should need far fewer iterations than Jacobi-PCG (%d)", ra.iters,
              rj.iters);
        CHECK(resa < 1e-6, "AMG-PCG solution residual %g", resa);
        pcg_work_free(&w);
        inv_destroy(J);
    }

    /* the matrix hypre holds is H */
    {
        synth_random_vector(p->n, 13, x);
        bsr_spmv(&p->A, x, y);
        st = boomeramg_matvec(M, x, z);
        double d = 0.0, ny = 0.0;
        for (size_t k = 0; k < len; ++k) {
            d = fmax(d, fabs(z[k] - y[k]));
            ny = fmax(ny, fabs(y[k]));
        }
        CHECK(st == MPM_OK && d <= 1e-14 * ny, "hypre's copy of H: max |A_hypre x - H x| = %g (max %g): %s", d, ny,
              mpm_last_error());
    }

    /* repeated setups: same pattern, new pattern, back */
    {
        shift_diagonal(p, 0.5);
        st = inv_setup(M, &in);
        CHECK(st == MPM_OK, "re-setup with the same pattern: %s", mpm_last_error());
        printf("boomeramg: re-setup with the same pattern %.3f s\n", M->stats.setup_s);
        PcgWork w = {0};
        PcgResult r2 = run_pcg(p, M, b, x, &w);
        CHECK(rel_residual(&p->A, b, x) < 1e-6, "AMG-PCG after re-setup (%d iterations)", r2.iters);
        shift_diagonal(p, -0.5);

        SynthProblem q;
        SynthParams sq = {.center = {1, 2, 3}, .radius = 6.0, .reach = 1, .mass = 1.0, .stiff = 100.0,
                          .dirichlet = 1, .seed = 5};
        st = synth_build(&q, &sq);
        InvSetupInput iq = input_of(&q);
        st |= inv_setup(M, &iq);
        CHECK(st == MPM_OK, "setup on a new pattern: %s", mpm_last_error());
        double *bq = malloc(sizeof(double) * 3 * (size_t)q.n), *xq = malloc(sizeof(double) * 3 * (size_t)q.n);
        synth_random_vector(q.n, 9, bq);
        projection_apply(&q.proj, bq);
        PcgResult rq = run_pcg(&q, M, bq, xq, &w);
        CHECK(rel_residual(&q.A, bq, xq) < 1e-6, "AMG-PCG on the new pattern (%d iterations)", rq.iters);
        free(bq);
        free(xq);
        synth_free(&q);

        st = inv_setup(M, &in);
        r2 = run_pcg(p, M, b, x, &w);
        CHECK(st == MPM_OK && rel_residual(&p->A, b, x) < 1e-6, "AMG-PCG back on the first pattern");
        pcg_work_free(&w);

        InvSetupInput mf = in;
        mf.H = NULL;
        mpm_clear_error();
        CHECK(inv_setup(M, &mf) == MPM_EINTERNAL, "matrix-free boomeramg must fail");
        mpm_clear_error();
        CHECK(inv_apply(M, b, x) == MPM_EINTERNAL, "apply after a failed setup must fail");
        mpm_clear_error();
    }
    inv_destroy(M);

    /* option variants all give a working preconditioner */
    {
        static const char *variants[][2][2] = {
            {{"amg_coarsen", "PMIS"}, {"amg_nodal", "6"}},
            {{"amg_coarsen", "falgout"}, {"amg_nodal", "0"}},
            {{"amg_agg_levels", "1"}, {"amg_strong_threshold", "0.25"}},
            {{"amg_relax", "8"}, {"amg_sweeps", "2"}},
            {{"amg_rbm", "2"}, {"amg_interp", "0"}},
        };
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; ++v) {
            SolverOptions o = {0};
            add_opt(&o, variants[v][0][0], variants[v][0][1]);
            add_opt(&o, variants[v][1][0], variants[v][1][1]);
            InvApprox *V = NULL;
            st = inv_create(&inv_boomeramg_ops, &o, &V);
            CHECK(st == MPM_OK, "create with %s=%s: %s", o.key[0], o.value[0], mpm_last_error());
            if (st) continue;
            st = inv_setup(V, &in);
            CHECK(st == MPM_OK, "setup with %s=%s %s=%s: %s", o.key[0], o.value[0], o.key[1], o.value[1],
                  mpm_last_error());
            if (!st) {
                PcgWork w = {0};
                PcgResult r = run_pcg(p, V, b, x, &w);
                boomeramg_info(V, &levels, &cx);
                printf("boomeramg %s=%s %s=%s: %d levels, complexity %.2f, setup %.3f s, PCG %d iterations\n",
                       o.key[0], o.value[0], o.key[1], o.value[1], levels, cx, V->stats.setup_s, r.iters);
                CHECK(rel_residual(&p->A, b, x) < 1e-6, "variant %zu residual", v);
                pcg_work_free(&w);
            }
            inv_destroy(V);
        }
        static const char *bad[][2] = {{"amg_coarsen", "RS"},           {"amg_nodal", "5"},     {"amg_relax", "4"},
                                       {"amg_strong_threshold", "1.5"}, {"amg_agg_levels", "-1"}, {"amg_sweeps", "x"},
                                       {"amg_interp", "10"},            {"amg_rbm", "4"},       {"amg_max_levels", "0"}};
        for (size_t v = 0; v < sizeof bad / sizeof bad[0]; ++v) {
            SolverOptions o = {0};
            add_opt(&o, bad[v][0], bad[v][1]);
            InvApprox *V = NULL;
            mpm_clear_error();
            st = inv_create(&inv_boomeramg_ops, &o, &V);
            CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), bad[v][0]), "%s=%s must be rejected: %d '%s'",
                  bad[v][0], bad[v][1], st, mpm_last_error());
            mpm_clear_error();
        }
    }
    free(b);
    free(x);
    free(z);
    free(y);
    free(My);
    free(Mx);
}

#if MPM_WITH_ML
static double max_abs_diff(size_t len, const double *a, const double *b, double *amax)
{
    double d = 0.0, m = 0.0;
    for (size_t k = 0; k < len; ++k) {
        d = fmax(d, fabs(a[k] - b[k]));
        m = fmax(m, fabs(a[k]));
    }
    if (amax) *amax = m;
    return d;
}

static void test_ml(SynthProblem *p)
{
    const size_t len = 3 * (size_t)p->n;
    double *b = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len), *z = malloc(sizeof(double) * len);
    double *y = malloc(sizeof(double) * len), *My = malloc(sizeof(double) * len), *Mx = malloc(sizeof(double) * len);
    double *xs = malloc(sizeof(double) * len);
    InvSetupInput in = input_of(p);

    int st = cholmod_reference(p, &in, b, xs);

    InvApprox *M = NULL;
    st = inv_create(&inv_ml_ops, NULL, &M);
    CHECK(st == MPM_OK && M && strcmp(M->ops->name, "ml") == 0, "ml create: %s", mpm_last_error());
    if (st) return;
    st = inv_setup(M, &in);
    CHECK(st == MPM_OK, "ml setup: %s", mpm_last_error());
    if (st) return;
    int levels = 0;
    double cx = 0.0;
    CHECK(ml_info(M, &levels, &cx) == MPM_OK && levels >= 2 && cx >= 1.0, "ml hierarchy: %d levels, complexity %g",
          levels, cx);

    /* ML reads exactly H: by its rows (getrow) and by its operator (matvec) */
    {
        synth_random_vector(p->n, 13, x);
        bsr_spmv(&p->A, x, y);
        double ny = 0.0;
        st = ml_getrow_matvec(M, x, z);
        double d = max_abs_diff(len, y, z, &ny);
        CHECK(st == MPM_OK && d <= 1e-14 * ny, "ML's getrow rows: max |A_ml x - H x| = %g (max %g)", d, ny);
        st = ml_matvec(M, x, z);
        d = max_abs_diff(len, y, z, &ny);
        CHECK(st == MPM_OK && d == 0.0, "ML's fine operator: max |A_ml x - H x| = %g", d);
    }

    /* one V-cycle from zero: A-norm error reduction */
    st = inv_apply(M, b, z);
    CHECK(st == MPM_OK, "ml apply: %s", mpm_last_error());
    {
        for (size_t k = 0; k < len; ++k) y[k] = xs[k] - z[k];
        double red = a_norm(&p->A, y) / a_norm(&p->A, xs);
        CHECK(red < 0.5, "ml: one V-cycle: ||x - Mb||_A / ||x||_A = %g", red);
        printf("ml: %d levels, operator complexity %.2f, setup %.3f s, one V-cycle %.4f s, A-norm error after one "
               "V-cycle %.3f\n",
               levels, cx, M->stats.setup_s, M->stats.apply_s, red);
    }

    /* symmetry and positivity of the V-cycle operator */
    for (int trial = 0; trial < 3; ++trial) {
        synth_random_vector(p->n, 300 + trial, x);
        synth_random_vector(p->n, 400 + trial, y);
        if (trial == 0) {
            projection_apply(&p->proj, x);
            projection_apply(&p->proj, y);
        }
        st = inv_apply(M, x, Mx);
        st |= inv_apply(M, y, My);
        double xMy = vec_dot(len, x, My), yMx = vec_dot(len, y, Mx), xMx = vec_dot(len, x, Mx);
        double scale = sqrt(fabs(xMx) * fabs(vec_dot(len, y, My)));
        CHECK(st == MPM_OK && fabs(xMy - yMx) <= 1e-10 * scale,
              "ml symmetry: x^T M y %.17g vs y^T M x %.17g (scale %g)", xMy, yMx, scale);
        CHECK(xMx > 0.0, "ml positivity: x^T M x = %g", xMx);
        if (trial == 0)
            printf("ml: x^T M y = %.15g, y^T M x = %.15g, |diff|/scale = %.2e\n", xMy, yMx, fabs(xMy - yMx) / scale);
    }
    st = inv_apply(M, b, y);
    CHECK(st == MPM_OK && memcmp(y, z, sizeof(double) * len) == 0, "ml: repeated application differs");

    /* PN-ML-PCG vs PN-PCG (block Jacobi) */
    PcgWork w = {0};
    {
        InvApprox *J = NULL;
        inv_create(&inv_block_jacobi_ops, NULL, &J);
        st = inv_setup(J, &in);
        PcgResult rj = run_pcg(p, J, b, x, &w);
        M->stats.apply_s = 0.0;
        PcgResult ra = run_pcg(p, M, b, x, &w);
        double resa = rel_residual(&p->A, b, x);
        printf("PCG to 1e-8 (preconditioned norm): block Jacobi %d iterations, ML %d iterations (residual %.1e, "
               "%.4f s per V-cycle)\n",
               rj.iters, ra.iters, resa, M->stats.apply_s / (ra.iters + 1));
        CHECK(ra.iters * 4 < rj.iters, "ML-PCG (%d) should need far fewer iterations than Jacobi-PCG (%d)", ra.iters,
              rj.iters);
        CHECK(resa < 1e-6, "ML-PCG solution residual %g", resa);
        inv_destroy(J);
    }

    /* new values, same object: the same V-cycle as a fresh object's (a cached
     * lambda_max or hierarchy of the old values would differ) */
    {
        shift_diagonal(p, 50.0);
        st = inv_setup(M, &in);
        st |= inv_apply(M, b, z);
        InvApprox *F = NULL;
        st |= inv_create(&inv_ml_ops, NULL, &F);
        st |= inv_setup(F, &in);
        st |= inv_apply(F, b, y);
        double ny = 0.0, d = max_abs_diff(len, y, z, &ny);
        CHECK(st == MPM_OK && d <= 1e-14 * ny, "ml re-setup on new values: max |M_reused b - M_fresh b| = %g (max %g)",
              d, ny);
        inv_destroy(F);
        shift_diagonal(p, -50.0);
        st = inv_setup(M, &in);
        CHECK(st == MPM_OK, "ml setup back on the old values: %s", mpm_last_error());

        SynthProblem q;
        SynthParams sq = {.center = {1, 2, 3}, .radius = 6.0, .reach = 1, .mass = 1.0, .stiff = 100.0,
                          .dirichlet = 1, .seed = 5};
        st = synth_build(&q, &sq);
        InvSetupInput iq = input_of(&q);
        st |= inv_setup(M, &iq);
        CHECK(st == MPM_OK, "ml setup on a new pattern: %s", mpm_last_error());
        double *bq = malloc(sizeof(double) * 3 * (size_t)q.n), *xq = malloc(sizeof(double) * 3 * (size_t)q.n);
        synth_random_vector(q.n, 9, bq);
        projection_apply(&q.proj, bq);
        PcgResult rq = run_pcg(&q, M, bq, xq, &w);
        CHECK(rel_residual(&q.A, bq, xq) < 1e-6, "ML-PCG on the new pattern (%d iterations)", rq.iters);
        free(bq);
        free(xq);
        synth_free(&q);

        InvSetupInput mf = in;
        mf.H = NULL;
        mpm_clear_error();
        CHECK(inv_setup(M, &mf) == MPM_EINTERNAL, "matrix-free ml must fail");
        mpm_clear_error();
        CHECK(inv_apply(M, b, x) == MPM_EINTERNAL, "ml apply after a failed setup must fail");
        mpm_clear_error();
    }
    inv_destroy(M);

    /* option variants all give a working preconditioner; bad values are refused */
    {
        static const char *variants[][2][2] = {
            {{"ml_smoother", "sgs"}, {"ml_sweeps", "1"}},
            {{"ml_smoother", "chebyshev"}, {"ml_sweeps", "4"}},
            {{"ml_rbm", "off"}, {"ml_threshold", "0.02"}},
            {{"ml_damping", "0"}, {"ml_coarse_size", "64"}},
            {{"ml_levels", "1"}, {"ml_sweeps", "1"}}, /* one level: KLU on the whole matrix */
        };
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; ++v) {
            SolverOptions o = {0};
            add_opt(&o, variants[v][0][0], variants[v][0][1]);
            add_opt(&o, variants[v][1][0], variants[v][1][1]);
            InvApprox *V = NULL;
            st = inv_create(&inv_ml_ops, &o, &V);
            CHECK(st == MPM_OK, "ml create with %s=%s: %s", o.key[0], o.value[0], mpm_last_error());
            if (st) continue;
            st = inv_setup(V, &in);
            CHECK(st == MPM_OK, "ml setup with %s=%s %s=%s: %s", o.key[0], o.value[0], o.key[1], o.value[1],
                  mpm_last_error());
            if (!st) {
                PcgResult r = run_pcg(p, V, b, x, &w);
                ml_info(V, &levels, &cx);
                printf("ml %s=%s %s=%s: %d levels, complexity %.2f, setup %.3f s, PCG %d iterations\n", o.key[0],
                       o.value[0], o.key[1], o.value[1], levels, cx, V->stats.setup_s, r.iters);
                CHECK(rel_residual(&p->A, b, x) < 1e-6, "ml variant %zu residual", v);
                if (v == 4) CHECK(levels == 1 && r.iters <= 2, "ml_levels=1 is a direct solve: %d levels, %d iterations",
                                  levels, r.iters);
            }
            inv_destroy(V);
        }
        static const char *bad[][2] = {{"ml_smoother", "jacobi"}, {"ml_sweeps", "0"},     {"ml_sweeps", "1.5"},
                                       {"ml_levels", "21"},       {"ml_threshold", "1"},  {"ml_threshold", "-0.1"},
                                       {"ml_coarse_size", "0"},   {"ml_damping", "2.5"},  {"ml_rbm", "yes"},
                                       {"ml_damping", "nan"}};
        for (size_t v = 0; v < sizeof bad / sizeof bad[0]; ++v) {
            SolverOptions o = {0};
            add_opt(&o, bad[v][0], bad[v][1]);
            InvApprox *V = NULL;
            mpm_clear_error();
            st = inv_create(&inv_ml_ops, &o, &V);
            CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), bad[v][0]) && !strchr(mpm_last_error(), '\n'),
                  "ml %s=%s must be rejected in one line: %d '%s'", bad[v][0], bad[v][1], st, mpm_last_error());
            inv_destroy(V);
            mpm_clear_error();
        }
    }
    pcg_work_free(&w);
    free(b);
    free(x);
    free(xs);
    free(z);
    free(y);
    free(My);
    free(Mx);
}

/* The null space ML is given: an unconstrained elastic MPM Hessian at rest
 * (F = I, no velocity, no gravity: zero stress) annihilates translations and
 * infinitesimal rotations of the node positions. H = M + dt^2 K (SPEC 3), so
 * K v = (H v - M v) / dt^2 must vanish to round-off for each of the 6 modes,
 * while a generic vector is not annihilated. */
static void test_ml_rigid_body_modes(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 8;
    o.F_noise = 0.0;
    o.v_noise = 0.0;
    o.C_noise = 0.0;
    Fixture f;
    int st = fixture_build(&f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return;
    StepProblem *pb = &f.pb;
    problem_finish_dirichlet(pb);
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *zero = calloc(len, sizeof(double)), *ns = malloc(sizeof(double) * 6 * len);
    double *Hv = malloc(sizeof(double) * len), *Kv = malloc(sizeof(double) * len);
    problem_energy(pb, zero);
    st = problem_tangent(pb, 0);
    Bsr H = {0};
    st |= problem_assemble(pb, &H);
    CHECK(st == MPM_OK && pb->n_dirichlet == 0, "assemble: %s", mpm_last_error());
    ml_rigid_body_modes(n, f.g.coord, ns);
    /* K's scale: its largest diagonal entry */
    double kmax = 0.0;
    for (int i = 0; i < n; ++i) {
        int64_t k = bsr_find(&H, i, i);
        for (int d = 0; d < 3; ++d) kmax = fmax(kmax, (H.val[9 * k + 4 * d] - f.g.mass[i]) / (o.dt * o.dt));
    }
    double worst = 0.0;
    for (int m = 0; m < 7; ++m) {
        double *v = ns + (size_t)(m < 6 ? m : 0) * len;
        if (m == 6) synth_random_vector(n, 3, v); /* a generic vector (over mode 0): K must see it */
        bsr_spmv(&H, v, Hv);
        double kv = 0.0, vmax = 0.0;
        for (int i = 0; i < n; ++i)
            for (int d = 0; d < 3; ++d) {
                Kv[3 * i + d] = (Hv[3 * i + d] - f.g.mass[i] * v[3 * i + d]) / (o.dt * o.dt);
                kv = fmax(kv, fabs(Kv[3 * i + d]));
                vmax = fmax(vmax, fabs(v[3 * i + d]));
            }
        double rel = kv / (kmax * vmax);
        if (m < 6) {
            worst = fmax(worst, rel);
            CHECK(rel < 1e-12, "rigid-body mode %d: max|K v| / (max K_ii max|v|) = %.3e", m, rel);
        } else {
            CHECK(rel > 1e-3, "a random vector: max|K v| / (max K_ii max|v|) = %.3e", rel);
            printf("ml null space: %d nodes, max|K v| / (max K_ii max|v|) over the 6 rigid-body modes %.2e (a random "
                   "vector %.2e)\n",
                   n, worst, rel);
        }
    }
    bsr_free(&H);
    free(zero);
    free(ns);
    free(Hv);
    free(Kv);
    fixture_free(&f);
}
#endif

static void mpm_spmv(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }
static void mpm_project(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

/* A real BC-projected MPM Hessian: CHOLMOD solves it exactly, BoomerAMG
 * preconditions it (nodal coarsening variants printed for the record). */
static void test_mpm_hessian(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 20;
    o.two_materials = 1;
    o.F_noise = 0.2;
    Fixture f;
    int st = fixture_build(&f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return;
    StepProblem *pb = &f.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    int ymin = f.g.coord[1];
    for (int i = 0; i < n; ++i)
        if (f.g.coord[3 * i + 1] < ymin) ymin = f.g.coord[3 * i + 1];
    const double zero[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i)
        if (f.g.coord[3 * i + 1] == ymin) problem_set_dirichlet(pb, i, zero, NULL);
    problem_finish_dirichlet(pb);
    double *dv = malloc(sizeof(double) * len), *b = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len);
    double *diag = malloc(sizeof(double) * 9 * (size_t)n);
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    problem_gradient(pb, dv, b); /* a realistic right-hand side: the gradient */
    st = problem_tangent(pb, 1);
    Bsr H = {0};
    st |= problem_assemble(pb, &H);
    CHECK(st == MPM_OK, "assemble: %s", mpm_last_error());
    problem_diagonal(pb, diag);
    LinearOp op = {n, mpm_spmv, &H};
    Projection proj = {mpm_project, pb};
    InvSetupInput in = {.n_nodes = n, .H = &H, .diag = diag, .coord = f.g.coord, .coloring = &f.g.coloring,
                        .op = &op, .proj = &proj, .problem = pb};
    SynthProblem view = {.n = n, .op = op, .proj = proj}; /* run_pcg needs only these */
    printf("MPM Hessian: %d nodes (%d Dirichlet), %lld blocks (%.1f per row), dt %g, E 1e4 and 3e6\n", n,
           pb->n_dirichlet, (long long)H.nnzb, (double)H.nnzb / n, o.dt);

    InvApprox *C = NULL;
    st = inv_create(&inv_cholmod_ops, NULL, &C);
    st |= inv_setup(C, &in);
    st |= inv_apply(C, b, x);
    double res = rel_residual(&H, b, x), lnz = 0;
    cholmod_direct_info(C, &lnz, NULL);
    CHECK(st == MPM_OK && res < 1e-10, "cholmod on the MPM Hessian: %s, residual %g", mpm_last_error(), res);
    printf("MPM Hessian, cholmod: factor nnz %.4g, setup %.3f s, apply %.4f s, residual %.1e\n", lnz,
           C->stats.setup_s, C->stats.apply_s, res);
    inv_destroy(C);

    PcgWork w = {0};
    InvApprox *J = NULL;
    inv_create(&inv_block_jacobi_ops, NULL, &J);
    st = inv_setup(J, &in);
    PcgResult rj = run_pcg(&view, J, b, x, &w);
    printf("MPM Hessian, PCG to 1e-8: block Jacobi %d iterations (%.3f s apply total)\n", rj.iters,
           J->stats.apply_s);
    inv_destroy(J);
    static const char *nodal[] = {"4", "6", "1", "0", "4 amg_rbm=2"};
    for (size_t v = 0; v < sizeof nodal / sizeof nodal[0]; ++v) {
        SolverOptions so = {0};
        char nv[8];
        snprintf(nv, sizeof nv, "%c", nodal[v][0]);
        add_opt(&so, "amg_nodal", nv);
        if (strstr(nodal[v], "amg_rbm=2")) add_opt(&so, "amg_rbm", "2");
        InvApprox *M = NULL;
        st = inv_create(&inv_boomeramg_ops, &so, &M);
        st |= inv_setup(M, &in);
        CHECK(st == MPM_OK, "boomeramg nodal %s on the MPM Hessian: %s", nodal[v], mpm_last_error());
        if (st) {
            inv_destroy(M);
            continue;
        }
        int levels = 0;
        double cx = 0;
        boomeramg_info(M, &levels, &cx);
        PcgResult ra = run_pcg(&view, M, b, x, &w);
        double resa = rel_residual(&H, b, x);
        printf("MPM Hessian, PCG to 1e-8: boomeramg amg_nodal=%s %d iterations (%d levels, operator complexity %.2f, "
               "setup %.3f s, %.4f s per V-cycle, residual %.1e)\n",
               nodal[v], ra.iters, levels, cx, M->stats.setup_s, M->stats.apply_s / (ra.iters + 1), resa);
        if (v == 0) {
            double *Hx = malloc(sizeof(double) * len), *Ax = malloc(sizeof(double) * len);
            synth_random_vector(n, 17, dv);
            bsr_spmv(&H, dv, Hx);
            st = boomeramg_matvec(M, dv, Ax);
            double d = 0.0, m = 0.0;
            for (size_t k = 0; k < len; ++k) {
                d = fmax(d, fabs(Ax[k] - Hx[k]));
                m = fmax(m, fabs(Hx[k]));
            }
            CHECK(st == MPM_OK && d <= 1e-14 * m, "hypre's copy of the MPM Hessian: max diff %g (max %g)", d, m);
            free(Hx);
            free(Ax);
        }
        if (v == 0)
            CHECK(ra.iters * 2 < rj.iters && resa < 1e-6,
                  "AMG-PCG (%d iterations, residual %g) vs Jacobi-PCG (%d) on the MPM Hessian", ra.iters, resa,
                  rj.iters);
        inv_destroy(M);
    }
#if MPM_WITH_ML
    {
        InvApprox *M = NULL;
        st = inv_create(&inv_ml_ops, NULL, &M);
        st |= inv_setup(M, &in);
        CHECK(st == MPM_OK, "ml on the MPM Hessian: %s", mpm_last_error());
        if (!st) {
            int levels = 0;
            double cx = 0;
            ml_info(M, &levels, &cx);
            PcgResult ra = run_pcg(&view, M, b, x, &w);
            double resa = rel_residual(&H, b, x);
            printf("MPM Hessian, PCG to 1e-8: ml %d iterations (%d levels, operator complexity %.2f, setup %.3f s, "
                   "%.4f s per V-cycle, residual %.1e)\n",
                   ra.iters, levels, cx, M->stats.setup_s, M->stats.apply_s / (ra.iters + 1), resa);
            CHECK(ra.iters * 5 < rj.iters * 2 && resa < 1e-6,
                  "ML-PCG (%d iterations, residual %g) vs Jacobi-PCG (%d) on the MPM Hessian", ra.iters, resa, rj.iters);
        }
        inv_destroy(M);
    }
#endif
    pcg_work_free(&w);
    bsr_free(&H);
    free(dv);
    free(b);
    free(x);
    free(diag);
    fixture_free(&f);
}

int main(void)
{
    SynthProblem p;
    /* a slab: thin enough that CHOLMOD's factorisations stay fast with the
     * reference BLAS, thick enough for a 125-block stencil in every direction */
    SynthParams sp = {.center = {-5, 7, -3}, .radius = 0.0, .box = {30, 12, 6}, .reach = 2, .mass = 1.0,
                      .stiff = 1000.0, .dirichlet = 1, .seed = 42};
    int st = synth_build(&p, &sp);
    CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
    if (st) return test_summary("test_adapters");
    printf("synthetic problem: %d nodes, %d Dirichlet, %lld blocks (%.1f per row)\n", p.n, p.n_fixed,
           (long long)p.A.nnzb, (double)p.A.nnzb / p.n);
    test_cholmod(&p);
    test_cholmod_chain();
    test_boomeramg(&p);
#if MPM_WITH_ML
    test_ml(&p);
#endif
    synth_free(&p);
    test_mpm_hessian();
#if MPM_WITH_ML
    test_ml_rigid_body_modes();
#endif
    return test_summary("test_adapters");
}
