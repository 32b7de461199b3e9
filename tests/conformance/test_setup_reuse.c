/* floor: adapters */
/* Setup reuse (docs/solvers.md "Setup reuse"; solvers/inverse_approx.c), on
 * every implementation with a reuse op in this build: the in-house
 * multigrid (mg) always, and each third-party adapter that is built (the
 * generated MPM_BUILT_ADAPTERS list) with a row in `rows` saying what its
 * reuse can do. A built adapter with a reuse op and no row fails the test;
 * the minimal build checks mg alone.
 *  1. reuse_every=1 (the default) sets up afresh at every request: the
 *     applications are bitwise those of a new object set up on the same
 *     matrix;
 *  2. a refresh equals a fresh setup on the new values (where the
 *     implementation can refresh: mg, Galerkin products on the kept
 *     transfers; CHOLMOD, numeric refactorisation);
 *  3. a lagged inverse (CHOLMOD's old factor, BoomerAMG's old hierarchy,
 *     mg's old coarse operators) is still symmetric and positive, and PCG
 *     on the new matrix reaches the same tolerance with it; an adapter
 *     keeps what it was built on even when the caller overwrites its matrix
 *     in place;
 *  4. across steps the kept setup is reused only while the nodes and the
 *     pattern are unchanged, and dropped (a rebuild, one pattern miss) when
 *     they change;
 *  5. the counters add up (requests = rebuilds + refreshes + lagged), mg's
 *     cadence, and (own checks) CHOLMOD's symbolic reuse across a pattern
 *     change and BoomerAMG's elasticity options, which keep its V-cycle
 *     symmetric and positive, and refuse bad values;
 *  6. bad option values, or reuse of an implementation without a reuse op,
 *     are refused with a one-line error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_adapters_built.h" /* generated: MPM_BUILT_ADAPTERS(X), the adapters of this build */
#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"
#include "solvers/mg/mg.h"
#include "tests/common/synthetic.h"
#include "tests/common/testutil.h"

static InvSetupInput input_of(const SynthProblem *p)
{
    return (InvSetupInput){.n_nodes = p->n, .H = &p->A, .diag = p->diag, .coord = p->coord, .coloring = &p->col,
                           .op = &p->op, .proj = &p->proj};
}

static InvApprox *create(const InvApproxOps *ops, const char *opts)
{
    SolverOptions o;
    memset(&o, 0, sizeof o);
    InvApprox *M = NULL;
    int st = solver_opts_set_list(&o, opts, "test");
    st = st ? st : inv_create(ops, &o, &M);
    CHECK(st == MPM_OK, "%s create (%s): %s", ops->name, opts, mpm_last_error());
    return M;
}

static int setup(InvApprox *M, const SynthProblem *p)
{
    InvSetupInput in = input_of(p);
    int st = inv_setup(M, &in);
    CHECK(st == MPM_OK, "%s setup: %s", M->ops->name, mpm_last_error());
    return st;
}

/* max |M1 r - M2 r| / max |M2 r| over one projected random r */
static double apply_diff(InvApprox *M1, InvApprox *M2, int n, unsigned long long seed)
{
    size_t len = 3 * (size_t)n;
    double *r = malloc(sizeof(double) * len), *z1 = calloc(len, sizeof(double)), *z2 = calloc(len, sizeof(double));
    synth_random_vector(n, seed, r);
    int st = inv_apply(M1, r, z1);
    st = st ? st : inv_apply(M2, r, z2);
    CHECK(st == MPM_OK, "apply: %s", mpm_last_error());
    double d = 0.0, m = 0.0;
    for (size_t k = 0; k < len; ++k) {
        d = fmax(d, fabs(z1[k] - z2[k]));
        m = fmax(m, fabs(z2[k]));
    }
    free(r);
    free(z1);
    free(z2);
    return m > 0 ? d / m : d;
}

