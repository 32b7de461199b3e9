/* Trilinos ML smoothed-aggregation V-cycle behind the InvApprox interface
 * (docs/design.md, "the one idea": PN-ML-PCG and LBFGS-ML; SPEC 7).
 *
 * API use follows the ML 5.0 User's Guide (Sala, Hu, Tuminaro, Sandia
 * SAND2004-4821: "ML as a preconditioner through its C interface",
 * "smoothed aggregation", "user-defined matrices: getrow and matvec") and
 * the comments in ml_struct.h / ml_aggregate.h of Trilinos 13.2.
 *
 * Choices:
 *  - Fine matrix: ML_Init_Amatrix + ML_Set_Amatrix_Getrow over the block-CSR
 *    rows (scalar row 3I+a = row a of every block of block row I; exact zeros
 *    off the diagonal are not reported, so ML sees the true graph and the
 *    Dirichlet rows that the projection decoupled as Dirichlet rows) +
 *    ML_Set_Amatrix_Matvec = bsr_spmv. No copy of the Hessian.
 *  - Smoothed aggregation (ML_Gen_MultiLevelHierarchy_UsingAggregation),
 *    uncoupled aggregation (one process), 3 equations per node, near-null
 *    space = 3 translations + 3 rotations about the centroid of the nodes'
 *    integer coordinates (ML_Aggregate_Set_NullSpace; column k of the 3n x 6
 *    array is mode k). Rotations are not projected: ML leaves Dirichlet rows
 *    out of the aggregates, so their values there do not matter.
 *  - Symmetry: the same smoother pre and post (ML_BOTH) on every level but
 *    the coarsest: Chebyshev in D^-1 A (ML_Gen_Smoother_Cheby, eigenvalue
 *    ratio 30 as in ML's own defaults) or symmetric Gauss-Seidel; Galerkin
 *    RAP with R = P^T; coarsest level solved by KLU through Amesos. The
 *    V-cycle operator is then symmetric positive definite, as CG requires.
 *  - Chebyshev needs lambda_max(D^-1 A) per level; ML computes it at
 *    smoother generation when the operator's cached value is unset (its
 *    sentinel is -666.666). Every setup builds a new ML object, so no cached
 *    estimate of an old matrix can survive a change of values; the random
 *    seed of those estimates is reset too, so equal matrices give equal
 *    V-cycles (tests/conformance/test_adapters.c checks both).
 *  - ML calls exit() on some errors (bad parameters, failed allocations), so
 *    every option is validated in create and sizes are checked before ML is
 *    called. */
#include "adapters/ml.h"

#include <Trilinos_version.h>
#include <ml_include.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/mpi_startup.h"
#include "core/error.h"

#if !defined(HAVE_MPI)
#error "adapters/ml.c expects ML built with MPI (Debian's libtrilinos-ml-dev)"
#endif

enum { ML_SMOOTH_CHEBY = 0, ML_SMOOTH_SGS = 1 };
enum { ML_RANDOM_SEED = 1234567 };

typedef struct {
    InvApprox base;
    /* options */
    int smoother, sweeps, levels, coarse_size, rbm;
    double threshold, damping;
    /* last setup; NULL ml = none */
    ML *ml;
    ML_Aggregate *ag;
    /* ML reads the fine matrix through getrow/matvec at every V-cycle, so
     * it keeps its own copy: the caller overwrites its Hessian in place at
     * the next Newton iteration, and a reused (lagged) hierarchy must keep
     * smoothing with the matrix it was built on. The copy costs one pass
     * over the blocks, small beside the aggregation. */
    Bsr own;
    const Bsr *H; /* &own after a successful setup, else NULL */
    int n, n_levels;
    double op_complexity;
    double *nullspace; /* 3n x 6, column-major */
    double *rhs;       /* 3n: ML_Solve_MGV takes a non-const input */
    int cap;
} Ml;

static int g_ml_ready = 0;

/* MPI once per process (adapters/mpi_startup.h); ML itself keeps no global
 * state to finalise. */
