/* hypre BoomerAMG V-cycle behind the InvApprox interface (docs/design.md, "the one
 * idea": PN-AMG-PCG and LBFGS-AMG; SPEC 7).
 *
 * API use follows the hypre Reference Manual and User's Manual (2.26,
 * hypre.readthedocs.io: "IJ System Interface", "ParCSR Solvers / BoomerAMG")
 * and the comments in HYPRE_IJ_mv.h / HYPRE_parcsr_ls.h.
 *
 * Choices (all from the documented option lists):
 *  - BoomerAMG as a preconditioner: MaxIter 1, Tol 0 -> one V-cycle per
 *    Solve; the initial guess is set to zero before every Solve.
 *  - Symmetry: relax type 6 (hybrid symmetric Gauss-Seidel; on one process
 *    a plain forward+backward GS sweep) or 8 (its l1 variant) on both the
 *    down and the up cycle, relaxation order 0 (lexicographic; CF order
 *    would still be symmetric but we keep the simplest), Gaussian elimination
 *    on the coarsest level, Galerkin RAP with R = P^T. The V-cycle operator
 *    is then symmetric positive definite, as CG requires.
 *  - Systems AMG: NumFunctions 3 with the default dof map (0,1,2,0,1,2,...)
 *    which is exactly our node-major interleaving (SPEC 1).
 *  - Nodal coarsening, default 4 (row-sum norm of each 3x3 block): a norm
 *    makes every coupled node pair a strength candidate whatever the signs
 *    of the block entries, which suits elasticity blocks (not M-matrix
 *    blocks); 6 (signed sum of the block) presumes negative off-diagonal
 *    blocks as in a vector Laplacian. Measured PCG iterations to 1e-8
 *    (tests/conformance/test_adapters.c): spring-network matrix, HMIS+4: 7 vs
 *    PMIS+6: 6; MPM Hessian (test fixture, 2197 nodes, dt 1e-2): nodal 4:
 *    30, 6: 30, 1: 31, 0: 29 (block Jacobi 115). No measurable difference,
 *    so the choice rests on the sign argument.
 *  - HMIS coarsening with extended+i interpolation truncated to 4 entries a
 *    row: hypre's defaults and its recommendation for 3D problems, with
 *    strength threshold 0.5 (User's Manual, BoomerAMG section). On MPM
 *    Hessians (125-block rows) HMIS coarsens very fast (operator complexity
 *    about 1.05); on a 3375-node fixture (two materials, E 1e4 / 3e6) at
 *    dt 1e-2 and 5e-2, falgout, thresholds 0.25-0.95, no truncation,
 *    aggressive levels or rigid-body interpolation vectors all changed the
 *    PCG iteration count by under 10% (28 and 79 iterations; block Jacobi
 *    109 and 378, colored SGS 40 and 121); two sweeps gave -30% iterations
 *    for +100% per V-cycle.
 *  - amg_rbm: rotation modes x (e_k) about the centroid of the integer node
 *    coordinates, zeroed by the Dirichlet projection, passed with
 *    HYPRE_BoomerAMGSetInterpVectors (GM variants 1, 2 or LN variant 3);
 *    translations are already reproduced by unknown-based interpolation.
 *
 * Threads: the Debian libHYPRE is built without OpenMP (HYPRE_USING_OPENMP
 * undefined), so hypre itself runs on one thread; the conversion loops here
 * are OpenMP-parallel. */
/* _hypre_utilities.h (pulled in by _hypre_parcsr_ls.h below) calls ffs()
 * without including <strings.h>, which declares it only with X/Open
 * extensions on top of the project's _POSIX_C_SOURCE. */
#define _XOPEN_SOURCE 700
#include <strings.h>

#include "adapters/boomeramg.h"

#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_ls.h>
#include <HYPRE_parcsr_mv.h>
#include <HYPRE_utilities.h>
/* hypre's own (installed) internal header, read-only access to the AMG
 * hierarchy for boomeramg_info: the public HYPRE_BoomerAMGGetGridHierarchy
 * leaks memory in 2.26 (found with valgrind). */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter" /* inline helpers in hypre's headers */
#include <_hypre_parcsr_ls.h>
#pragma GCC diagnostic pop
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/mpi_startup.h"
#include "core/error.h"

