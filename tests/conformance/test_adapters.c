/* floor: adapters */
/* The third-party adapters (adapters/), each one that this build has: the
 * generated list of built adapters (MPM_BUILT_ADAPTERS, from
 * adapters/adapter_list.h) is walked, and every adapter goes through the same
 * checks, each where it applies to it. What differs between adapters is data,
 * one row of `rows` below per adapter: whether apply is an exact solve (a
 * factorisation) or one multigrid cycle, its symmetry bound, how much better
 * than block Jacobi it must precondition, how it shows the matrix it holds,
 * its hierarchy, its option variants and refused options, and its own
 * checks (CHOLMOD's symbolic-analysis reuse and indefinite matrices, ML's
 * one-level direct solve and rigid-body modes). A built adapter without a
 * row fails the test. With no adapter built (the minimal build) the test is
 * skipped.
 *
 * Problems: a synthetic SPD 3x3-block matrix (tests/common/synthetic.h: a
 * slab of grid nodes, spring network, 125-block stencil, Dirichlet rows
 * decoupled with an identity block), a second one on other nodes (a new
 * pattern), and a real BC-projected MPM Hessian (tests/common/fixture.h: two
 * fixed-corotated materials 300x apart in stiffness, sticky bottom layer).
 * The exact solution the multigrid cycles are measured against comes from
 * block-Jacobi PCG to 1e-13, so no adapter needs another.
 *
 * The checks (CHECKS below), per adapter:
 *   create        created by its ops, under its name; its hierarchy (levels
 *                 >= 2, operator complexity >= 1) where it has one;
 *   shows H       the matrix it holds equals H (every view it offers, to its
 *                 bound), on the synthetic and the MPM Hessian;
 *   one apply     exact: ||H z - b|| / ||b|| < 1e-10; a cycle: the A-norm
 *                 error of z = M b is below half that of 0;
 *   Dirichlet     M b vanishes on the Dirichlet nodes for a projected b;
 *   sym-pos       x^T M y = y^T M x to its bound, x^T M x > 0 (synthetic and
 *                 MPM Hessian);
 *   deterministic the same input gives bitwise the same output;
 *   PCG           PCG with it needs 4x fewer iterations than with block
 *                 Jacobi (its own factor on the MPM Hessian) and reaches a
 *                 true residual below 1e-6 (an exact solve: 1e-10 on the MPM
 *                 Hessian);
 *   re-setup      set up again on new values (same pattern) it applies as a
 *                 fresh object does (to 1e-14) and PCG converges; a new
 *                 pattern and back, PCG converges on each;
 *   refusals      matrix-free input is refused, and apply after that failed
 *                 setup; bad option values are refused in one line naming the
 *                 option;
 *   variants      every option variant of its row sets up and preconditions
 *                 PCG to 1e-6 (and sets up on the MPM Hessian);
 *   own checks    its row's function. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/adapter_list.h"
#include "mpm_adapters_built.h" /* generated: MPM_BUILT_ADAPTERS(X), the adapters of this build */
#if MPM_WITH_CHOLMOD
#include "adapters/cholmod.h"
#endif
#if MPM_WITH_HYPRE
#include "adapters/boomeramg.h"
#endif
#if MPM_WITH_ML
#include "adapters/ml.h"
#endif
#if MPM_WITH_PETSC
#include "adapters/petsc.h"
#include "solvers/mg/mg.h"
#endif
#include "core/error.h"
#include "core/event_log.h"
#include "core/problem.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"
#include "tests/common/fixture.h"
#include "tests/common/synthetic.h"
#include "tests/common/testutil.h"

/* ---------------------------------------------------------------------------
 * The problems
 * ------------------------------------------------------------------------- */

/* A matrix with what a setup and PCG need; the arrays belong to its owner. */
typedef struct {
    const char *name;
    int n;
    Bsr *A;
    const unsigned char *fixed; /* n: Dirichlet nodes */
    InvSetupInput in;
    const LinearOp *op;
    const Projection *proj;
} Problem;

static Problem problem_of_synth(SynthProblem *p, const char *name)
{
    Problem q = {.name = name, .n = p->n, .A = &p->A, .fixed = p->fixed, .op = &p->op, .proj = &p->proj};
    q.in = (InvSetupInput){.n_nodes = p->n, .H = &p->A, .diag = p->diag, .coord = p->coord, .coloring = &p->col,
                           .op = &p->op, .proj = &p->proj};
    return q;
}

/* A real BC-projected MPM Hessian and the gradient as a right-hand side. */
typedef struct {
    Fixture f;
    Bsr H;
    double *diag, *b;
    unsigned char *fixed;
    LinearOp op;
    Projection proj;
    int jacobi_iters; /* block-Jacobi PCG's iterations to 1e-8 */
} MpmHessian;