static int ml_mpi_init(void)
{
    if (g_ml_ready) return MPM_OK;
    int st = adapter_mpi_start("ml");
    if (st) return st;
    ML_Set_PrintLevel(0);
    g_ml_ready = 1;
    return MPM_OK;
}

int ml_library_startup(void) { return ml_mpi_init(); }

const char *ml_library_version(void) { return TRILINOS_VERSION_STRING; }

static int ml_create(SolverOptions *opt, InvApprox **out)
{
    int st = MPM_OK;
    const char *smoother = solver_opt_string(opt, "ml_smoother", "chebyshev");
    int sweeps = solver_opt_int(opt, "ml_sweeps", 2, 1, 10, &st);
    int levels = solver_opt_int(opt, "ml_levels", 10, 1, 20, &st);
    double threshold = solver_opt_number(opt, "ml_threshold", 0.0, &st);
    int coarse = solver_opt_int(opt, "ml_coarse_size", 512, 1, 100000, &st);
    double damping = solver_opt_number(opt, "ml_damping", 4.0 / 3.0, &st);
    const char *rbm = solver_opt_string(opt, "ml_rbm", "on");
    if (st) return st;
    int sm;
    if (strcmp(smoother, "chebyshev") == 0) sm = ML_SMOOTH_CHEBY;
    else if (strcmp(smoother, "sgs") == 0) sm = ML_SMOOTH_SGS;
    else return mpm_error(MPM_EINPUT, "--solver-opt ml_smoother=%s: expected chebyshev or sgs", smoother);
    if (!(threshold >= 0.0 && threshold < 1.0))
        return mpm_error(MPM_EINPUT, "--solver-opt ml_threshold=%g: expected a value in [0, 1)", threshold);
    if (!(damping >= 0.0 && damping <= 2.0))
        return mpm_error(MPM_EINPUT, "--solver-opt ml_damping=%g: expected a value in [0, 2]", damping);
    int r;
    if (strcmp(rbm, "on") == 0) r = 1;
    else if (strcmp(rbm, "off") == 0) r = 0;
    else return mpm_error(MPM_EINPUT, "--solver-opt ml_rbm=%s: expected on or off", rbm);
    Ml *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: ml");
    s->smoother = sm;
    s->sweeps = sweeps;
    s->levels = levels;
    s->threshold = threshold;
    s->coarse_size = coarse;
    s->damping = damping;
    s->rbm = r;
    s->base.ops = &inv_ml_ops;
    s->base.caps = INV_NEEDS_HESSIAN | INV_SYMMETRIC | INV_POSITIVE;
    /* ML's set-up runs on one thread; its V-cycle's fine-level products are
     * the project's OpenMP matvec (the coarse levels are serial) */
    s->base.setup_threads = 1;
    *out = &s->base;
    return MPM_OK;
}

/* ---- the fine matrix as ML sees it ---- */

/* Rows req[0..n_req) into (cols, vals), lens[i] entries each; 0 when
 * `space` is too small (ML then grows its buffers and asks again). */
static int bsr_getrow(ML_Operator *op, int n_req, int req[], int space, int cols[], double vals[], int lens[])
{
    const Ml *s = (const Ml *)ML_Get_MyGetrowData(op);
    const Bsr *H = s->H;
    int used = 0;
    for (int i = 0; i < n_req; ++i) {
        const int row = req[i], I = row / 3, a = row % 3;
        const int64_t k0 = H->row_ptr[I], k1 = H->row_ptr[I + 1];
        if (used + 3 * (k1 - k0) > space) return 0;
        int len = 0;
        for (int64_t k = k0; k < k1; ++k) {
            const double *v = H->val + 9 * k + 3 * a;
            const int J = H->col[k];
            for (int b = 0; b < 3; ++b) {
                const int c = 3 * J + b;
                if (v[b] == 0.0 && c != row) continue;
                cols[used + len] = c;
                vals[used + len] = v[b];
                ++len;
            }
        }
        lens[i] = len;
        used += len;
    }
    return 1;
}