/* hypre is configured with 32-bit HYPRE_Int/HYPRE_BigInt in Debian 12's
 * libhypre-dev; the conversion below relies on it. */
#if defined(HYPRE_BIGINT) || defined(HYPRE_MIXEDINT) || defined(HYPRE_COMPLEX) || defined(HYPRE_SINGLE) || \
    defined(HYPRE_LONG_DOUBLE)
#error "adapters/boomeramg.c expects hypre built with 32-bit integers and double precision"
#endif

enum { AMG_CHUNK_ROWS = 1024 }; /* block rows passed to IJMatrixSetValues per call */

typedef struct {
    InvApprox base;
    /* options */
    double strong;
    int coarsen, nodal, agg_levels, interp, pmax, relax, sweeps, rbm, max_levels;
    int nodal_diag, agg_interp, agg_pmax, num_paths, cheby_order, rbm_qmax;
    double trunc;
    /* matrix (rebuilt every setup, see build_matrix); NULL = none */
    HYPRE_IJMatrix ij;
    HYPRE_ParCSRMatrix par;
    /* vectors (kept while the size is unchanged); NULL = none */
    HYPRE_IJVector bij, xij;
    HYPRE_ParVector bpar, xpar;
    int vec_n;
    HYPRE_BigInt *idx; /* 0 .. 3n-1 */
    int cap_idx;
    /* chunk buffers for IJMatrixSetValues */
    HYPRE_Int *ncols;
    HYPRE_BigInt *rows, *cols;
    double *vals;
    int64_t cap_chunk_rows, cap_chunk_nz;
    /* rotation modes for interpolation (amg_rbm); NULL = none */
    HYPRE_IJVector rot_ij[3];
    HYPRE_ParVector rot_par[3];
    /* solver; NULL = none (no successful setup) */
    HYPRE_Solver amg;
    int n;
} Amg;

static int g_hypre_ready = 0;

/* At exit: hypre's global state is released (before MPI's finaliser,
 * registered earlier by adapter_mpi_start), so leak checkers see a clean
 * process. */
static void hypre_global_finalize(void)
{
    if (!g_hypre_ready) return;
    HYPRE_Finalize(); /* frees hypre's memory; calls no MPI */
    g_hypre_ready = 0;
}

/* MPI (adapters/mpi_startup.h) and hypre's initialisation, once per process. */
static int hypre_global_init(void)
{
    if (g_hypre_ready) return MPM_OK;
    int st = adapter_mpi_start("boomeramg");
    if (st) return st;
    if (HYPRE_Init() != 0) {
        HYPRE_ClearAllErrors();
        return mpm_error(MPM_EINTERNAL, "boomeramg: HYPRE_Init failed");
    }
    g_hypre_ready = 1;
    atexit(hypre_global_finalize);
    return MPM_OK;
}

/* hypre keeps a sticky global error flag; turn it into an mpm_error. The
 * "did not converge" bit is expected with MaxIter 1 and ignored. */
static int hy_check(HYPRE_Int ierr, const char *what)
{
    if (!ierr) return MPM_OK;
    HYPRE_ClearAllErrors();
    if (ierr == HYPRE_ERROR_CONV) return MPM_OK;
    char desc[1024] = "";
    HYPRE_DescribeError(ierr, desc);
    return mpm_error(MPM_EINTERNAL, "boomeramg: %s failed (hypre error %d: %s)", what, (int)ierr, desc);
}

/* An integer option in [lo, hi]: a one-line error naming key and value. */
static int opt_int_in(SolverOptions *opt, const char *key, int def, int lo, int hi, int *status)
{
    if (*status) return def;
    double v = solver_opt_number(opt, key, def, status);
    if (*status) return def;
    if (!(v >= lo && v <= hi && v == (int)v)) {
        *status = mpm_error(MPM_EINPUT, "--solver-opt %s=%g: expected an integer in [%d, %d]", key, v, lo, hi);
        return def;
    }
    return (int)v;
}

