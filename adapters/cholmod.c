/* CHOLMOD direct solver behind the InvApprox interface (docs/design.md, "the one idea":
 * PN-CHOLMOD and LBFGS-H-direct; SPEC 7).
 *
 * API use follows the CHOLMOD user guide (SuiteSparse 5.x, CHOLMOD/Doc/
 * CHOLMOD_UserGuide.pdf): cholmod_l_start / cholmod_l_analyze /
 * cholmod_l_factorize / cholmod_l_solve2 / cholmod_l_finish, the 64-bit index
 * ("_l_") variants so that large factors do not overflow int.
 *
 * Conversion. H is stored as full symmetric 3x3-block CSR with sorted columns.
 * Because H = H^T, its CSR arrays read as CSC describe the same matrix, so
 * scalar column j of the CHOLMOD matrix is scalar row j of H. We keep the
 * lower triangle (stype = -1: entries with row index >= column index), i.e.
 * from scalar row j of H the entries with scalar column >= j, which are
 * already in increasing order (blocks sorted, then b = 0..2 within a block):
 * the CHOLMOD matrix is "sorted" and "packed" without any sort. */
#include "adapters/cholmod.h"

#include <cholmod.h>
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

typedef SuiteSparse_long Sl;

typedef struct {
    InvApprox base;
    cholmod_common c;
    int started;
    cholmod_sparse *A;    /* scalar lower triangle, capacity cap_cols x cap_nz */
    Sl cap_cols, cap_nz;
    Sl *blk_off;          /* n + 1: start of each block row's entries in A->i/A->x */
    int *blk_first;       /* n: first block of the row with column >= row */
    int cap_rows;
    cholmod_factor *L;    /* symbolic (+ numeric after a successful setup) */
    cholmod_dense *X, *Y, *E; /* solve2 result and workspaces, reused */
    int n;                /* block rows of the current factor */
    int have_factor;      /* numeric factor valid for apply */
    int analyzed;         /* L holds a usable symbolic analysis of (an_n, an_pattern, an_nnzb) */
    int an_n;
    int64_t an_nnzb;
    uint64_t an_pattern;
    int analyze_count;
    long factorize_count;  /* numeric factorisations */
    long symbolic_reuses;  /* of them, on a kept symbolic analysis */
    double lnz;
} CholDirect;

static const char *cholmod_status_str(int s)
{
    switch (s) {
    case CHOLMOD_OK: return "ok";
    case CHOLMOD_NOT_INSTALLED: return "method not installed";
    case CHOLMOD_OUT_OF_MEMORY: return "out of memory";
    case CHOLMOD_TOO_LARGE: return "problem too large";
    case CHOLMOD_INVALID: return "invalid input";
    case CHOLMOD_GPU_PROBLEM: return "GPU problem";
    case CHOLMOD_NOT_POSDEF: return "not positive definite";
    case CHOLMOD_DSMALL: return "tiny diagonal entry";
    default: return "unknown status";
    }
}

static int chol_create(SolverOptions *opt, InvApprox **out)
{
    (void)opt; /* no options */
    CholDirect *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: cholmod");
    if (!cholmod_l_start(&s->c)) {
        free(s);
        return mpm_error(MPM_EINTERNAL, "cholmod: cholmod_l_start failed");
    }
    s->started = 1;
    /* Default settings (supernodal, automatic ordering choice); only CHOLMOD's
     * own printing is silenced: every failure is reported via mpm_error(). */
    s->c.print = 0;
    s->base.ops = &inv_cholmod_ops;
    s->base.caps = INV_NEEDS_HESSIAN | INV_SYMMETRIC | INV_POSITIVE;
    /* the supernodal factorisation and solves run in the BLAS: OpenBLAS's
     * own thread count when it is the BLAS loaded (else unknown: 0, the
     * run's OpenMP threads, is reported) */
    void *self = dlopen(NULL, RTLD_LAZY);
    void *sym = self ? dlsym(self, "openblas_get_num_threads") : NULL;
    if (sym) {
        int (*nthreads)(void);
        memcpy(&nthreads, &sym, sizeof nthreads); /* object pointer to function pointer, without a cast warning */
        s->base.setup_threads = s->base.apply_threads = nthreads();
    }
    if (self) dlclose(self);
    *out = &s->base;
    return MPM_OK;
}