static long stat_of(const InvApprox *M, const char *key)
{
    InvView v;
    inv_view(M, NULL, &v);
    for (int i = 0; i < v.n_stats; ++i)
        if (!strcmp(v.stat[i].key, key)) return (long)v.stat[i].value;
    return -1;
}

static void check_counters(const InvApprox *M, long req, long reb, long ref, long lag, long miss, const char *what)
{
    const InvReuseStats *r = &M->reuse;
    CHECK(r->requests == req && r->rebuilds == reb && r->refreshes == ref && r->lagged == lag &&
              r->pattern_misses == miss,
          "%s: requests %ld rebuilds %ld refreshes %ld lagged %ld misses %ld, expected %ld %ld %ld %ld %ld", what,
          r->requests, r->rebuilds, r->refreshes, r->lagged, r->pattern_misses, req, reb, ref, lag, miss);
    CHECK(r->requests == r->rebuilds + r->refreshes + r->lagged, "%s: counters do not add up", what);
    CHECK(stat_of(M, "setup_requests") == req && stat_of(M, "rebuilds") == reb && stat_of(M, "refreshes") == ref &&
              stat_of(M, "lagged") == lag && stat_of(M, "pattern_misses") == miss,
          "%s: view statistics differ from the counters", what);
}

/* x^T M y vs y^T M x (relative), and min over a few r of r^T M r / r^T r */
static void symmetric_positive(InvApprox *M, int n, const Projection *proj, const char *what)
{
    size_t len = 3 * (size_t)n;
    double *x = malloc(sizeof(double) * len), *y = malloc(sizeof(double) * len), *Mx = malloc(sizeof(double) * len),
           *My = malloc(sizeof(double) * len);
    double worst_sym = 0.0, min_ray = INFINITY;
    for (int t = 0; t < 4; ++t) {
        synth_random_vector(n, 100 + 2 * (unsigned)t, x);
        synth_random_vector(n, 101 + 2 * (unsigned)t, y);
        projection_apply(proj, x);
        projection_apply(proj, y);
        inv_apply(M, x, Mx);
        inv_apply(M, y, My);
        projection_apply(proj, Mx);
        projection_apply(proj, My);
        double a = vec_dot(len, y, Mx), b = vec_dot(len, x, My);
        worst_sym = fmax(worst_sym, fabs(a - b) / fmax(fabs(a), fabs(b)));
        min_ray = fmin(min_ray, vec_dot(len, x, Mx) / vec_dot(len, x, x));
    }
    CHECK(worst_sym < 1e-10, "%s: not symmetric (relative gap %.3g)", what, worst_sym);
    CHECK(min_ray > 0.0, "%s: not positive (r^T M r / r^T r = %.3g)", what, min_ray);
    free(x);
    free(y);
    free(Mx);
    free(My);
}

/* PCG on p's matrix with M to a relative 1e-10 of the initial preconditioned
 * norm; returns the iterations (-1 when it failed) and the true relative
 * residual. */
static int pcg_iters(const SynthProblem *p, InvApprox *M, double *relres)
{
    size_t len = 3 * (size_t)p->n;
    double *b = malloc(sizeof(double) * len), *x = calloc(len, sizeof(double)), *r = malloc(sizeof(double) * len);
    synth_random_vector(p->n, 7, b);
    projection_apply(&p->proj, b);
    PcgWork w = {0};
    PcgResult res;
    PcgOptions o = {.stop = PCG_RELATIVE_L2, .rel_tol = 1e-10, .max_iters = 2000};
    int st = pcg_solve(&p->op, M, &p->proj, b, x, &o, &w, &res);
    bsr_spmv(&p->A, x, r);
    for (size_t k = 0; k < len; ++k) r[k] = b[k] - r[k];
    projection_apply(&p->proj, r);
    *relres = vec_norm(len, r) / vec_norm(len, b);
    int it = st == MPM_OK && !res.capped ? res.iters : -1;
    pcg_work_free(&w);
    free(b);
    free(x);
    free(r);
    return it;
}