static int amg_create(SolverOptions *opt, InvApprox **out)
{
    int st = MPM_OK;
    double strong = solver_opt_number(opt, "amg_strong_threshold", 0.5, &st);
    double nodal = solver_opt_number(opt, "amg_nodal", 4, &st);
    double agg = solver_opt_number(opt, "amg_agg_levels", 0, &st);
    double interp = solver_opt_number(opt, "amg_interp", 6, &st);
    double pmax = solver_opt_number(opt, "amg_pmax", 4, &st);
    double relax = solver_opt_number(opt, "amg_relax", 6, &st);
    double sweeps = solver_opt_number(opt, "amg_sweeps", 1, &st);
    double rbm = solver_opt_number(opt, "amg_rbm", 0, &st);
    double max_levels = solver_opt_number(opt, "amg_max_levels", 25, &st);
    double trunc = solver_opt_number(opt, "amg_trunc", 0.0, &st);
    const char *coarsen = solver_opt_string(opt, "amg_coarsen", "HMIS");
    /* hypre 2.26's HYPRE_parcsr_ls.h documents each range */
    int nodal_diag = opt_int_in(opt, "amg_nodal_diag", 0, 0, 2, &st);
    int agg_interp = opt_int_in(opt, "amg_agg_interp", 4, 1, 7, &st);
    int agg_pmax = opt_int_in(opt, "amg_agg_pmax", 0, 0, 1000, &st);
    int num_paths = opt_int_in(opt, "amg_num_paths", 1, 1, 100, &st);
    int cheby_order = opt_int_in(opt, "amg_cheby_order", 2, 1, 4, &st);
    int rbm_qmax = opt_int_in(opt, "amg_rbm_qmax", 0, 0, 1000, &st);
    if (st) return st;
    if (!(strong > 0.0 && strong < 1.0))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_strong_threshold=%g: expected a value in (0, 1)", strong);
    if (!(nodal == 0 || nodal == 1 || nodal == 2 || nodal == 3 || nodal == 4 || nodal == 6))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_nodal=%g: expected 0, 1, 2, 3, 4 or 6", nodal);
    if (!(agg >= 0 && agg <= 20 && agg == (int)agg))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_agg_levels=%g: expected an integer in [0, 20]", agg);
    /* interpolations that keep working with systems AMG here; the block
     * variants 10 and 11 gave a non-convergent PCG on MPM Hessians */
    if (!(interp == 0 || interp == 3 || interp == 6 || interp == 8 || interp == 14))
        return mpm_error(MPM_EINPUT,
                         "--solver-opt amg_interp=%g: expected 0 (classical), 3 (direct), 6 (extended+i), "
                         "8 (standard) or 14 (extended)",
                         interp);
    if (!(pmax >= 0 && pmax <= 1000 && pmax == (int)pmax))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_pmax=%g: expected an integer in [0, 1000]", pmax);
    if (!(trunc >= 0.0 && trunc < 1.0))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_trunc=%g: expected a value in [0, 1)", trunc);
    /* smoothers that keep the V-cycle symmetric: symmetric ones on both
     * legs (6, 8, 16 Chebyshev, 18 l1-Jacobi), or a forward sweep down with
     * its backward twin up (3 -> 3/4, 13 -> 13/14) */
    if (!(relax == 3 || relax == 6 || relax == 8 || relax == 13 || relax == 16 || relax == 18))
        return mpm_error(MPM_EINPUT,
                         "--solver-opt amg_relax=%g: expected 6 or 8 (symmetric Gauss-Seidel), 3 or 13 (forward down, "
                         "backward up), 16 (Chebyshev) or 18 (l1-Jacobi): the V-cycle must stay symmetric for CG",
                         relax);
    if (!(sweeps >= 1 && sweeps <= 100 && sweeps == (int)sweeps))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_sweeps=%g: expected an integer in [1, 100]", sweeps);
    if (!(rbm == 0 || rbm == 1 || rbm == 2 || rbm == 3))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_rbm=%g: expected 0 (off) or an interpolation variant 1..3", rbm);
    if (rbm && nodal == 0)
        return mpm_error(MPM_EINPUT, "--solver-opt amg_rbm=%g: needs nodal coarsening (amg_nodal != 0)", rbm);
    if (!(max_levels >= 1 && max_levels <= 100 && max_levels == (int)max_levels))
        return mpm_error(MPM_EINPUT, "--solver-opt amg_max_levels=%g: expected an integer in [1, 100]", max_levels);
    int ctype;
    if (strcasecmp(coarsen, "HMIS") == 0) ctype = 10;
    else if (strcasecmp(coarsen, "PMIS") == 0) ctype = 8;
    else if (strcasecmp(coarsen, "falgout") == 0) ctype = 6;
    else return mpm_error(MPM_EINPUT, "--solver-opt amg_coarsen=%s: expected HMIS, PMIS or falgout", coarsen);

    Amg *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg");
    s->strong = strong;
    s->coarsen = ctype;
    s->nodal = (int)nodal;
    s->agg_levels = (int)agg;
    s->interp = (int)interp;
    s->pmax = (int)pmax;
    s->relax = (int)relax;
    s->sweeps = (int)sweeps;
    s->rbm = (int)rbm;
    s->max_levels = (int)max_levels;
    s->trunc = trunc;
    s->nodal_diag = nodal_diag;
    s->agg_interp = agg_interp;
    s->agg_pmax = agg_pmax;
    s->num_paths = num_paths;
    s->cheby_order = cheby_order;
    s->rbm_qmax = rbm_qmax;
    s->base.ops = &inv_boomeramg_ops;
    s->base.caps = INV_NEEDS_HESSIAN | INV_SYMMETRIC | INV_POSITIVE;
#ifndef HYPRE_USING_OPENMP
    /* hypre's setup and V-cycle run on one thread (the matrix conversion
     * before them is OpenMP-parallel) */
    s->base.setup_threads = s->base.apply_threads = 1;
#endif
    *out = &s->base;
    return MPM_OK;
}