static int bsr_matvec(ML_Operator *op, int in_len, double *x, int out_len, double *y)
{
    const Ml *s = (const Ml *)ML_Get_MyMatvecData(op);
    (void)in_len;
    (void)out_len;
    bsr_spmv(s->H, x, y);
    return 0;
}

static void destroy_hierarchy(Ml *s)
{
    if (s->ml) ML_Destroy(&s->ml);
    if (s->ag) ML_Aggregate_Destroy(&s->ag);
    s->ml = NULL;
    s->ag = NULL;
    s->n_levels = 0;
    s->op_complexity = 0.0;
}

void ml_rigid_body_modes(int n, const int *coord, double *ns)
{
    const size_t N = 3 * (size_t)n;
    double c[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) c[d] += coord[3 * i + d];
    for (int d = 0; d < 3; ++d) c[d] /= n > 0 ? n : 1;
    memset(ns, 0, sizeof(double) * 6 * N);
    for (int i = 0; i < n; ++i) {
        const double x = coord[3 * i] - c[0], y = coord[3 * i + 1] - c[1], z = coord[3 * i + 2] - c[2];
        for (int d = 0; d < 3; ++d) ns[d * N + 3 * i + d] = 1.0;
        double *r0 = ns + 3 * N + 3 * i, *r1 = ns + 4 * N + 3 * i, *r2 = ns + 5 * N + 3 * i;
        r0[1] = -z, r0[2] = y;
        r1[0] = z, r1[2] = -x;
        r2[0] = -y, r2[1] = x;
    }
}

static int ensure_buffers(Ml *s, int n, int rbm)
{
    if (n <= s->cap) return MPM_OK;
    free(s->nullspace);
    free(s->rhs);
    s->nullspace = NULL;
    s->cap = 0;
    s->rhs = malloc(sizeof(double) * 3 * (size_t)n);
    if (rbm) s->nullspace = malloc(sizeof(double) * 18 * (size_t)n);
    if (!s->rhs || (rbm && !s->nullspace)) return mpm_error(MPM_EINTERNAL, "out of memory: ml (%d nodes)", n);
    s->cap = n;
    return MPM_OK;
}

static int build_hierarchy(Ml *s, const InvSetupInput *in)
{
    const int N = 3 * s->n;
    /* ML's eigenvalue estimates (prolongator damping, Chebyshev) start from
     * random vectors drawn from a process-wide seed that advances: reset it
     * so that the hierarchy is a function of the matrix alone */
    ML_set_random_seed(ML_RANDOM_SEED);
    ML_Create(&s->ml, s->levels);
    ML_Comm_Set_UsrComm(s->ml->comm, MPI_COMM_SELF);
    ML_Set_ResidualOutputFrequency(s->ml, 0);
    ML_Init_Amatrix(s->ml, 0, N, N, s);
    ML_Set_Amatrix_Getrow(s->ml, 0, bsr_getrow, NULL, N);
    ML_Set_Amatrix_Matvec(s->ml, 0, bsr_matvec);

    ML_Aggregate_Create(&s->ag);
    ML_Aggregate_Set_OutputLevel(s->ag, 0);
    ML_Aggregate_Set_MaxLevels(s->ag, s->levels);
    ML_Aggregate_Set_CoarsenScheme_Uncoupled(s->ag);
    ML_Aggregate_Set_Threshold(s->ag, s->threshold);
    ML_Aggregate_Set_MaxCoarseSize(s->ag, s->coarse_size);
    ML_Aggregate_Set_DampingFactor(s->ag, s->damping);
    if (s->rbm) {
        ml_rigid_body_modes(in->n_nodes, in->coord, s->nullspace);
        ML_Aggregate_Set_NullSpace(s->ag, 3, 6, s->nullspace, N); /* ML copies it */
    } else {
        ML_Aggregate_Set_NullSpace(s->ag, 3, 3, NULL, N); /* translations */
    }
    const int nl = ML_Gen_MultiLevelHierarchy_UsingAggregation(s->ml, 0, ML_INCREASING, s->ag);
    if (nl < 1) return mpm_error(MPM_ENUMERIC, "ml: aggregation built no hierarchy (%d levels)", nl);
    s->n_levels = nl;
    for (int l = 0; l < nl - 1; ++l) {
        int e = s->smoother == ML_SMOOTH_CHEBY ? ML_Gen_Smoother_Cheby(s->ml, l, ML_BOTH, 30.0, s->sweeps)
                                               : ML_Gen_Smoother_SymGaussSeidel(s->ml, l, ML_BOTH, s->sweeps, 1.0);
        if (e) return mpm_error(MPM_ENUMERIC, "ml: smoother generation on level %d failed (%d)", l, e);
    }
#ifdef HAVE_ML_AMESOS
    if (ML_Gen_Smoother_Amesos(s->ml, nl - 1, ML_AMESOS_KLU, 1, 0.0, 0))
        return mpm_error(MPM_ENUMERIC, "ml: KLU factorisation of the coarsest level (%d) failed", nl - 1);
#else
    /* no direct solver in this ML: symmetric Gauss-Seidel sweeps on the coarsest level */
    ML_Gen_Smoother_SymGaussSeidel(s->ml, nl - 1, ML_BOTH, 4, 1.0);
#endif
    ML_Gen_Solver(s->ml, ML_MGV, 0, nl - 1);
    double fine = 0.0, total = 0.0;
    for (int l = 0; l < nl; ++l) {
        double nz = (double)ML_Operator_Get_Nnz(&s->ml->Amat[l]);
        if (l == 0) fine = nz;
        total += nz;
    }
    s->op_complexity = fine > 0 ? total / fine : 0.0;
    return MPM_OK;
}