/* ---------------------------------------------------------------------------
 * What differs between implementations
 * ------------------------------------------------------------------------- */

typedef struct {
    SynthProblem *A1, *A2, *B; /* A1, A2: one pattern, other values; B: other nodes */
    SynthParams sp;            /* A1's parameters */
} Matrices;

typedef struct ReuseRow ReuseRow;
struct ReuseRow {
    const char *name;
    const char *fixed_opts; /* options making its apply a fixed symmetric map ("" for none) */
    int refreshes;          /* its reuse op can update the values (else it lags) */
    int keeps_its_matrix;   /* a lagged setup survives the caller overwriting the matrix in place */
    void (*own_checks)(const ReuseRow *row, const InvApproxOps *ops, const Matrices *m);
};

/* "fixed_opts,more" (either may be empty) */
static const char *with_opts(char *buf, size_t cap, const char *fixed, const char *more)
{
    snprintf(buf, cap, "%s%s%s", fixed, fixed[0] && more[0] ? "," : "", more);
    return buf;
}

/* 5. mg's cadence: reuse_every=3 over 7 requests rebuilds at 1, 4, 7 */
static void mg_own_checks(const ReuseRow *row, const InvApproxOps *ops, const Matrices *m)
{
    (void)row;
    InvApprox *M = create(ops, "reuse_every=3");
    inv_begin_solve(M);
    for (int i = 0; i < 7; ++i) setup(M, i % 2 ? m->A2 : m->A1);
    check_counters(M, 7, 3, 4, 0, 0, "mg reuse_every=3");
    CHECK(stat_of(M, "levels") > 1, "mg: a hierarchy expected");
    inv_destroy(M);
}

/* 5. a pattern change inside a solve: rebuilt, counted as a miss; the
 * symbolic analysis is redone for the new pattern and reused after */
static void cholmod_own_checks(const ReuseRow *row, const InvApproxOps *ops, const Matrices *m)
{
    (void)row;
    InvApprox *M = create(ops, "reuse_every=0");
    inv_begin_solve(M);
    setup(M, m->A1);
    setup(M, m->B);
    setup(M, m->B);
    check_counters(M, 3, 2, 1, 0, 1, "cholmod pattern change");
    CHECK(stat_of(M, "symbolic_reuses") == 1 && stat_of(M, "factorizations") == 3 && stat_of(M, "analyses") == 2,
          "cholmod: symbolic_reuses %ld factorizations %ld analyses %ld", stat_of(M, "symbolic_reuses"),
          stat_of(M, "factorizations"), stat_of(M, "analyses"));
    inv_destroy(M);
}

/* 5. BoomerAMG's elasticity options (adapters/boomeramg.c) keep the V-cycle
 * symmetric and positive, and PCG converges with each; bad values are refused */
static void boomeramg_own_checks(const ReuseRow *row, const InvApproxOps *ops, const Matrices *m)
{
    (void)row;
    const char *variants[] = {"amg_relax=3",     "amg_relax=13",
                              "amg_relax=16,amg_cheby_order=3", "amg_relax=18,amg_sweeps=2",
                              "amg_rbm=2,amg_rbm_qmax=4", "amg_agg_levels=1,amg_agg_interp=6,amg_agg_pmax=4,amg_num_paths=2",
                              "amg_nodal=1,amg_nodal_diag=1,amg_trunc=0.1,amg_interp=14"};
    for (size_t i = 0; i < sizeof variants / sizeof variants[0]; ++i) {
        InvApprox *M = create(ops, variants[i]);
        if (!M || setup(M, m->A2)) {
            inv_destroy(M);
            continue;
        }
        symmetric_positive(M, m->A2->n, &m->A2->proj, variants[i]);
        double rr;
        int it = pcg_iters(m->A2, M, &rr);
        printf("boomeramg %-60s PCG %d iterations\n", variants[i], it);
        CHECK(it > 0 && it < 60 && rr < 1e-9, "boomeramg %s: PCG %d iterations, residual %.3g", variants[i], it, rr);
        inv_destroy(M);
    }
    const char *bad[] = {"amg_relax=7", "amg_agg_interp=9", "amg_trunc=1.5", "amg_cheby_order=2.5",
                         "amg_nodal_diag=3", "amg_rbm=1,amg_nodal=0", "amg_num_paths=0", "amg_rbm_qmax=-1"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        SolverOptions o;
        memset(&o, 0, sizeof o);
        InvApprox *M = NULL;
        solver_opts_set_list(&o, bad[i], "test");
        mpm_clear_error();
        int st = inv_create(ops, &o, &M);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), "--solver-opt amg_") && !strchr(mpm_last_error(), '\n'),
              "%s: st %d, '%s'", bad[i], st, mpm_last_error());
        inv_destroy(M);
    }
    mpm_clear_error();
}