static void destroy_solver(Amg *s)
{
    if (s->amg) HYPRE_BoomerAMGDestroy(s->amg);
    s->amg = NULL;
}

static void destroy_matrix(Amg *s)
{
    if (s->ij) HYPRE_IJMatrixDestroy(s->ij); /* also frees the ParCSR object */
    s->ij = NULL;
    s->par = NULL;
}

static void destroy_rot(Amg *s)
{
    for (int k = 0; k < 3; ++k) {
        if (s->rot_ij[k]) HYPRE_IJVectorDestroy(s->rot_ij[k]);
        s->rot_ij[k] = NULL;
        s->rot_par[k] = NULL;
    }
}

/* Rotation modes (0,-z,y), (z,0,-x), (-y,x,0) about the centroid, zero where
 * the projection removes them (Dirichlet nodes). */
static int build_rot(Amg *s, const InvSetupInput *in)
{
    destroy_rot(s);
    if (!in->coord) return mpm_error(MPM_EINTERNAL, "boomeramg: amg_rbm needs node coordinates");
    const int n = in->n_nodes, N = 3 * n;
    double c[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) c[d] += in->coord[3 * i + d];
    for (int d = 0; d < 3; ++d) c[d] /= n > 0 ? n : 1;
    double *v = malloc(sizeof(double) * (size_t)N);
    if (!v) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg");
    HYPRE_Int e = 0;
    for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < n; ++i) {
            double x = in->coord[3 * i] - c[0], y = in->coord[3 * i + 1] - c[1], z = in->coord[3 * i + 2] - c[2];
            double *vi = v + 3 * i;
            if (k == 0) vi[0] = 0, vi[1] = -z, vi[2] = y;
            else if (k == 1) vi[0] = z, vi[1] = 0, vi[2] = -x;
            else vi[0] = -y, vi[1] = x, vi[2] = 0;
        }
        projection_apply(in->proj, v);
        e |= HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, N - 1, &s->rot_ij[k]);
        e |= HYPRE_IJVectorSetObjectType(s->rot_ij[k], HYPRE_PARCSR);
        e |= HYPRE_IJVectorInitialize(s->rot_ij[k]);
        e |= HYPRE_IJVectorSetValues(s->rot_ij[k], N, s->idx, v);
        e |= HYPRE_IJVectorAssemble(s->rot_ij[k]);
        e |= HYPRE_IJVectorGetObject(s->rot_ij[k], (void **)&s->rot_par[k]);
    }
    free(v);
    return hy_check(e, "rigid-body-mode vectors");
}