static void mpm_spmv(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }
static void mpm_project(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

static double *vec_new(size_t len) { return calloc(len, sizeof(double)); }
static size_t len_of(const Problem *p) { return 3 * (size_t)p->n; }

/* ||b - A x|| / ||b|| (no projection: Dirichlet rows are part of the system) */
static double rel_residual(const Bsr *A, const double *b, const double *x)
{
    size_t len = 3 * (size_t)A->n;
    double *r = vec_new(len);
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
    double *Ae = vec_new(len);
    bsr_spmv(A, e, Ae);
    double v = sqrt(fmax(vec_dot(len, e, Ae), 0.0));
    free(Ae);
    return v;
}

static double max_abs_diff(size_t len, const double *a, const double *b, double *bmax)
{
    double d = 0.0, m = 0.0;
    for (size_t k = 0; k < len; ++k) {
        d = fmax(d, fabs(a[k] - b[k]));
        m = fmax(m, fabs(b[k]));
    }
    if (bmax) *bmax = m;
    return d;
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
static PcgResult run_pcg(const Problem *p, InvApprox *M, const double *b, double *x)
{
    PcgWork w = {0};
    PcgResult res;
    PcgOptions o = {.stop = PCG_ABSOLUTE, .abs_tol = 0.0, .max_iters = 0};
    pcg_solve(p->op, M, p->proj, b, x, &o, &w, &res); /* rho0 only */
    o.max_iters = 10000;
    o.abs_tol = 1e-8 * res.rho0;
    int st = pcg_solve(p->op, M, p->proj, b, x, &o, &w, &res);
    CHECK(st == MPM_OK && !res.capped, "%s on %s, PCG: status %d, capped %d: %s", M->ops->name, p->name, st,
          res.capped, mpm_last_error());
    pcg_work_free(&w);
    return res;
}

static int jacobi_iters(const Problem *p, const double *b)
{
    InvApprox *J = NULL;
    double *x = vec_new(len_of(p));
    int st = inv_create(&inv_block_jacobi_ops, NULL, &J);
    st = st ? st : inv_setup(J, &p->in);
    CHECK(st == MPM_OK, "block Jacobi on %s: %s", p->name, mpm_last_error());
    int it = run_pcg(p, J, b, x).iters;
    inv_destroy(J);
    free(x);
    return it;
}

/* b: a projected random vector (seed 21); x: H x = b from block-Jacobi PCG to
 * 1e-13 of the initial preconditioned residual (the exact solution a
 * multigrid cycle is measured against) */
static void reference_solution(const Problem *p, double *b, double *x)
{
    synth_random_vector(p->n, 21, b);
    projection_apply(p->proj, b);
    InvApprox *J = NULL;
    int st = inv_create(&inv_block_jacobi_ops, NULL, &J);
    st = st ? st : inv_setup(J, &p->in);
    PcgWork w = {0};
    PcgResult res;
    PcgOptions o = {.stop = PCG_ABSOLUTE, .abs_tol = 0.0, .max_iters = 0};
    st = st ? st : pcg_solve(p->op, J, p->proj, b, x, &o, &w, &res);
    o.max_iters = 100000;
    o.abs_tol = 1e-13 * res.rho0;
    st = st ? st : pcg_solve(p->op, J, p->proj, b, x, &o, &w, &res);
    CHECK(st == MPM_OK && !res.capped && rel_residual(p->A, b, x) < 1e-11, "reference solution on %s: %s", p->name,
          mpm_last_error());
    pcg_work_free(&w);
    inv_destroy(J);
}

/* ---------------------------------------------------------------------------
 * The rows: what differs between adapters
 * ------------------------------------------------------------------------- */

typedef struct AdapterRow AdapterRow;

typedef struct {
    const char *what; /* NULL ends the list */
    int (*matvec)(InvApprox *self, const double *x, double *y);
    double tol; /* max |A_lib x - H x| <= tol * max |H x| */
} MatrixView;

typedef struct {
    SynthProblem *synth, *other; /* the synthetic problem and one on other nodes */
    const Problem *mpm;          /* the MPM Hessian, NULL when it could not be built */
    MpmHessian *hessian;
} Problems;

static void mpm_hessian_options(FixtureOptions *o);
static int mpm_hessian_build(MpmHessian *h, Problem *out, const FixtureOptions *opts);
static void mpm_hessian_free(MpmHessian *h);

struct AdapterRow {
    const char *name; /* as in adapters/adapter_list.h */
    int exact;        /* apply solves H z = r (a factorisation); else it is one multigrid cycle */
    double sym_tol;   /* |x^T M y - y^T M x| <= sym_tol * sqrt(|x^T M x| |y^T M y|) */
    double mpm_pcg_factor; /* on the MPM Hessian: iterations * factor < block Jacobi's (not for exact) */
    int (*hierarchy)(const InvApprox *self, int *levels, double *op_complexity); /* NULL: none */
    MatrixView views[3];
    const char *const *variants;     /* option lists ("k=v,k=v") that must precondition well */
    const char *const *refused;      /* option lists create must refuse, naming the first key */
    const char *const *mpm_variants; /* option lists that must set up on the MPM Hessian */
    void (*own_checks)(const AdapterRow *row, const InvApproxOps *ops, Problems *pr);
};

static InvApprox *create(const InvApproxOps *ops, const char *opts)
{
    SolverOptions o;
    memset(&o, 0, sizeof o);
    InvApprox *M = NULL;
    int st = solver_opts_set_list(&o, opts, "test");
    st = st ? st : inv_create(ops, &o, &M);
    CHECK(st == MPM_OK && M, "%s create (%s): %s", ops->name, opts, mpm_last_error());
    return st ? NULL : M;
}

/* created and set up on p, or NULL (after a failed CHECK) */
static InvApprox *ready(const InvApproxOps *ops, const char *opts, const Problem *p)
{
    InvApprox *M = create(ops, opts);
    if (!M) return NULL;
    int st = inv_setup(M, &p->in);
    CHECK(st == MPM_OK, "%s (%s) setup on %s: %s", ops->name, opts, p->name, mpm_last_error());
    if (st) {
        inv_destroy(M);
        return NULL;
    }
    return M;
}

/* ---------------------------------------------------------------------------
 * The checks
 * ------------------------------------------------------------------------- */

static void check_create(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    CHECK(!strcmp(ops->name, row->name), "inv_%s_ops is named '%s'", row->name, ops->name);
    InvApprox *M = ready(ops, "", &p);
    if (!M) return;
    CHECK(M->ops == ops && (M->caps & INV_NEEDS_HESSIAN), "%s: ops and caps (0x%x)", row->name, M->caps);
    if (row->hierarchy) {
        int levels = 0;
        double cx = 0.0;
        CHECK(row->hierarchy(M, &levels, &cx) == MPM_OK && levels >= 2 && cx >= 1.0,
              "%s hierarchy: %d levels, complexity %g", row->name, levels, cx);
        printf("%s: %d levels, operator complexity %.2f, setup %.3f s\n", row->name, levels, cx, M->stats.setup_s);
    }
    inv_destroy(M);
}

static void shows_matrix_on(const AdapterRow *row, const InvApproxOps *ops, const Problem *p)
{
    InvApprox *M = ready(ops, "", p);
    if (!M) return;
    size_t len = len_of(p);
    double *x = vec_new(len), *y = vec_new(len), *z = vec_new(len);
    synth_random_vector(p->n, 13, x);
    bsr_spmv(p->A, x, y);
    for (const MatrixView *v = row->views; v->what; ++v) {
        int st = v->matvec(M, x, z);
        double ny = 0.0, d = max_abs_diff(len, z, y, &ny);
        CHECK(st == MPM_OK && d <= v->tol * ny, "%s's %s on %s: max |A_lib x - H x| = %g (max %g, bound %g): %s",
              row->name, v->what, p->name, d, ny, v->tol, mpm_last_error());
    }
    inv_destroy(M);
    free(x);
    free(y);
    free(z);
}

static void check_shows_matrix(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    shows_matrix_on(row, ops, &p);
    if (pr->mpm) shows_matrix_on(row, ops, pr->mpm);
}

/* exact: one application solves; a cycle: halves the A-norm error */
static void check_one_apply(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *x = vec_new(len), *z = vec_new(len), *e = vec_new(len);
    reference_solution(&p, b, x);
    InvApprox *M = ready(ops, "", &p);
    if (M) {
        int st = inv_apply(M, b, z);
        CHECK(st == MPM_OK, "%s apply: %s", row->name, mpm_last_error());
        if (row->exact) {
            double res = rel_residual(p.A, b, z);
            CHECK(res < 1e-10, "%s solve: ||Hz-b||/||b|| = %g", row->name, res);
            printf("%s: one application solves, ||Hz-b||/||b|| = %.2e (%.4f s)\n", row->name, res, M->stats.apply_s);
        } else {
            for (size_t k = 0; k < len; ++k) e[k] = x[k] - z[k];
            double red = a_norm(p.A, e) / a_norm(p.A, x);
            CHECK(red < 0.5, "%s, one cycle: ||x - Mb||_A / ||x||_A = %g", row->name, red);
            printf("%s: one cycle %.4f s, A-norm error after it %.3f\n", row->name, M->stats.apply_s, red);
        }
        inv_destroy(M);
    }
    free(b);
    free(x);
    free(z);
    free(e);
}

static void check_dirichlet(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *z = vec_new(len);
    synth_random_vector(p.n, 21, b);
    projection_apply(p.proj, b);
    InvApprox *M = ready(ops, "", &p);
    if (M) {
        int st = inv_apply(M, b, z);
        double worst = 0.0;
        for (int i = 0; i < p.n; ++i)
            if (p.fixed[i]) worst = fmax(worst, fabs(z[3 * i]) + fabs(z[3 * i + 1]) + fabs(z[3 * i + 2]));
        CHECK(st == MPM_OK && worst <= 1e-14 * vec_norm(len, z),
              "%s: the Dirichlet entries of M b must vanish for a projected b (largest %g, ||Mb|| %g)", row->name,
              worst, vec_norm(len, z));
        inv_destroy(M);
    }
    free(b);
    free(z);
}

/* x^T M y vs y^T M x and x^T M x > 0 over three pairs (the first projected, as PCG sees them) */
static void symmetric_positive_on(const AdapterRow *row, const InvApproxOps *ops, const Problem *p)
{
    InvApprox *M = ready(ops, "", p);
    if (!M) return;
    size_t len = len_of(p);
    double *x = vec_new(len), *y = vec_new(len), *Mx = vec_new(len), *My = vec_new(len);
    for (int trial = 0; trial < 3; ++trial) {
        synth_random_vector(p->n, 300 + (unsigned)trial, x);
        synth_random_vector(p->n, 400 + (unsigned)trial, y);
        if (trial == 0) {
            projection_apply(p->proj, x);
            projection_apply(p->proj, y);
        }
        int st = inv_apply(M, x, Mx);
        st |= inv_apply(M, y, My);
        double xMy = vec_dot(len, x, My), yMx = vec_dot(len, y, Mx), xMx = vec_dot(len, x, Mx);
        double scale = sqrt(fabs(xMx) * fabs(vec_dot(len, y, My)));
        CHECK(st == MPM_OK && fabs(xMy - yMx) <= row->sym_tol * scale,
              "%s symmetry on %s: x^T M y %.17g vs y^T M x %.17g (scale %g, bound %g)", row->name, p->name, xMy, yMx,
              scale, row->sym_tol);
        CHECK(xMx > 0.0, "%s positivity on %s: x^T M x = %g", row->name, p->name, xMx);
        if (trial == 0)
            printf("%s on %s: |x^T M y - y^T M x| / scale = %.2e\n", row->name, p->name, fabs(xMy - yMx) / scale);
    }
    inv_destroy(M);
    free(x);
    free(y);
    free(Mx);
    free(My);
}

static void check_symmetric_positive(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    symmetric_positive_on(row, ops, &p);
    if (pr->mpm) symmetric_positive_on(row, ops, pr->mpm);
}

static void check_deterministic(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *z1 = vec_new(len), *z2 = vec_new(len);
    synth_random_vector(p.n, 21, b);
    InvApprox *M = ready(ops, "", &p);
    if (M) {
        int st = inv_apply(M, b, z1);
        st |= inv_apply(M, b, z2);
        CHECK(st == MPM_OK && memcmp(z1, z2, sizeof(double) * len) == 0, "%s: repeated application differs",
              row->name);
        inv_destroy(M);
    }
    free(b);
    free(z1);
    free(z2);
}

/* PCG with it against PCG with block Jacobi, on the synthetic problem and the MPM Hessian */
static void check_pcg(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *x = vec_new(len);
    synth_random_vector(p.n, 21, b);
    projection_apply(p.proj, b);
    int rj = jacobi_iters(&p, b);
    InvApprox *M = ready(ops, "", &p);
    if (M) {
        M->stats.apply_s = 0.0;
        PcgResult ra = run_pcg(&p, M, b, x);
        double res = rel_residual(p.A, b, x);
        printf("%s on %s: PCG to 1e-8 %d iterations (block Jacobi %d), residual %.1e, %.4f s per application\n",
               row->name, p.name, ra.iters, rj, res, M->stats.apply_s / (ra.iters + 1));
        CHECK(ra.iters * 4 < rj, "%s-PCG (%d) should need far fewer iterations than Jacobi-PCG (%d)", row->name,
              ra.iters, rj);
        CHECK(res < 1e-6, "%s-PCG solution residual %g", row->name, res);
        inv_destroy(M);
    }
    free(b);
    free(x);
    if (!pr->mpm) return;
    const Problem *h = pr->mpm;
    x = vec_new(len_of(h));
    M = ready(ops, "", h);
    if (M) {
        if (row->exact) {
            int st = inv_apply(M, pr->hessian->b, x);
            double res = rel_residual(h->A, pr->hessian->b, x);
            CHECK(st == MPM_OK && res < 1e-10, "%s on the MPM Hessian: %s, residual %g", row->name, mpm_last_error(),
                  res);
            printf("%s on the MPM Hessian: setup %.3f s, apply %.4f s, residual %.1e\n", row->name, M->stats.setup_s,
                   M->stats.apply_s, res);
        } else {
            PcgResult ra = run_pcg(h, M, pr->hessian->b, x);
            double res = rel_residual(h->A, pr->hessian->b, x);
            int levels = 0;
            double cx = 0.0;
            if (row->hierarchy) row->hierarchy(M, &levels, &cx);
            printf("%s on the MPM Hessian: PCG to 1e-8 %d iterations (block Jacobi %d; %d levels, complexity %.2f, "
                   "setup %.3f s), residual %.1e\n",
                   row->name, ra.iters, pr->hessian->jacobi_iters, levels, cx, M->stats.setup_s, res);
            CHECK(ra.iters * row->mpm_pcg_factor < pr->hessian->jacobi_iters && res < 1e-6,
                  "%s-PCG (%d iterations, residual %g) vs Jacobi-PCG (%d) on the MPM Hessian (factor %g)", row->name,
                  ra.iters, res, pr->hessian->jacobi_iters, row->mpm_pcg_factor);
        }
        inv_destroy(M);
    }
    free(x);
}

/* set up again on new values: as a fresh object; a new pattern and back: PCG converges on each */
static void check_resetup(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *x = vec_new(len), *z = vec_new(len), *y = vec_new(len);
    synth_random_vector(p.n, 21, b);
    projection_apply(p.proj, b);
    InvApprox *M = ready(ops, "", &p);
    if (!M) goto out;

    /* new values, same object: the same application as a fresh object's (a
     * cached eigenvalue estimate, factor or hierarchy of the old values would differ) */
    shift_diagonal(pr->synth, 50.0);
    int st = inv_setup(M, &p.in);
    st |= inv_apply(M, b, z);
    InvApprox *F = ready(ops, "", &p);
    if (F) {
        st |= inv_apply(F, b, y);
        double ny = 0.0, d = max_abs_diff(len, z, y, &ny);
        CHECK(st == MPM_OK && d <= 1e-14 * ny, "%s re-setup on new values: max |M_reused b - M_fresh b| = %g (max %g)",
              row->name, d, ny);
        inv_destroy(F);
    }
    PcgResult r = run_pcg(&p, M, b, x);
    CHECK(rel_residual(p.A, b, x) < 1e-6, "%s-PCG after a re-setup on new values (%d iterations)", row->name, r.iters);
    shift_diagonal(pr->synth, -50.0);

    /* a new pattern, then back */
    Problem q = problem_of_synth(pr->other, "the other nodes");
    double *bq = vec_new(len_of(&q)), *xq = vec_new(len_of(&q));
    synth_random_vector(q.n, 9, bq);
    projection_apply(q.proj, bq);
    st = inv_setup(M, &q.in);
    CHECK(st == MPM_OK, "%s setup on a new pattern: %s", row->name, mpm_last_error());
    if (!st) {
        r = run_pcg(&q, M, bq, xq);
        CHECK(rel_residual(q.A, bq, xq) < 1e-6, "%s-PCG on the new pattern (%d iterations)", row->name, r.iters);
    }
    st = inv_setup(M, &p.in);
    CHECK(st == MPM_OK, "%s setup back on the first pattern: %s", row->name, mpm_last_error());
    if (!st) {
        r = run_pcg(&p, M, b, x);
        CHECK(rel_residual(p.A, b, x) < 1e-6, "%s-PCG back on the first pattern (%d iterations)", row->name, r.iters);
    }
    free(bq);
    free(xq);
    inv_destroy(M);
out:
    free(b);
    free(x);
    free(z);
    free(y);
}

static void check_refusals(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *x = vec_new(len);
    synth_random_vector(p.n, 21, b);
    InvApprox *M = ready(ops, "", &p);
    if (M) {
        InvSetupInput mf = p.in;
        mf.H = NULL;
        mpm_clear_error();
        CHECK(inv_setup(M, &mf) == MPM_EINTERNAL, "%s: matrix-free input must be refused", row->name);
        mpm_clear_error();
        CHECK(inv_apply(M, b, x) == MPM_EINTERNAL, "%s: apply after a failed setup must fail", row->name);
        mpm_clear_error();
        inv_destroy(M);
    }
    for (const char *const *bad = row->refused; bad && *bad; ++bad) {
        SolverOptions o;
        memset(&o, 0, sizeof o);
        solver_opts_set_list(&o, *bad, "test");
        InvApprox *V = NULL;
        mpm_clear_error();
        int st = inv_create(ops, &o, &V);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), o.key[0]) && !strchr(mpm_last_error(), '\n'),
              "%s %s must be refused in one line naming %s: %d '%s'", row->name, *bad, o.key[0], st,
              mpm_last_error());
        inv_destroy(V);
        mpm_clear_error();
    }
    free(b);
    free(x);
}