/* mg, CHOLMOD and PETSc can refresh; BoomerAMG and ML only lag */
static const ReuseRow mg_row = {"mg", "coarse_exact=1,min_coarse_nodes=50", 1, 0, mg_own_checks};
static const ReuseRow rows[] = {
    {"cholmod", "", 1, 1, cholmod_own_checks},
    {"boomeramg", "", 0, 1, boomeramg_own_checks},
    {"ml", "", 0, 1, NULL},
    /* PETSc refreshes: the new values into its Mat, the kept KSP set up
     * again (SAME_NONZERO_PATTERN). With plain aggregation, as the presets
     * have it: GAMG's smoothed aggregation estimates an eigenvalue from a
     * random vector whose generator a re-setup does not restart, so its
     * refresh differs from a fresh setup by about 0.4 % */
    {"petsc", "pc_type=gamg,pc_gamg_agg_nsmooths=0", 1, 1, NULL},
    {NULL, NULL, 0, 0, NULL}};

#define DECLARE_OPS(name) extern const InvApproxOps inv_##name##_ops;
MPM_BUILT_ADAPTERS(DECLARE_OPS)
#define BUILT_ENTRY(name) {#name, &inv_##name##_ops},
static const struct {
    const char *name;
    const InvApproxOps *ops;
} built[] = {MPM_BUILT_ADAPTERS(BUILT_ENTRY){NULL, NULL}};

/* ---------------------------------------------------------------------------
 * The checks, on one implementation
 * ------------------------------------------------------------------------- */