static int ml_setup(InvApprox *self, const InvSetupInput *in)
{
    Ml *s = (Ml *)self;
    destroy_hierarchy(s);
    s->H = NULL;
    const Bsr *H = in->H;
    if (!H) return mpm_error(MPM_EINTERNAL, "ml: needs the assembled Hessian (matrix-free PN is not supported)");
    if (H->n != in->n_nodes)
        return mpm_error(MPM_EINTERNAL, "ml: Hessian has %d block rows but the problem %d nodes", H->n, in->n_nodes);
    if (3 * (int64_t)H->n > (int64_t)0x7fffffff / 6 || 9 * H->row_ptr[H->n] > (int64_t)0x7fffffff)
        return mpm_error(MPM_EINTERNAL, "ml: Hessian too large for ML's int indices (%d nodes, %lld blocks)", H->n,
                         (long long)H->nnzb);
    if (s->rbm && !in->coord) return mpm_error(MPM_EINTERNAL, "ml: ml_rbm=on needs node coordinates");
    s->n = H->n;
    if (H->n == 0) return MPM_OK;
    int st = ml_mpi_init();
    if (!st) st = ensure_buffers(s, H->n, s->rbm);
    if (st) return st;
    st = bsr_copy(&s->own, H);
    if (st) return st;
    s->H = &s->own;
    st = build_hierarchy(s, in);
    if (st) {
        destroy_hierarchy(s); /* the next setup starts afresh */
        s->H = NULL;
    }
    return st;
}

/* Setup reuse (inverse_approx.h): always lagged. ML has no update of a
 * hierarchy's values short of a new aggregation and Galerkin products (the
 * whole setup), so the kept V-cycle, built on the kept copy of the matrix,
 * is applied as it is: symmetric and positive, a few more PCG iterations
 * in exchange for the setup (83 % of pn-ml-pcg's time on twist). */
static int ml_reuse(InvApprox *self, const InvSetupInput *in, int values, int *refreshed)
{
    Ml *s = (Ml *)self;
    (void)values;
    *refreshed = 0;
    if (!in->H || in->H->n != s->n) return mpm_error(MPM_EINTERNAL, "ml: reused for a different matrix");
    if (s->n > 0 && !s->ml) return mpm_error(MPM_EINTERNAL, "ml: reused without a successful setup");
    return MPM_OK;
}