static void free_sparse(CholDirect *s)
{
    if (!s->A) return;
    /* restore the allocated dimensions so CHOLMOD's memory accounting matches */
    s->A->nrow = s->A->ncol = (size_t)s->cap_cols;
    cholmod_l_free_sparse(&s->A, &s->c);
    s->cap_cols = s->cap_nz = 0;
}

static void drop_factor(CholDirect *s)
{
    if (s->L) cholmod_l_free_factor(&s->L, &s->c);
    s->have_factor = 0;
    s->analyzed = 0;
}

/* Sizes A for N scalar columns and nz entries (grows only) and fills the
 * pattern and values from H. */
static int convert(CholDirect *s, const Bsr *H)
{
    const int n = H->n;
    if (n > s->cap_rows) {
        Sl *o = realloc(s->blk_off, sizeof(Sl) * ((size_t)n + 1));
        if (!o) return mpm_error(MPM_EINTERNAL, "out of memory: cholmod (%d block rows)", n);
        s->blk_off = o;
        int *f = realloc(s->blk_first, sizeof(int) * (size_t)n);
        if (!f) return mpm_error(MPM_EINTERNAL, "out of memory: cholmod (%d block rows)", n);
        s->blk_first = f;
        s->cap_rows = n;
    }
    /* per block row: first block with column >= row, scalar entries kept */
    Sl *off = s->blk_off;
    int *first = s->blk_first;
#pragma omp parallel for schedule(static)
    for (int I = 0; I < n; ++I) {
        int64_t lo = H->row_ptr[I], hi = H->row_ptr[I + 1];
        while (lo < hi) { /* lower bound of I among sorted columns */
            int64_t mid = lo + (hi - lo) / 2;
            if (H->col[mid] < I) lo = mid + 1;
            else hi = mid;
        }
        first[I] = (int)(lo - H->row_ptr[I]);
        int64_t k = lo, end = H->row_ptr[I + 1];
        int has_diag = k < end && H->col[k] == I;
        int64_t upper = end - k - (has_diag ? 1 : 0);
        off[I + 1] = (Sl)(9 * upper + (has_diag ? 6 : 0));
    }
    off[0] = 0;
    for (int I = 0; I < n; ++I) off[I + 1] += off[I];
    const Sl N = 3 * (Sl)n, nz = off[n];

    if (!s->A || N > s->cap_cols || nz > s->cap_nz) {
        Sl cols = N > s->cap_cols ? N + N / 8 + 3 : s->cap_cols;
        Sl cap = nz > s->cap_nz ? nz + nz / 8 + 64 : s->cap_nz;
        free_sparse(s);
        s->A = cholmod_l_allocate_sparse((size_t)cols, (size_t)cols, (size_t)cap, 1, 1, -1, CHOLMOD_REAL, &s->c);
        if (!s->A)
            return mpm_error(MPM_EINTERNAL, "cholmod: cannot allocate a %ld x %ld matrix with %ld entries (%s)",
                             (long)cols, (long)cols, (long)cap, cholmod_status_str(s->c.status));
        s->cap_cols = cols;
        s->cap_nz = cap;
    }
    cholmod_sparse *A = s->A;
    A->nrow = A->ncol = (size_t)N;
    Sl *Ap = A->p, *Ai = A->i;
    double *Ax = A->x;
#pragma omp parallel for schedule(static)
    for (int I = 0; I < n; ++I) {
        const int64_t k0 = H->row_ptr[I] + first[I], end = H->row_ptr[I + 1];
        Sl q = off[I];
        for (int a = 0; a < 3; ++a) {
            Ap[3 * (Sl)I + a] = q;
            for (int64_t k = k0; k < end; ++k) {
                const int J = H->col[k];
                const double *blk = H->val + 9 * k + 3 * a; /* scalar row 3I+a of H */
                for (int b = (J == I ? a : 0); b < 3; ++b) {
                    Ai[q] = 3 * (Sl)J + b;
                    Ax[q] = blk[b];
                    ++q;
                }
            }
        }
    }
    Ap[N] = nz;
    return MPM_OK;
}