static void check_variants(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    Problem p = problem_of_synth(pr->synth, "the synthetic slab");
    size_t len = len_of(&p);
    double *b = vec_new(len), *x = vec_new(len);
    synth_random_vector(p.n, 21, b);
    projection_apply(p.proj, b);
    for (const char *const *v = row->variants; v && *v; ++v) {
        InvApprox *M = ready(ops, *v, &p);
        if (!M) continue;
        PcgResult r = run_pcg(&p, M, b, x);
        double res = rel_residual(p.A, b, x);
        printf("%s %s: setup %.3f s, PCG %d iterations\n", row->name, *v, M->stats.setup_s, r.iters);
        CHECK(res < 1e-6, "%s %s: PCG residual %g", row->name, *v, res);
        inv_destroy(M);
    }
    for (const char *const *v = row->mpm_variants; pr->mpm && v && *v; ++v) {
        InvApprox *M = ready(ops, *v, pr->mpm);
        if (!M) continue;
        double *xh = vec_new(len_of(pr->mpm));
        PcgResult r = run_pcg(pr->mpm, M, pr->hessian->b, xh);
        printf("%s %s on the MPM Hessian: setup %.3f s, PCG %d iterations, residual %.1e\n", row->name, *v,
               M->stats.setup_s, r.iters, rel_residual(pr->mpm->A, pr->hessian->b, xh));
        free(xh);
        inv_destroy(M);
    }
    free(b);
    free(x);
}