static void destroy_vectors(Amg *s)
{
    if (s->bij) HYPRE_IJVectorDestroy(s->bij);
    if (s->xij) HYPRE_IJVectorDestroy(s->xij);
    s->bij = s->xij = NULL;
    s->bpar = s->xpar = NULL;
}

static int ensure_vectors(Amg *s, int n)
{
    if (s->bij && s->xij && s->vec_n == n) return MPM_OK;
    destroy_vectors(s);
    const int N = 3 * n;
    if (N > s->cap_idx) {
        HYPRE_BigInt *p = realloc(s->idx, sizeof(HYPRE_BigInt) * (size_t)N);
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg (%d unknowns)", N);
        s->idx = p;
        s->cap_idx = N;
    }
    for (int k = 0; k < N; ++k) s->idx[k] = k;
    HYPRE_Int e = 0;
    e |= HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, N - 1, &s->bij);
    e |= HYPRE_IJVectorSetObjectType(s->bij, HYPRE_PARCSR);
    e |= HYPRE_IJVectorInitialize(s->bij);
    e |= HYPRE_IJVectorAssemble(s->bij);
    e |= HYPRE_IJVectorGetObject(s->bij, (void **)&s->bpar);
    e |= HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, N - 1, &s->xij);
    e |= HYPRE_IJVectorSetObjectType(s->xij, HYPRE_PARCSR);
    e |= HYPRE_IJVectorInitialize(s->xij);
    e |= HYPRE_IJVectorAssemble(s->xij);
    e |= HYPRE_IJVectorGetObject(s->xij, (void **)&s->xpar);
    s->vec_n = n; /* on error the caller destroys whatever was created */
    return hy_check(e, "vector creation");
}

/* Fills the chunk buffers with scalar rows of block rows [I0, I1). */
static int fill_chunk(Amg *s, const Bsr *H, int I0, int I1)
{
    const int64_t nb = H->row_ptr[I1] - H->row_ptr[I0];
    const int64_t rows = 3 * (int64_t)(I1 - I0), nz = 9 * nb;
    if (rows > s->cap_chunk_rows) {
        HYPRE_Int *nc = realloc(s->ncols, sizeof(HYPRE_Int) * (size_t)rows);
        if (!nc) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg");
        s->ncols = nc;
        HYPRE_BigInt *r = realloc(s->rows, sizeof(HYPRE_BigInt) * (size_t)rows);
        if (!r) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg");
        s->rows = r;
        s->cap_chunk_rows = rows;
    }
    if (nz > s->cap_chunk_nz) {
        int64_t cap = nz + nz / 8 + 64;
        HYPRE_BigInt *c = realloc(s->cols, sizeof(HYPRE_BigInt) * (size_t)cap);
        if (!c) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg (%lld entries)", (long long)cap);
        s->cols = c;
        double *v = realloc(s->vals, sizeof(double) * (size_t)cap);
        if (!v) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg (%lld entries)", (long long)cap);
        s->vals = v;
        s->cap_chunk_nz = cap;
    }
    const int64_t base = H->row_ptr[I0];
#pragma omp parallel for schedule(static)
    for (int I = I0; I < I1; ++I) {
        const int64_t k0 = H->row_ptr[I], k1 = H->row_ptr[I + 1], len = k1 - k0;
        for (int a = 0; a < 3; ++a) {
            const int64_t r = 3 * (int64_t)(I - I0) + a;
            s->rows[r] = 3 * I + a;
            s->ncols[r] = (HYPRE_Int)(3 * len);
            /* scalar row 3I+a: rows of block row I laid out one after another */
            int64_t q = 9 * (k0 - base) + 3 * len * a;
            for (int64_t k = k0; k < k1; ++k) {
                const double *blk = H->val + 9 * k + 3 * a;
                const int J = H->col[k];
                for (int b = 0; b < 3; ++b, ++q) {
                    s->cols[q] = 3 * J + b;
                    s->vals[q] = blk[b];
                }
            }
        }
    }
    return MPM_OK;
}