static int factorize(CholDirect *s);

static int chol_setup(InvApprox *self, const InvSetupInput *in)
{
    CholDirect *s = (CholDirect *)self;
    self->stats = (InvStats){0};
    s->have_factor = 0;
    const Bsr *H = in->H;
    if (!H) return mpm_error(MPM_EINTERNAL, "cholmod: needs the assembled Hessian (matrix-free PN is not supported)");
    if (H->n != in->n_nodes)
        return mpm_error(MPM_EINTERNAL, "cholmod: Hessian has %d block rows but the problem %d nodes", H->n,
                         in->n_nodes);
    s->n = H->n;
    if (H->n == 0) return MPM_OK;
    int st = convert(s, H);
    if (st) return st;

    if (!(s->analyzed && s->an_n == H->n && s->an_nnzb == H->nnzb && s->an_pattern == H->pattern_id)) {
        drop_factor(s);
        s->L = cholmod_l_analyze(s->A, &s->c);
        if (!s->L)
            return mpm_error(MPM_EINTERNAL, "cholmod: symbolic analysis of a %d-node Hessian failed (%s)", H->n,
                             cholmod_status_str(s->c.status));
        s->analyzed = 1;
        s->an_n = H->n;
        s->an_nnzb = H->nnzb;
        s->an_pattern = H->pattern_id;
        s->analyze_count++;
        s->lnz = s->c.lnz;
    } else {
        s->symbolic_reuses++;
    }
    return factorize(s);
}

/* Setup reuse (inverse_approx.h): values = 1 refactorises numerically on
 * the kept symbolic analysis (the same pattern: the wrapper checked it);
 * values = 0 keeps the factor of the earlier matrix (lagged). */
static int chol_reuse(InvApprox *self, const InvSetupInput *in, int values, int *refreshed)
{
    CholDirect *s = (CholDirect *)self;
    *refreshed = 0;
    const Bsr *H = in->H;
    if (!H || H->n != s->n) return mpm_error(MPM_EINTERNAL, "cholmod: reused for a different matrix");
    if (!values || H->n == 0) return MPM_OK;
    if (!(s->analyzed && s->an_n == H->n && s->an_nnzb == H->nnzb && s->an_pattern == H->pattern_id))
        return chol_setup(self, in); /* cannot happen through the wrapper; stay correct anyway */
    s->have_factor = 0;
    int st = convert(s, H);
    if (st) return st;
    s->symbolic_reuses++;
    st = factorize(s);
    *refreshed = st == MPM_OK;
    return st;
}

static int factorize(CholDirect *s)
{
    s->factorize_count++;
    int ok = cholmod_l_factorize(s->A, s->L, &s->c);
    if (!ok || s->c.status < CHOLMOD_OK || s->L->minor < s->L->n) {
        int status = s->c.status;
        const Sl minor = (Sl)s->L->minor, N = (Sl)s->L->n;
        /* L->minor counts pivots in the fill-reducing order; L->Perm maps it
         * back to our unknown (node-major, 3 per node) */
        const Sl *perm = s->L->Perm;
        const Sl u = (minor < N && perm) ? perm[minor] : minor;
        drop_factor(s); /* a broken-down supernodal factor is not reused */
        /* a Hessian that is not positive definite is a breakdown of the step */
        if (status == CHOLMOD_NOT_POSDEF || (ok && minor < N))
            return mpm_error(MPM_ENUMERIC,
                             "cholmod: Hessian is not positive definite (factorisation broke down at pivot %ld of "
                             "%ld, unknown %ld = node %ld component %ld)",
                             (long)minor, (long)N, (long)u, (long)(u / 3), (long)(u % 3));
        return mpm_error(MPM_EINTERNAL, "cholmod: numeric factorisation failed (%s)", cholmod_status_str(status));
    }
    s->have_factor = 1;
    return MPM_OK;
}