static void check_own(const AdapterRow *row, const InvApproxOps *ops, Problems *pr) { row->own_checks(row, ops, pr); }

static int always(const AdapterRow *row) { return row != NULL; }
static int has_views(const AdapterRow *row) { return row->views[0].what != NULL; }
static int has_options(const AdapterRow *row) { return row->variants || row->mpm_variants; }
static int has_own(const AdapterRow *row) { return row->own_checks != NULL; }

static const struct {
    const char *name;
    int (*applies)(const AdapterRow *row);
    void (*run)(const AdapterRow *row, const InvApproxOps *ops, Problems *pr);
} CHECKS[] = {
    {"create", always, check_create},
    {"shows H", has_views, check_shows_matrix},
    {"one apply", always, check_one_apply},
    {"Dirichlet", always, check_dirichlet},
    {"sym-pos", always, check_symmetric_positive},
    {"deterministic", always, check_deterministic},
    {"PCG", always, check_pcg},
    {"re-setup", always, check_resetup},
    {"refusals", always, check_refusals},
    {"variants", has_options, check_variants},
    {"own checks", has_own, check_own},
};
#define N_CHECKS (sizeof CHECKS / sizeof CHECKS[0])

/* ---------------------------------------------------------------------------
 * CHOLMOD's own checks
 * ------------------------------------------------------------------------- */
#if MPM_WITH_CHOLMOD
/* A chain of n nodes, block-tridiagonal with dense 3x3 blocks: minimum
 * degree ordering eliminates the chain from its ends without fill, so the
 * factor holds exactly the lower triangle, 6 n + 9 (n - 1) entries; a
 * factor that dropped or duplicated blocks of A would not. The solve must
 * be exact too. */
static void cholmod_chain(void)
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
    double *diag = vec_new(9 * (size_t)n), *b = vec_new(3 * (size_t)n), *x = vec_new(3 * (size_t)n);
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

/* The symbolic analysis is reused for an unchanged pattern and redone for a
 * new one; an indefinite matrix fails setup naming the node, apply then
 * fails, and the next setup recovers. */
static void cholmod_own_checks(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    cholmod_chain();
    SynthProblem *sp = pr->synth;
    Problem p = problem_of_synth(sp, "the synthetic slab");
    const size_t len = len_of(&p);
    double *b = vec_new(len), *x = vec_new(len);
    synth_random_vector(p.n, 7, b);
    InvApprox *C = ready(ops, "", &p);
    if (!C) goto out;
    double lnz = 0.0;
    int n_an = -1;
    cholmod_direct_info(C, &lnz, &n_an);
    CHECK(n_an == 1, "one analysis after the first setup, got %d", n_an);
    /* L's pattern holds tril(A)'s: a factor of fewer entries dropped some of A */
    CHECK(lnz >= (double)(9 * sp->A.nnzb + 3 * sp->n) / 2, "factor nnz %g smaller than the lower triangle", lnz);
    printf("cholmod: %d nodes, factor nnz %.4g (%.1f x nnz(tril A)), setup %.3f s\n", p.n, lnz,
           lnz / ((9.0 * (double)sp->A.nnzb + 3.0 * sp->n) / 2.0), C->stats.setup_s);

    /* same pattern, new values: numeric refactorisation only */
    shift_diagonal(sp, 0.5);
    int st = inv_setup(C, &p.in);
    cholmod_direct_info(C, NULL, &n_an);
    CHECK(st == MPM_OK && n_an == 1, "same pattern must not re-analyse: status %d, analyses %d", st, n_an);
    st = inv_apply(C, b, x);
    CHECK(st == MPM_OK && rel_residual(p.A, b, x) < 1e-10, "refactorised solve: ||Ax-b||/||b|| = %g",
          rel_residual(p.A, b, x));
    shift_diagonal(sp, -0.5);

    /* new pattern: new analysis */
    Problem q = problem_of_synth(pr->other, "the other nodes");
    st = inv_setup(C, &q.in);
    cholmod_direct_info(C, NULL, &n_an);
    CHECK(st == MPM_OK && n_an == 2, "new pattern must re-analyse: status %d, analyses %d", st, n_an);
    double *bq = vec_new(len_of(&q)), *xq = vec_new(len_of(&q));
    synth_random_vector(q.n, 8, bq);
    st = inv_apply(C, bq, xq);
    CHECK(st == MPM_OK && rel_residual(q.A, bq, xq) < 1e-10, "solve after the pattern change: ||Ax-b||/||b|| = %g",
          rel_residual(q.A, bq, xq));
    free(bq);
    free(xq);

    /* back to the big matrix (storage grows again), made indefinite */
    int node = -1;
    for (int i = p.n / 2; i < p.n && node < 0; ++i)
        if (!p.fixed[i]) node = i;
    int64_t k = bsr_find(p.A, node, node);
    double saved[9];
    memcpy(saved, p.A->val + 9 * k, sizeof saved);
    for (int d = 0; d < 9; ++d) p.A->val[9 * k + d] = -saved[d]; /* symmetric, not positive definite */
    mpm_clear_error();
    st = inv_setup(C, &p.in);
    char want[32];
    snprintf(want, sizeof want, "node %d ", node);
    CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "not positive definite") && strstr(mpm_last_error(), want),
          "indefinite matrix: status %d, message '%s'", st, mpm_last_error());
    printf("cholmod on an indefinite matrix (node %d negated): '%s'\n", node, mpm_last_error());
    cholmod_direct_info(C, NULL, &n_an);
    CHECK(n_an == 3, "pattern back: analyses %d", n_an);
    mpm_clear_error();
    st = inv_apply(C, b, x);
    CHECK(st == MPM_EINTERNAL, "apply after a failed setup must fail, got %d", st);
    mpm_clear_error();
    memcpy(p.A->val + 9 * k, saved, sizeof saved);
    st = inv_setup(C, &p.in);
    st |= inv_apply(C, b, x);
    double res = rel_residual(p.A, b, x);
    cholmod_direct_info(C, NULL, &n_an);
    CHECK(st == MPM_OK && res < 1e-10 && n_an == 4, "recovery after failure: status %d, residual %g, analyses %d", st,
          res, n_an);
    CHECK(cholmod_direct_info(NULL, NULL, NULL) == MPM_EINTERNAL, "info on NULL");
    mpm_clear_error();
    inv_destroy(C);