/* A new IJ matrix every setup. hypre allows re-opening an assembled matrix
 * (HYPRE_IJMatrixInitialize) and overwriting its values, but its assembled-
 * matrix SetValues searches each row linearly for every entry; with ~375
 * entries a row that measured about twice as slow as building a fresh
 * preallocated matrix (e.g. 0.73 s vs 0.36 s on a 3360-node, 125-block-
 * stencil test matrix), so the matrix object is not reused. */
static int build_matrix(Amg *s, const Bsr *H)
{
    const int n = H->n, N = 3 * n;
    destroy_matrix(s);
    HYPRE_Int e = HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, N - 1, 0, N - 1, &s->ij);
    if (e) return hy_check(e, "HYPRE_IJMatrixCreate");
    e |= HYPRE_IJMatrixSetObjectType(s->ij, HYPRE_PARCSR);
    /* exact row sizes (all in the process-local "diag" part, none off-process)
     * so hypre allocates once */
    HYPRE_Int *sizes = malloc(sizeof(HYPRE_Int) * 2 * (size_t)N);
    if (!sizes) return mpm_error(MPM_EINTERNAL, "out of memory: boomeramg (%d rows)", N);
    for (int I = 0; I < n; ++I)
        for (int a = 0; a < 3; ++a) sizes[3 * I + a] = (HYPRE_Int)(3 * (H->row_ptr[I + 1] - H->row_ptr[I]));
    memset(sizes + N, 0, sizeof(HYPRE_Int) * (size_t)N);
    e |= HYPRE_IJMatrixSetDiagOffdSizes(s->ij, sizes, sizes + N);
    e |= HYPRE_IJMatrixInitialize(s->ij);
    free(sizes);
    int st = hy_check(e, "matrix creation");
    if (st) return st;
    for (int I0 = 0; I0 < n; I0 += AMG_CHUNK_ROWS) {
        int I1 = I0 + AMG_CHUNK_ROWS < n ? I0 + AMG_CHUNK_ROWS : n;
        st = fill_chunk(s, H, I0, I1);
        if (st) return st;
        e |= HYPRE_IJMatrixSetValues(s->ij, 3 * (I1 - I0), s->ncols, s->rows, s->cols, s->vals);
    }
    e |= HYPRE_IJMatrixAssemble(s->ij);
    e |= HYPRE_IJMatrixGetObject(s->ij, (void **)&s->par);
    return hy_check(e, "matrix assembly");
}

static int build_solver(Amg *s)
{
    HYPRE_Int e = HYPRE_BoomerAMGCreate(&s->amg);
    if (e) return hy_check(e, "HYPRE_BoomerAMGCreate");
    e |= HYPRE_BoomerAMGSetPrintLevel(s->amg, 0);
    e |= HYPRE_BoomerAMGSetMaxIter(s->amg, 1);
    e |= HYPRE_BoomerAMGSetTol(s->amg, 0.0);
    e |= HYPRE_BoomerAMGSetMaxLevels(s->amg, s->max_levels);
    e |= HYPRE_BoomerAMGSetNumFunctions(s->amg, 3);
    e |= HYPRE_BoomerAMGSetNodal(s->amg, s->nodal);
    e |= HYPRE_BoomerAMGSetStrongThreshold(s->amg, s->strong);
    e |= HYPRE_BoomerAMGSetCoarsenType(s->amg, s->coarsen);
    e |= HYPRE_BoomerAMGSetAggNumLevels(s->amg, s->agg_levels);
    e |= HYPRE_BoomerAMGSetInterpType(s->amg, s->interp);
    e |= HYPRE_BoomerAMGSetPMaxElmts(s->amg, s->pmax);
    e |= HYPRE_BoomerAMGSetNodalDiag(s->amg, s->nodal_diag);
    e |= HYPRE_BoomerAMGSetNumPaths(s->amg, s->num_paths);
    e |= HYPRE_BoomerAMGSetAggInterpType(s->amg, s->agg_interp);
    e |= HYPRE_BoomerAMGSetAggPMaxElmts(s->amg, s->agg_pmax);
    e |= HYPRE_BoomerAMGSetTruncFactor(s->amg, s->trunc);
    e |= HYPRE_BoomerAMGSetRelaxType(s->amg, s->relax);          /* down and up; coarsest -> 9 */
    if (s->relax == 3 || s->relax == 13) /* a forward sweep down, its backward twin up: symmetric */
        e |= HYPRE_BoomerAMGSetCycleRelaxType(s->amg, s->relax + 1, 2);
    if (s->relax == 16) e |= HYPRE_BoomerAMGSetChebyOrder(s->amg, s->cheby_order);
    e |= HYPRE_BoomerAMGSetCycleRelaxType(s->amg, 9, 3);         /* Gaussian elimination on the coarsest level */
    e |= HYPRE_BoomerAMGSetRelaxOrder(s->amg, 0);
    e |= HYPRE_BoomerAMGSetNumSweeps(s->amg, s->sweeps);
    e |= HYPRE_BoomerAMGSetCycleNumSweeps(s->amg, 1, 3);
    if (s->rbm) {
        e |= HYPRE_BoomerAMGSetInterpVectors(s->amg, 3, s->rot_par);
        e |= HYPRE_BoomerAMGSetInterpVecVariant(s->amg, s->rbm);
        if (s->rbm_qmax) e |= HYPRE_BoomerAMGSetInterpVecQMax(s->amg, s->rbm_qmax);
    }
    int st = hy_check(e, "BoomerAMG options");
    if (st) return st;
    /* Setup only reads b and x for their layout. */
    e = HYPRE_BoomerAMGSetup(s->amg, s->par, s->bpar, s->xpar);
    return hy_check(e, "HYPRE_BoomerAMGSetup");
}