static int chol_apply(InvApprox *self, const double *r, double *z)
{
    CholDirect *s = (CholDirect *)self;
    if (s->n == 0) return MPM_OK;
    if (!s->have_factor) return mpm_error(MPM_EINTERNAL, "cholmod: apply without a successful setup");
    const size_t N = 3 * (size_t)s->n;
    /* A dense header around the caller's vector; CHOLMOD only reads B. */
    cholmod_dense B = {0};
    B.nrow = N;
    B.ncol = 1;
    B.nzmax = N;
    B.d = N;
    B.x = (void *)r;
    B.z = NULL;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_l_solve2(CHOLMOD_A, s->L, &B, NULL, &s->X, NULL, &s->Y, &s->E, &s->c))
        return mpm_error(MPM_EINTERNAL, "cholmod: triangular solves failed (%s)", cholmod_status_str(s->c.status));
    memcpy(z, s->X->x, sizeof(double) * N);
    return MPM_OK;
}

static void chol_destroy(InvApprox *self)
{
    if (!self) return;
    CholDirect *s = (CholDirect *)self;
    if (s->started) {
        drop_factor(s);
        free_sparse(s);
        if (s->X) cholmod_l_free_dense(&s->X, &s->c);
        if (s->Y) cholmod_l_free_dense(&s->Y, &s->c);
        if (s->E) cholmod_l_free_dense(&s->E, &s->c);
        cholmod_l_finish(&s->c);
    }
    free(s->blk_off);
    free(s->blk_first);
    free(s);
}

int cholmod_direct_info(const InvApprox *self, double *factor_nnz, int *analyze_count)
{
    if (!self || self->ops != &inv_cholmod_ops)
        return mpm_error(MPM_EINTERNAL, "cholmod_direct_info: not a cholmod inverse approximation");
    const CholDirect *s = (const CholDirect *)self;
    if (factor_nnz) *factor_nnz = s->analyzed ? s->lnz : 0.0;
    if (analyze_count) *analyze_count = s->analyze_count;
    return MPM_OK;
}

static void chol_view(const InvApprox *self, FILE *f, InvView *out)
{
    const CholDirect *s = (const CholDirect *)self;
    double lnz = s->analyzed ? s->lnz : 0.0;
    if (f)
        fprintf(f,
                "  CHOLMOD Cholesky: %d block rows, factor nonzeros %.0f, %d symbolic analyses, %ld numeric "
                "factorisations (%ld on a kept analysis)\n",
                s->n, lnz, s->analyze_count, s->factorize_count, s->symbolic_reuses);
    inv_view_add(out, "factor_nnz", lnz);
    inv_view_add(out, "analyses", s->analyze_count);
    inv_view_add(out, "factorizations", (double)s->factorize_count);
    inv_view_add(out, "symbolic_reuses", (double)s->symbolic_reuses);
}

const InvApproxOps inv_cholmod_ops = {"cholmod", "CHOLMOD sparse Cholesky factor of the Hessian, exact solves",
                                      chol_create,  chol_setup,
                                      chol_apply,   chol_view,
                                      chol_destroy, cholmod_library_startup,
                                      chol_reuse,   cholmod_library_version};

/* ---- library start-up and version (header: "Start-up") ---- */

int cholmod_library_startup(void)
{
    cholmod_common c;
    if (!cholmod_l_start(&c)) return mpm_error(MPM_EINTERNAL, "cholmod: cholmod_l_start failed");
    cholmod_l_finish(&c);
    return MPM_OK;
}

const char *cholmod_library_version(void)
{
    static char text[32];
    int v[3] = {0, 0, 0};
    cholmod_version(v); /* the library's, not the header's */
    snprintf(text, sizeof text, "%d.%d.%d", v[0], v[1], v[2]);
    return text;
}