out:
    free(b);
    free(x);
}
#endif

/* ---------------------------------------------------------------------------
 * ML's own checks
 * ------------------------------------------------------------------------- */
#if MPM_WITH_ML
/* ml_levels=1 is one level: a direct solve (KLU on the whole matrix). The
 * null space ML is given: an unconstrained elastic MPM Hessian at rest
 * (F = I, no velocity, no gravity: zero stress) annihilates translations and
 * infinitesimal rotations of the node positions. H = M + dt^2 K (SPEC 3), so
 * K v = (H v - M v) / dt^2 must vanish to round-off for each of the 6 modes,
 * while a generic vector is not annihilated. */
static void ml_own_checks(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    {
        Problem p = problem_of_synth(pr->synth, "the synthetic slab");
        double *b = vec_new(len_of(&p)), *x = vec_new(len_of(&p));
        synth_random_vector(p.n, 21, b);
        projection_apply(p.proj, b);
        InvApprox *V = ready(ops, "ml_levels=1,ml_sweeps=1", &p);
        if (V) {
            int levels = 0;
            double cx = 0.0;
            PcgResult r = run_pcg(&p, V, b, x);
            ml_info(V, &levels, &cx);
            CHECK(levels == 1 && r.iters <= 2, "ml_levels=1 is a direct solve: %d levels, %d iterations", levels,
                  r.iters);
            inv_destroy(V);
        }
        free(b);
        free(x);
    }
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
    double *zero = vec_new(len), *ns = vec_new(6 * len), *Hv = vec_new(len), *Kv = vec_new(len);
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

/* ---------------------------------------------------------------------------
 * PETSc's own checks
 * ------------------------------------------------------------------------- */
#if MPM_WITH_PETSC
/* PCG iterations to 1e-8 on the MPM Hessian with `opts` (-1 when it did not set up) */
static int petsc_pcg_iters(const InvApproxOps *ops, const char *opts, Problems *pr, double *setup_s)
{
    InvApprox *M = ready(ops, opts, pr->mpm);
    if (!M) return -1;
    double *x = vec_new(len_of(pr->mpm));
    PcgResult r = run_pcg(pr->mpm, M, pr->hessian->b, x);
    double res = rel_residual(pr->mpm->A, pr->hessian->b, x);
    CHECK(res < 1e-6, "petsc %s on the MPM Hessian: PCG residual %g", opts, res);
    if (setup_s) *setup_s = M->stats.setup_s;
    free(x);
    inv_destroy(M);
    return r.iters;
}

/* one application of `opts` on the MPM Hessian's gradient (x: 3n) */
static int petsc_solve_once(const InvApproxOps *ops, const char *opts, Problems *pr, double *x)
{
    InvApprox *M = ready(ops, opts, pr->mpm);
    if (!M) return MPM_EINTERNAL;
    int st = inv_apply(M, pr->hessian->b, x);
    CHECK(st == MPM_OK, "petsc %s apply: %s", opts, mpm_last_error());
    inv_destroy(M);
    return st;
}

/* The preset's options (experiments/driver/registry.c, pn-gamg-pcg) */
#define PETSC_GAMG "pc_type=gamg,pc_gamg_agg_nsmooths=0,mg_levels_ksp_type=chebyshev,mg_levels_pc_type=jacobi"
/* hypre through PETSc with the boomeramg adapter's defaults (adapters/boomeramg.c) */
#define PETSC_HYPRE                                                                                                 \
    "pc_type=hypre,pc_hypre_type=boomeramg,pc_hypre_boomeramg_strong_threshold=0.5,"                                \
    "pc_hypre_boomeramg_coarsen_type=HMIS,pc_hypre_boomeramg_nodal_coarsen=4,pc_hypre_boomeramg_interp_type=ext+i," \
    "pc_hypre_boomeramg_P_max=4,pc_hypre_boomeramg_relax_type_all=symmetric-SOR/Jacobi,"                         \
    "pc_hypre_boomeramg_relax_type_coarse=Gaussian-elimination,pc_hypre_boomeramg_grid_sweeps_all=1,"              \
    "pc_hypre_boomeramg_no_CF=1"
/* ML through PETSc with the ml adapter's aggregation options (adapters/ml.c) */
#define PETSC_ML                                                                                        \
    "pc_type=ml,pc_ml_maxNlevels=10,pc_ml_maxCoarseSize=512,pc_ml_CoarsenScheme=Uncoupled,pc_ml_Threshold=0," \
    "pc_ml_DampingFactor=1.3333333333333333,pc_ml_nullspace=user,mg_levels_ksp_type=chebyshev,"             \
    "mg_levels_pc_type=jacobi,mg_levels_ksp_max_it=2"

/* z = M b with `opts` on the MPM Hessian, and M's levels (0: failed) */
static int apply_once(const InvApproxOps *ops, const char *opts, Problems *pr, double *z, int *levels)
{
    InvApprox *M = ready(ops, opts, pr->mpm);
    if (!M) return MPM_EINTERNAL;
    int st = inv_apply(M, pr->hessian->b, z);
    CHECK(st == MPM_OK, "%s %s apply: %s", ops->name, opts, mpm_last_error());
    InvView v;
    memset(&v, 0, sizeof v);
    inv_view(M, NULL, &v);
    *levels = v.n_levels;
    inv_destroy(M);
    return st;
}

static void petsc_pcmg_checks(const InvApproxOps *ops, Problems *pr)
{
    const size_t len = len_of(pr->mpm);
    /* coarse_exact: the coarse CG to 1e-12, so both cycles are fixed maps;
     * then the adaptive one (the same CG iterations, the same cycle) */
    static const char *const pairs[][2] = {
        {"coarse_exact=1,min_coarse_nodes=100", "petsc_hierarchy=linear,petsc_coarse_exact=1,petsc_min_coarse_nodes=100"},
        {"min_coarse_nodes=100", "petsc_hierarchy=linear,petsc_min_coarse_nodes=100"},
        {"embedding=quadratic,min_coarse_nodes=100,sweeps=2",
         "petsc_hierarchy=quadratic,petsc_min_coarse_nodes=100,petsc_sweeps=2"}};
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; ++k) {
        double *z_mg = vec_new(len), *z_petsc = vec_new(len);
        int l_mg = 0, l_petsc = 0;
        if (!apply_once(&inv_mg_ops, pairs[k][0], pr, z_mg, &l_mg) &&
            !apply_once(ops, pairs[k][1], pr, z_petsc, &l_petsc)) {
            double zmax = 0.0, diff = max_abs_diff(len, z_petsc, z_mg, &zmax);
            printf("PCMG with the SGS shell smoother (%s) against the in-house V-cycle (%s): %d and %d levels, "
                   "max |z_petsc - z_mg| / max |z_mg| = %.1e\n",
                   pairs[k][1], pairs[k][0], l_petsc, l_mg, diff / zmax);
            CHECK(l_mg >= 3 && l_petsc == l_mg, "PCMG levels %d, in-house %d (at least 3 expected)", l_petsc, l_mg);
            CHECK(zmax > 0 && diff <= 1e-12 * zmax, "PCMG (%s) against the in-house V-cycle: max difference %g (max %g)",
                  pairs[k][1], diff, zmax);
        }
        free(z_mg);
        free(z_petsc);
    }
    /* as a PCG preconditioner: the in-house cycle's iterations, and with
     * PETSc's own smoothers a preconditioner far better than block Jacobi */
    int mg = petsc_pcg_iters(&inv_mg_ops, "min_coarse_nodes=100", pr, NULL);
    int pcmg = petsc_pcg_iters(ops, "petsc_hierarchy=linear,petsc_min_coarse_nodes=100", pr, NULL);
    /* PETSc's default level smoothers (Chebyshev with SOR, 2 iterations) */
    int cheb = petsc_pcg_iters(ops, "petsc_hierarchy=linear,petsc_min_coarse_nodes=100,petsc_smoother=petsc", pr, NULL);
    printf("PCG to 1e-8 on the MPM Hessian: in-house V-cycle %d iterations, PCMG with the SGS shell %d, PCMG with "
           "PETSc's default smoothers (Chebyshev/SOR) %d, block Jacobi %d\n",
           mg, pcmg, cheb, pr->hessian->jacobi_iters);
    CHECK(mg > 0 && pcmg == mg, "PCG with PCMG (%d iterations) and with the in-house V-cycle (%d)", pcmg, mg);
    CHECK(cheb > 0 && 3 * cheb < pr->hessian->jacobi_iters, "PCMG with PETSc's smoothers: %d PCG iterations, block "
          "Jacobi %d", cheb, pr->hessian->jacobi_iters);
}