static int amg_setup(InvApprox *self, const InvSetupInput *in)
{
    Amg *s = (Amg *)self;
    self->stats = (InvStats){0};
    destroy_solver(s);
    destroy_matrix(s); /* free the old copy before building the new one */
    const Bsr *H = in->H;
    if (!H) return mpm_error(MPM_EINTERNAL, "boomeramg: needs the assembled Hessian (matrix-free PN is not supported)");
    if (H->n != in->n_nodes)
        return mpm_error(MPM_EINTERNAL, "boomeramg: Hessian has %d block rows but the problem %d nodes", H->n,
                         in->n_nodes);
    if (3 * (int64_t)H->n > (int64_t)0x7fffffff || 9 * H->row_ptr[H->n] > (int64_t)0x7fffffff)
        return mpm_error(MPM_EINTERNAL, "boomeramg: Hessian too large for hypre's 32-bit indices (%d nodes, %lld blocks)",
                         H->n, (long long)H->nnzb);
    s->n = H->n;
    if (H->n == 0) return MPM_OK;
    int st = hypre_global_init();
    if (!st) st = ensure_vectors(s, H->n);
    if (!st) st = build_matrix(s, H);
    if (!st && s->rbm) st = build_rot(s, in);
    if (!st) st = build_solver(s);
    if (st) {
        /* leave nothing half-built behind: the next setup starts afresh */
        destroy_solver(s);
        destroy_matrix(s);
        destroy_vectors(s);
        destroy_rot(s);
        return st;
    }
    return MPM_OK;
}

/* Setup reuse (inverse_approx.h): the hierarchy and its copy of the matrix
 * are kept as they are, a lagged preconditioner, whatever `values` asks:
 * hypre 2.26 has no update of a whole hierarchy's values short of a new
 * BoomerAMGSetup (only its fine-level matrix could be overwritten, which
 * would leave the smoother and the coarse operators inconsistent). */
static int amg_reuse(InvApprox *self, const InvSetupInput *in, int values, int *refreshed)
{
    Amg *s = (Amg *)self;
    (void)values;
    *refreshed = 0;
    if (!in->H || in->H->n != s->n) return mpm_error(MPM_EINTERNAL, "boomeramg: reused for a different matrix");
    return MPM_OK;
}

static int amg_apply(InvApprox *self, const double *r, double *z)
{
    Amg *s = (Amg *)self;
    if (s->n == 0) return MPM_OK;
    if (!s->amg) return mpm_error(MPM_EINTERNAL, "boomeramg: apply without a successful setup");
    const int N = 3 * s->n;
    HYPRE_Int e = 0;
    e |= HYPRE_IJVectorSetValues(s->bij, N, s->idx, r);
    e |= HYPRE_ParVectorSetConstantValues(s->xpar, 0.0);
    int st = hy_check(e, "vector update");
    if (st) return st;
    e = HYPRE_BoomerAMGSolve(s->amg, s->par, s->bpar, s->xpar);
    st = hy_check(e, "HYPRE_BoomerAMGSolve");
    if (st) return st;
    e = HYPRE_IJVectorGetValues(s->xij, N, s->idx, z);
    st = hy_check(e, "vector read-back");
    return st;
}