static void check_reuse(const ReuseRow *row, const InvApproxOps *ops, const Matrices *m)
{
    const SynthProblem *A1 = m->A1, *A2 = m->A2, *B = m->B;
    const char *extra = row->fixed_opts, *name = ops->name;
    char opts[160];

    /* 1. reuse_every=1: every request a full setup, bitwise a fresh object's */
    {
        InvApprox *M = create(ops, with_opts(opts, sizeof opts, extra, "reuse_every=1")), *F = create(ops, extra);
        inv_begin_solve(M);
        setup(M, A1);
        setup(M, A2);
        setup(F, A2);
        double d = apply_diff(M, F, A2->n, 1);
        CHECK(d == 0.0, "%s reuse_every=1: applications differ from a fresh setup by %.3g", name, d);
        check_counters(M, 2, 2, 0, 0, 0, name);
        inv_destroy(M);
        inv_destroy(F);
    }

    /* 2. a refresh equals a fresh setup on the new values */
    if (row->refreshes) {
        InvApprox *M = create(ops, with_opts(opts, sizeof opts, extra, "reuse_every=5")), *F = create(ops, extra);
        inv_begin_solve(M);
        setup(M, A1);
        setup(M, A2);
        setup(F, A2);
        double d = apply_diff(M, F, A2->n, 2);
        CHECK(d < 1e-12, "%s refresh: applications differ from a fresh setup by %.3g", name, d);
        check_counters(M, 2, 1, 1, 0, 0, name);
        inv_destroy(M);
        inv_destroy(F);
    }

    /* 3. lagged: still symmetric and positive; PCG on A2 reaches the same
     * tolerance as with a fresh setup (a few more iterations) */
    {
        InvApprox *M = create(ops, with_opts(opts, sizeof opts, extra, "reuse_every=0,reuse_refresh=0")),
                  *F = create(ops, extra);
        inv_begin_solve(M);
        setup(M, A1);
        setup(M, A2);
        setup(F, A2);
        check_counters(M, 2, 1, 0, 1, 0, name);
        double d = apply_diff(M, F, A2->n, 3);
        CHECK(d > 1e-6, "%s lagged: no different from a fresh setup (%.3g): nothing was lagged", name, d);
        symmetric_positive(M, A2->n, &A2->proj, name);
        double rl, rf;
        int il = pcg_iters(A2, M, &rl), ifr = pcg_iters(A2, F, &rf);
        printf("%-9s PCG on the new matrix to 1e-10: fresh %d iterations (residual %.2g), lagged %d (%.2g)\n", name,
               ifr, rf, il, rl);
        CHECK(il > 0 && rl < 1e-9 && ifr > 0 && rf < 1e-9, "%s: PCG with the lagged inverse: %d iterations, %.3g", name,
              il, rl);
        inv_destroy(M);
        inv_destroy(F);
    }

    /* 3b. lagged means the old inverse even when the caller overwrites its
     * matrix in place (as a step does between Newton iterations): CHOLMOD,
     * BoomerAMG and ML keep what they were built on (ML through its own
     * copy of the matrix, which its V-cycle reads at every application) */
    if (row->keeps_its_matrix) {
        SynthProblem W;
        int wst = synth_build(&W, &m->sp); /* the values of A1, in storage the test overwrites */
        CHECK(wst == MPM_OK && W.A.nnzb == A2->A.nnzb, "synth_build W: %s", mpm_last_error());
        if (!wst) {
            InvApprox *M = create(ops, "reuse_every=0,reuse_refresh=0"), *F = create(ops, "");
            inv_begin_solve(M);
            setup(M, &W);
            memcpy(W.A.val, A2->A.val, sizeof(double) * 9 * (size_t)A2->A.nnzb);
            memcpy(W.diag, A2->diag, sizeof(double) * 9 * (size_t)A2->n);
            setup(M, &W); /* lagged */
            check_counters(M, 2, 1, 0, 1, 0, name);
            setup(F, A1);
            double d = apply_diff(M, F, A1->n, 5);
            CHECK(d < 1e-12, "%s lagged after an in-place overwrite: differs from the inverse of the old matrix by %.3g",
                  name, d);
            inv_destroy(M);
            inv_destroy(F);
            synth_free(&W);
        }
    }

    /* 4. across steps: kept while the nodes and pattern hold, dropped when
     * they change; without the option every step rebuilds */
    {
        InvApprox *M = create(ops, with_opts(opts, sizeof opts, extra, "reuse_every=0,reuse_across_steps=1")),
                  *F = create(ops, extra);
        inv_begin_solve(M); /* step 1 */
        setup(M, A1);
        inv_begin_solve(M); /* step 2: same nodes and pattern */
        setup(M, A2);
        long refreshed = row->refreshes;
        check_counters(M, 2, 1, refreshed, 1 - refreshed, 0, name);
        inv_begin_solve(M); /* step 3: the active set changed */
        setup(M, B);
        check_counters(M, 3, 2, refreshed, 1 - refreshed, 1, name);
        setup(F, B);
        double d = apply_diff(M, F, B->n, 4);
        CHECK(d == 0.0, "%s after a pattern change: applications differ from a fresh setup by %.3g", name, d);
        inv_destroy(M);
        /* the option off: a new step rebuilds even on the same pattern */
        M = create(ops, with_opts(opts, sizeof opts, extra, "reuse_every=0"));
        inv_begin_solve(M);
        setup(M, A1);
        setup(M, A2); /* same step: reused */
        inv_begin_solve(M);
        setup(M, A2); /* next step: rebuilt */
        check_counters(M, 3, 2, refreshed, 1 - refreshed, 0, name);
        inv_destroy(M);
        inv_destroy(F);
    }

    if (row->own_checks) row->own_checks(row, ops, m);
}