static void petsc_own_checks(const AdapterRow *row, const InvApproxOps *ops, Problems *pr)
{
    (void)row;
    if (!pr->mpm) return;
    const size_t len = len_of(pr->mpm);

    /* GAMG with the rigid-body modes against Jacobi on an elasticity
     * fixture: one material, dt 0.2 (stiffness well above the mass), a
     * sticky bottom layer; and on the two-material Hessian */
    FixtureOptions eo;
    mpm_hessian_options(&eo);
    eo.two_materials = 0;
    eo.F_noise = 0.05;
    eo.dt = 0.2;
    MpmHessian eh;
    Problem ep;
    if (mpm_hessian_build(&eh, &ep, &eo) == MPM_OK) {
        Problems epr = *pr;
        epr.mpm = &ep;
        epr.hessian = &eh;
        int gamg = petsc_pcg_iters(ops, PETSC_GAMG, &epr, NULL);
        int plain = petsc_pcg_iters(ops, PETSC_GAMG ",petsc_rbm=off", &epr, NULL);
        int jacobi = petsc_pcg_iters(ops, "pc_type=jacobi", &epr, NULL);
        printf("petsc on the elasticity fixture, PCG to 1e-8: GAMG with rigid-body modes %d iterations, without %d, "
               "PETSc's Jacobi %d (block Jacobi %d)\n",
               gamg, plain, jacobi, eh.jacobi_iters);
        CHECK(gamg > 0 && jacobi > 0 && 3 * gamg < jacobi,
              "GAMG with rigid-body modes (%d iterations) must need far fewer than Jacobi (%d) on the elasticity "
              "fixture",
              gamg, jacobi);
        mpm_hessian_free(&eh);
    }
    {
        int gamg = petsc_pcg_iters(ops, PETSC_GAMG, pr, NULL), jacobi = petsc_pcg_iters(ops, "pc_type=jacobi", pr, NULL);
        printf("petsc on the two-material MPM Hessian: GAMG %d iterations, PETSc's Jacobi %d\n", gamg, jacobi);
        CHECK(gamg > 0 && jacobi > 0 && 2 * gamg < jacobi, "GAMG (%d) vs Jacobi (%d) on the MPM Hessian", gamg, jacobi);
    }

    /* exact solves: PETSc's LU and Cholesky, MUMPS; against each other and CHOLMOD */
    static const char *const direct[] = {"pc_type=lu", "pc_type=cholesky", "pc_type=lu,pc_factor_mat_solver_type=mumps",
                                         "petsc_mat_type=baij,pc_type=lu"};
    enum { N_DIRECT = sizeof direct / sizeof direct[0] };
    double *z[N_DIRECT + 1];
    for (int d = 0; d <= N_DIRECT; ++d) z[d] = vec_new(len);
    int have_ref = 0;
#if MPM_WITH_CHOLMOD
    have_ref = petsc_solve_once(&inv_cholmod_ops, "", pr, z[N_DIRECT]) == MPM_OK;
#endif
    for (int d = 0; d < N_DIRECT; ++d) {
        if (petsc_solve_once(ops, direct[d], pr, z[d])) continue;
        double res = rel_residual(pr->mpm->A, pr->hessian->b, z[d]);
        double zmax = 0.0, diff = have_ref ? max_abs_diff(len, z[d], z[N_DIRECT], &zmax) : 0.0;
        printf("petsc %s on the MPM Hessian: ||Hz-b||/||b|| = %.1e%s", direct[d], res, have_ref ? "" : "\n");
        if (have_ref) printf(", max |z - z_cholmod| / max |z_cholmod| = %.1e\n", diff / zmax);
        CHECK(res < 1e-10, "petsc %s: residual %g", direct[d], res);
        CHECK(!have_ref || diff <= 1e-9 * zmax, "petsc %s against CHOLMOD: max difference %g (max %g)", direct[d], diff,
              zmax);
    }
    for (int d = 0; d <= N_DIRECT; ++d) free(z[d]);

    /* a complete solve (a KSP with its own type) inside PCG: one or two outer iterations */
    int inner = petsc_pcg_iters(ops, "ksp_type=cg,ksp_rtol=1e-10," PETSC_GAMG, pr, NULL);
    CHECK(inner >= 0 && inner <= 2, "petsc ksp_type=cg to 1e-10 as the preconditioner: %d PCG iterations", inner);

    /* the cross-checks: PETSc's hypre and ML against the direct adapters with the same options */
#if MPM_WITH_HYPRE
    {
        int via = petsc_pcg_iters(ops, PETSC_HYPRE, pr, NULL), direct_amg = petsc_pcg_iters(&inv_boomeramg_ops, "", pr, NULL);
        printf("cross-check, PCG to 1e-8 on the MPM Hessian: PETSc pc_type=hypre %d iterations, the boomeramg adapter "
               "%d\n",
               via, direct_amg);
        CHECK(via > 0 && via == direct_amg, "PETSc's hypre (%d) and the boomeramg adapter (%d) with the same options",
              via, direct_amg);
    }
#endif
#if MPM_WITH_ML
    {
        int via = petsc_pcg_iters(ops, PETSC_ML, pr, NULL), direct_ml = petsc_pcg_iters(&inv_ml_ops, "", pr, NULL);
        printf("cross-check, PCG to 1e-8 on the MPM Hessian: PETSc pc_type=ml %d iterations, the ml adapter %d\n", via,
               direct_ml);
        CHECK(via > 0, "PETSc's ML: %d", via);
    }
#endif

    /* HOT's hierarchy as a PCMG against the in-house V-cycle (solvers/mg):
     * the same levels, with mpmbench's coloured SGS as the PCSHELL smoother
     * the same cycle to round-off; with PETSc's smoothers a working one */
    petsc_pcmg_checks(ops, pr);

    /* the copy into PETSc's storage against one SpMV: a second setup on the
     * same pattern refills the values only (pc_type=none: nothing else) */
    InvApprox *M = ready(ops, "pc_type=none", pr->mpm);
    if (M) {
        double *x = vec_new(len), *y = vec_new(len);
        synth_random_vector(pr->mpm->n, 5, x);
        double t0 = event_clock();
        for (int k = 0; k < 10; ++k) bsr_spmv(pr->mpm->A, x, y);
        double spmv = (event_clock() - t0) / 10;
        double setup = 1e300;
        for (int k = 0; k < 5; ++k) {
            inv_setup(M, &pr->mpm->in);
            setup = fmin(setup, M->stats.setup_s);
        }
        t0 = event_clock();
        for (int k = 0; k < 10; ++k) petsc_matvec(M, x, y);
        double petsc_spmv = (event_clock() - t0) / 10;
        printf("petsc: refilling the Mat (setup with pc_type=none, same pattern) %.2e s, one bsr_spmv %.2e s (%.1fx), "
               "PETSc's MatMult %.2e s\n",
               setup, spmv, setup / spmv, petsc_spmv);
        free(x);
        free(y);
        inv_destroy(M);
    }
}
#endif