static void amg_destroy(InvApprox *self)
{
    if (!self) return;
    Amg *s = (Amg *)self;
    destroy_solver(s);
    destroy_matrix(s);
    destroy_vectors(s);
    destroy_rot(s);
    free(s->idx);
    free(s->ncols);
    free(s->rows);
    free(s->cols);
    free(s->vals);
    free(s);
}

int boomeramg_info(const InvApprox *self, int *levels, double *op_complexity)
{
    if (!self || self->ops != &inv_boomeramg_ops)
        return mpm_error(MPM_EINTERNAL, "boomeramg_info: not a boomeramg inverse approximation");
    const Amg *s = (const Amg *)self;
    if (!s->amg) return mpm_error(MPM_EINTERNAL, "boomeramg_info: no hierarchy (setup not done or failed)");
    /* a HYPRE_Solver made by HYPRE_BoomerAMGCreate is a hypre_ParAMGData */
    hypre_ParAMGData *d = (hypre_ParAMGData *)s->amg;
    const int nl = hypre_ParAMGDataNumLevels(d);
    hypre_ParCSRMatrix **A = hypre_ParAMGDataAArray(d);
    double fine = 0.0, total = 0.0;
    for (int l = 0; l < nl && A; ++l) {
        if (!A[l]) continue;
        hypre_CSRMatrix *D = hypre_ParCSRMatrixDiag(A[l]), *O = hypre_ParCSRMatrixOffd(A[l]);
        double nnz = (D ? (double)hypre_CSRMatrixNumNonzeros(D) : 0.0) + (O ? (double)hypre_CSRMatrixNumNonzeros(O) : 0.0);
        if (l == 0) fine = nnz;
        total += nnz;
    }
    if (levels) *levels = nl;
    if (op_complexity) *op_complexity = fine > 0 ? total / fine : 0.0;
    return MPM_OK;
}

int boomeramg_matvec(InvApprox *self, const double *x, double *y)
{
    if (!self || self->ops != &inv_boomeramg_ops)
        return mpm_error(MPM_EINTERNAL, "boomeramg_matvec: not a boomeramg inverse approximation");
    Amg *s = (Amg *)self;
    if (!s->amg) return mpm_error(MPM_EINTERNAL, "boomeramg_matvec: no matrix (setup not done or failed)");
    const int N = 3 * s->n;
    HYPRE_Int e = HYPRE_IJVectorSetValues(s->bij, N, s->idx, x);
    e |= HYPRE_ParCSRMatrixMatvec(1.0, s->par, s->bpar, 0.0, s->xpar);
    e |= HYPRE_IJVectorGetValues(s->xij, N, s->idx, y);
    return hy_check(e, "matrix-vector product");
}

static void amg_view(const InvApprox *self, FILE *f, InvView *out)
{
    int levels = 0;
    double cx = 0.0;
    const Amg *s = (const Amg *)self;
    if (s->amg && boomeramg_info(self, &levels, &cx) != MPM_OK) levels = 0;
    if (f) fprintf(f, "  hypre BoomerAMG V-cycle: %d unknowns, %d levels, operator complexity %.3f\n", 3 * s->n, levels, cx);
    inv_view_add(out, "levels", levels);
    inv_view_add(out, "operator_complexity", cx);
}

const InvApproxOps inv_boomeramg_ops = {"boomeramg", "one hypre BoomerAMG V-cycle (systems AMG, symmetric smoothing)",
                                        amg_create,  amg_setup,
                                        amg_apply,   amg_view,
                                        amg_destroy, boomeramg_library_startup,
                                        amg_reuse,   boomeramg_library_version};

/* ---- library start-up and version (header: "Start-up") ---- */

int boomeramg_library_startup(void) { return hypre_global_init(); }

const char *boomeramg_library_version(void) { return HYPRE_RELEASE_VERSION; }