static int ml_apply(InvApprox *self, const double *r, double *z)
{
    Ml *s = (Ml *)self;
    if (s->n == 0) return MPM_OK;
    if (!s->ml) return mpm_error(MPM_EINTERNAL, "ml: apply without a successful setup");
    const size_t N = 3 * (size_t)s->n;
    memcpy(s->rhs, r, sizeof(double) * N);
    ML_Solve_MGV(s->ml, s->rhs, z); /* zeroes z first: one V-cycle from a zero guess */
    return MPM_OK;
}

static void ml_destroy(InvApprox *self)
{
    if (!self) return;
    Ml *s = (Ml *)self;
    destroy_hierarchy(s);
    bsr_free(&s->own);
    free(s->nullspace);
    free(s->rhs);
    free(s);
}

int ml_info(const InvApprox *self, int *levels, double *op_complexity)
{
    if (!self || self->ops != &inv_ml_ops) return mpm_error(MPM_EINTERNAL, "ml_info: not an ml inverse approximation");
    const Ml *s = (const Ml *)self;
    if (!s->ml) return mpm_error(MPM_EINTERNAL, "ml_info: no hierarchy (setup not done or failed)");
    if (levels) *levels = s->n_levels;
    if (op_complexity) *op_complexity = s->op_complexity;
    return MPM_OK;
}

int ml_matvec(InvApprox *self, const double *x, double *y)
{
    if (!self || self->ops != &inv_ml_ops) return mpm_error(MPM_EINTERNAL, "ml_matvec: not an ml inverse approximation");
    Ml *s = (Ml *)self;
    if (!s->ml) return mpm_error(MPM_EINTERNAL, "ml_matvec: no matrix (setup not done or failed)");
    const int N = 3 * s->n;
    memcpy(s->rhs, x, sizeof(double) * (size_t)N);
    ML_Operator_Apply(&s->ml->Amat[0], N, s->rhs, N, y);
    return MPM_OK;
}

int ml_getrow_matvec(InvApprox *self, const double *x, double *y)
{
    if (!self || self->ops != &inv_ml_ops)
        return mpm_error(MPM_EINTERNAL, "ml_getrow_matvec: not an ml inverse approximation");
    Ml *s = (Ml *)self;
    if (!s->ml) return mpm_error(MPM_EINTERNAL, "ml_getrow_matvec: no matrix (setup not done or failed)");
    const int N = 3 * s->n;
    int space = 64, *cols = NULL, len = 0;
    double *vals = NULL;
    int st = MPM_OK;
    for (int row = 0; row < N && !st; ++row) {
        for (;;) {
            if (!cols) {
                cols = malloc(sizeof(int) * (size_t)space);
                vals = malloc(sizeof(double) * (size_t)space);
                if (!cols || !vals) {
                    st = mpm_error(MPM_EINTERNAL, "out of memory: ml_getrow_matvec");
                    break;
                }
            }
            if (ML_Operator_Getrow(&s->ml->Amat[0], 1, &row, space, cols, vals, &len)) break;
            free(cols);
            free(vals);
            cols = NULL;
            vals = NULL;
            space *= 2;
        }
        if (st) break;
        double acc = 0.0;
        for (int k = 0; k < len; ++k) acc += vals[k] * x[cols[k]];
        y[row] = acc;
    }
    free(cols);
    free(vals);
    return st;
}

static void ml_view(const InvApprox *self, FILE *f, InvView *out)
{
    const Ml *s = (const Ml *)self;
    if (f)
        fprintf(f, "  Trilinos ML smoothed aggregation V-cycle: %d unknowns, %d levels, operator complexity %.3f, %s\n",
                3 * s->n, s->n_levels, s->op_complexity, s->smoother == ML_SMOOTH_CHEBY ? "Chebyshev" : "SGS");
    inv_view_add(out, "levels", s->n_levels);
    inv_view_add(out, "operator_complexity", s->op_complexity);
    inv_view_add(out, "library_threads", 1); /* ML's own set-up and coarse levels */
}

const InvApproxOps inv_ml_ops = {"ml",       "one Trilinos ML smoothed-aggregation V-cycle (elasticity null space)",
                                 ml_create,  ml_setup,
                                 ml_apply,   ml_view,
                                 ml_destroy, ml_library_startup,
                                 ml_reuse,   ml_library_version};