/* ---------------------------------------------------------------------------
 * The rows
 * ------------------------------------------------------------------------- */
#if MPM_WITH_HYPRE
static const char *const boomeramg_variants[] = {"amg_coarsen=PMIS,amg_nodal=6",
                                                 "amg_coarsen=falgout,amg_nodal=0",
                                                 "amg_agg_levels=1,amg_strong_threshold=0.25",
                                                 "amg_relax=8,amg_sweeps=2",
                                                 "amg_rbm=2,amg_interp=0",
                                                 NULL};
static const char *const boomeramg_refused[] = {"amg_coarsen=RS",   "amg_nodal=5",     "amg_relax=4",
                                                "amg_strong_threshold=1.5", "amg_agg_levels=-1", "amg_sweeps=x",
                                                "amg_interp=10",    "amg_rbm=4",       "amg_max_levels=0",
                                                NULL};
/* nodal coarsening variants on the MPM Hessian (the default, amg_nodal=4, is the PCG check's) */
static const char *const boomeramg_mpm_variants[] = {"amg_nodal=6", "amg_nodal=1", "amg_nodal=0",
                                                     "amg_nodal=4,amg_rbm=2", NULL};
#endif
#if MPM_WITH_ML
static const char *const ml_variants[] = {"ml_smoother=sgs,ml_sweeps=1", "ml_smoother=chebyshev,ml_sweeps=4",
                                          "ml_rbm=off,ml_threshold=0.02", "ml_damping=0,ml_coarse_size=64",
                                          "ml_levels=1,ml_sweeps=1", NULL};
static const char *const ml_refused[] = {"ml_smoother=jacobi", "ml_sweeps=0",     "ml_sweeps=1.5",  "ml_levels=21",
                                         "ml_threshold=1",     "ml_threshold=-0.1", "ml_coarse_size=0",
                                         "ml_damping=2.5",     "ml_rbm=yes",      "ml_damping=nan", NULL};
#endif

#if MPM_WITH_PETSC
static const char *const petsc_variants[] = {PETSC_GAMG,
                                             "petsc_mat_type=baij,pc_type=hypre",
                                             "pc_type=ml",
                                             "pc_type=gamg,petsc_rbm=off",
                                             "pc_type=cholesky",
                                             "ksp_type=cg,ksp_rtol=1e-10",
                                             "petsc_hierarchy=linear",
                                             "petsc_hierarchy=linear,petsc_smoother=petsc,mg_levels_ksp_type=richardson,"
                                             "mg_levels_pc_type=sor",
                                             NULL};
static const char *const petsc_refused[] = {"pc_gamg_thresold=0.02", "pc_type=jacobi,pc_gamg_threshold=0.02",
                                            "pc_type=nosuch",        "pc_gamg_threshold=abc",
                                            "ksp_monitor=1",         "petsc_rbm=maybe",
                                            "petsc_mat_type=dense",
                                            /* HOT's hierarchy: its options only with it, and what it sets itself */
                                            "petsc_hierarchy=cubic",
                                            "pc_type=gamg,petsc_hierarchy=linear",
                                            "ksp_type=cg,petsc_hierarchy=linear",
                                            "mg_levels_ksp_type=chebyshev,petsc_hierarchy=linear",
                                            "mg_coarse_ksp_type=cg,petsc_hierarchy=linear,petsc_smoother=petsc",
                                            "petsc_coarse_tol=1,petsc_hierarchy=linear",
                                            "petsc_smoother=jacobi,petsc_hierarchy=linear", NULL};
static const char *const petsc_mpm_variants[] = {"pc_type=hypre", "pc_type=ml", NULL};
#endif

static const AdapterRow rows[] = {
#if MPM_WITH_CHOLMOD
    {.name = "cholmod", .exact = 1, .sym_tol = 1e-10, .own_checks = cholmod_own_checks},
#endif
#if MPM_WITH_HYPRE
    {.name = "boomeramg",
     .sym_tol = 1e-8,
     .mpm_pcg_factor = 2.0,
     .hierarchy = boomeramg_info,
     .views = {{"IJ matrix", boomeramg_matvec, 1e-14}},
     .variants = boomeramg_variants,
     .refused = boomeramg_refused,
     .mpm_variants = boomeramg_mpm_variants},
#endif
#if MPM_WITH_ML
    {.name = "ml",
     .sym_tol = 1e-10,
     .mpm_pcg_factor = 2.5,
     .hierarchy = ml_info,
     .views = {{"getrow rows", ml_getrow_matvec, 1e-14}, {"fine operator", ml_matvec, 0.0}},
     .variants = ml_variants,
     .refused = ml_refused,
     .own_checks = ml_own_checks},
#endif
#if MPM_WITH_PETSC
    /* the default is PETSc's own GAMG (smoothed aggregation): 58 PCG
     * iterations on the MPM Hessian against block Jacobi's 115 */
    {.name = "petsc",
     .sym_tol = 1e-10,
     .mpm_pcg_factor = 1.5,
     .hierarchy = petsc_info,
     .views = {{"Mat", petsc_matvec, 1e-14}},
     .variants = petsc_variants,
     .refused = petsc_refused,
     .mpm_variants = petsc_mpm_variants,
     .own_checks = petsc_own_checks},
#endif
    {.name = NULL}};