int main(void)
{
    /* two matrices with one pattern (the stiffness changes, as between
     * Newton iterations) and a third on other nodes (a new active set) */
    SynthParams sp = {.center = {2, -3, 1}, .radius = 7.0, .reach = 2, .mass = 1.0, .stiff = 500.0,
                      .dirichlet = 1, .core_ratio = 30.0, .seed = 5};
    SynthProblem A1, A2, B;
    int st = synth_build(&A1, &sp);
    SynthParams sp2 = sp;
    sp2.stiff = 2000.0;
    sp2.core_ratio = 300.0;
    sp2.seed = 6;
    st = st ? st : synth_build(&A2, &sp2);
    SynthParams sb = sp;
    sb.radius = 7.5;
    st = st ? st : synth_build(&B, &sb);
    CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
    if (st) return test_summary("test_setup_reuse");
    CHECK(A1.A.pattern_id == A2.A.pattern_id && A1.n == A2.n, "A1 and A2 must share a pattern");
    CHECK(B.n != A1.n, "B must have other nodes");
    printf("nodes: %d (A1, A2), %d (B)\n", A1.n, B.n);

    /* mg always, then every built adapter with a reuse op, each by its row */
    Matrices m = {&A1, &A2, &B, sp};
    printf("--- mg\n");
    check_reuse(&mg_row, &inv_mg_ops, &m);
    for (int a = 0; built[a].name; ++a) {
        const ReuseRow *row = NULL;
        for (int r = 0; rows[r].name && !row; ++r)
            if (!strcmp(rows[r].name, built[a].name)) row = &rows[r];
        if (!built[a].ops->reuse) {
            printf("--- %s: no reuse op, nothing to check\n", built[a].name);
            continue;
        }
        CHECK(row, "the adapter %s has a reuse op but tests/conformance/test_setup_reuse.c has no row for it",
              built[a].name);
        if (!row) continue;
        printf("--- %s\n", built[a].name);
        check_reuse(row, built[a].ops, &m);
    }

    /* 6. refused options */
    {
        const char *bad[][2] = {{"reuse_every=-1", "reuse_every=-1"},
                                {"reuse_across_steps=2", "reuse_across_steps=2"},
                                {"reuse_refresh=0.5", "reuse_refresh=0.5"}};
        for (int i = 0; i < 3; ++i) {
            SolverOptions o;
            memset(&o, 0, sizeof o);
            InvApprox *M = NULL;
            solver_opts_set_list(&o, bad[i][0], "test");
            mpm_clear_error();
            st = inv_create(&inv_mg_ops, &o, &M);
            CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), bad[i][1]) && !strchr(mpm_last_error(), '\n'),
                  "%s: st %d, '%s'", bad[i][0], st, mpm_last_error());
            inv_destroy(M);
        }
        SolverOptions o;
        memset(&o, 0, sizeof o);
        InvApprox *M = NULL;
        solver_opts_set_list(&o, "reuse_across_steps=1", "test");
        mpm_clear_error();
        st = inv_create(&inv_block_jacobi_ops, &o, &M);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), "cannot reuse"), "block-jacobi reuse: st %d, '%s'", st,
              mpm_last_error());
        inv_destroy(M);
        mpm_clear_error();
    }

    synth_free(&A1);
    synth_free(&A2);
    synth_free(&B);
    return test_summary("test_setup_reuse");
}