/* the adapters this build has, by the ops each defines (inv_NAME_ops, adapters/adapter_list.h) */
#define DECLARE_OPS(name) extern const InvApproxOps inv_##name##_ops;
MPM_BUILT_ADAPTERS(DECLARE_OPS)
#define BUILT_ENTRY(name) {#name, &inv_##name##_ops},
static const struct {
    const char *name;
    const InvApproxOps *ops;
} built[] = {MPM_BUILT_ADAPTERS(BUILT_ENTRY){NULL, NULL}};

/* ---------------------------------------------------------------------------
 * The MPM Hessian
 * ------------------------------------------------------------------------- */

/* The MPM Hessian of the checks: two materials, 20 particles an axis */
static void mpm_hessian_options(FixtureOptions *o)
{
    fixture_default(o);
    o->per_axis = 20;
    o->two_materials = 1;
    o->F_noise = 0.2;
}

static int mpm_hessian_build(MpmHessian *h, Problem *out, const FixtureOptions *opts)
{
    memset(h, 0, sizeof *h);
    FixtureOptions o = *opts;
    int st = fixture_build(&h->f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return st;
    StepProblem *pb = &h->f.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    int ymin = h->f.g.coord[1];
    for (int i = 0; i < n; ++i)
        if (h->f.g.coord[3 * i + 1] < ymin) ymin = h->f.g.coord[3 * i + 1];
    const double zero[3] = {0, 0, 0};
    h->fixed = calloc((size_t)n, 1);
    for (int i = 0; i < n; ++i)
        if (h->f.g.coord[3 * i + 1] == ymin) {
            problem_set_dirichlet(pb, i, zero, NULL);
            h->fixed[i] = 1;
        }
    problem_finish_dirichlet(pb);
    double *dv = vec_new(len);
    h->b = vec_new(len);
    h->diag = vec_new(9 * (size_t)n);
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    problem_gradient(pb, dv, h->b); /* a realistic right-hand side: the gradient */
    free(dv);
    st = problem_tangent(pb, 1);
    st |= problem_assemble(pb, &h->H);
    CHECK(st == MPM_OK, "assemble: %s", mpm_last_error());
    if (st) return st;
    problem_diagonal(pb, h->diag);
    h->op = (LinearOp){n, mpm_spmv, &h->H};
    h->proj = (Projection){mpm_project, pb};
    *out = (Problem){.name = "the MPM Hessian", .n = n, .A = &h->H, .fixed = h->fixed, .op = &h->op,
                     .proj = &h->proj};
    out->in = (InvSetupInput){.n_nodes = n, .H = &h->H, .diag = h->diag, .coord = h->f.g.coord,
                              .coloring = &h->f.g.coloring, .op = &h->op, .proj = &h->proj, .problem = pb};
    h->jacobi_iters = jacobi_iters(out, h->b);
    printf("MPM Hessian: %d nodes (%d Dirichlet), %lld blocks (%.1f per row), dt %g, E %s; block-Jacobi "
           "PCG to 1e-8: %d iterations\n",
           n, pb->n_dirichlet, (long long)h->H.nnzb, (double)h->H.nnzb / n, o.dt, o.two_materials ? "1e4 and 3e6" : "1e4",
           h->jacobi_iters);
    return MPM_OK;
}

static void mpm_hessian_free(MpmHessian *h)
{
    bsr_free(&h->H);
    free(h->diag);
    free(h->b);
    free(h->fixed);
    fixture_free(&h->f);
}

int main(void)
{
    if (!built[0].name) return test_skip("test_adapters", "no third-party adapter in this build (the minimal build)");

    SynthProblem synth, other;
    /* a slab: thin enough that CHOLMOD's factorisations stay fast with the
     * reference BLAS, thick enough for a 125-block stencil in every direction */
    SynthParams sp = {.center = {-5, 7, -3}, .radius = 0.0, .box = {30, 12, 6}, .reach = 2, .mass = 1.0,
                      .stiff = 1000.0, .dirichlet = 1, .seed = 42};
    /* other nodes (a ball, 27-block stencil): a new pattern */
    SynthParams sq = {.center = {1, 2, 3}, .radius = 6.0, .reach = 1, .mass = 1.0, .stiff = 100.0, .dirichlet = 1,
                      .seed = 5};
    int st = synth_build(&synth, &sp);
    st = st ? st : synth_build(&other, &sq);
    CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
    if (st) return test_summary("test_adapters");
    printf("synthetic problem: %d nodes, %d Dirichlet, %lld blocks (%.1f per row); other nodes: %d\n", synth.n,
           synth.n_fixed, (long long)synth.A.nnzb, (double)synth.A.nnzb / synth.n, other.n);
    MpmHessian hessian;
    Problem mpm;
    Problems pr = {.synth = &synth, .other = &other, .hessian = &hessian};
    FixtureOptions ho;
    mpm_hessian_options(&ho);
    if (mpm_hessian_build(&hessian, &mpm, &ho) == MPM_OK) pr.mpm = &mpm;

    /* which check ran on which adapter, printed at the end */
    enum { MAX_ADAPTERS = 16 };
    char ran[MAX_ADAPTERS][N_CHECKS];
    int n_built = 0;
    for (int a = 0; built[a].name && a < MAX_ADAPTERS; ++a, ++n_built) {
        const AdapterRow *row = NULL;
        for (int r = 0; rows[r].name && !row; ++r)
            if (!strcmp(rows[r].name, built[a].name)) row = &rows[r];
        CHECK(row, "the adapter %s is built but tests/conformance/test_adapters.c has no row for it", built[a].name);
        for (size_t c = 0; c < N_CHECKS; ++c) {
            ran[a][c] = row && CHECKS[c].applies(row);
            if (!ran[a][c]) continue;
            int failures = g_test_failures;
            printf("--- %s: %s\n", built[a].name, CHECKS[c].name);
            CHECKS[c].run(row, built[a].ops, &pr);
            if (g_test_failures > failures) ran[a][c] = 'F';
        }
    }
    printf("\n%-14s", "check");
    for (int a = 0; a < n_built; ++a) printf(" %-10s", built[a].name);
    printf("\n");
    for (size_t c = 0; c < N_CHECKS; ++c) {
        printf("%-14s", CHECKS[c].name);
        for (int a = 0; a < n_built; ++a) printf(" %-10s", ran[a][c] == 'F' ? "FAILED" : ran[a][c] ? "ok" : "-");
        printf("\n");
    }
    if (pr.mpm) mpm_hessian_free(&hessian);
    synth_free(&synth);
    synth_free(&other);
    return test_summary("test_adapters");
}
