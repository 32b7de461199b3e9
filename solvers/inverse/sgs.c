/* Coloured symmetric block Gauss-Seidel (HOT reference §5.2; paper §4.3 and
 * Table 3). */
#include "solvers/inverse/sgs.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/mat3.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"

/* The sweep on the doubles of A->val and on a single-precision copy of them
 * (solvers/inverse/sgs_sweep.inc, one body for both). */
#define SGS_VAL double
#define SGS_NAME(x) x##_f64
#include "solvers/inverse/sgs_sweep.inc"
#undef SGS_VAL
#undef SGS_NAME
#define SGS_VAL float
#define SGS_NAME(x) x##_f32
#include "solvers/inverse/sgs_sweep.inc"
#undef SGS_VAL
#undef SGS_NAME

int sgs_sweep(const Bsr *A, const double *Dinv, const NodeColoring *col, const double *r, double *delta, double *work)
{
    return sweep_f64(A, A->val, Dinv, col, r, delta, work);
}

int sgs_sweep_single(const Bsr *A, const float *val, const double *Dinv, const NodeColoring *col, const double *r,
                     double *delta, double *work)
{
    return sweep_f32(A, val, Dinv, col, r, delta, work);
}

int sgs_check_coloring(const Bsr *A, const NodeColoring *col)
{
    int n = A->n;
    int *blk = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    int *clr = malloc(sizeof(int) * (size_t)(col->n_blocks > 0 ? col->n_blocks : 1));
    if (!blk || !clr) {
        free(blk);
        free(clr);
        return mpm_error(MPM_EINTERNAL, "out of memory: colouring check");
    }
    for (int b = 0; b < col->n_blocks; ++b)
        for (int i = col->block_start[b]; i < col->block_start[b + 1]; ++i) blk[i] = b;
    for (int c = 0; c < MPM_NUM_COLORS; ++c)
        for (int bi = col->color_start[c]; bi < col->color_start[c + 1]; ++bi) clr[col->color_blocks[bi]] = c;
    int st = MPM_OK;
    for (int i = 0; i < n && !st; ++i)
        for (int64_t k = A->row_ptr[i]; k < A->row_ptr[i + 1]; ++k) {
            int j = A->col[k];
            if (blk[j] != blk[i] && clr[blk[j]] == clr[blk[i]]) {
                st = mpm_error(MPM_EINTERNAL,
                               "sgs: nodes %d and %d are coupled but lie in different blocks of colour %d", i, j,
                               clr[blk[i]]);
                break;
            }
        }
    free(blk);
    free(clr);
    return st;
}

/* ---- InvApprox "sgs" ---- */

typedef struct {
    InvApprox base;
    const Bsr *H;
    const NodeColoring *col;
    int n, cap;
    double *dinv; /* 9 cap */
    double *work; /* 6 cap */
} Sgs;

static int sgs_create(SolverOptions *opt, InvApprox **out)
{
    (void)opt;
    Sgs *S = calloc(1, sizeof *S);
    if (!S) return mpm_error(MPM_EINTERNAL, "out of memory: sgs");
    S->base.ops = &inv_sgs_ops;
    S->base.caps = INV_NEEDS_HESSIAN | INV_SYMMETRIC | INV_POSITIVE;
    *out = &S->base;
    return MPM_OK;
}

static int sgs_setup(InvApprox *self, const InvSetupInput *in)
{
    Sgs *S = (Sgs *)self;
    self->stats = (InvStats){0};
    if (!in->H) return mpm_error(MPM_EINPUT, "sgs needs an assembled matrix (not available matrix-free)");
    if (!in->coloring || !in->diag) return mpm_error(MPM_EINTERNAL, "sgs: no node colouring or diagonal given");
    int n = in->n_nodes;
    if (in->H->n != n) return mpm_error(MPM_EINTERNAL, "sgs: matrix has %d rows, expected %d", in->H->n, n);
    if (n > S->cap) {
        size_t cap = (size_t)(n > 0 ? n : 1);
        double *d = realloc(S->dinv, sizeof(double) * 9 * cap);
        if (!d) return mpm_error(MPM_EINTERNAL, "out of memory: sgs (%d nodes)", n);
        S->dinv = d;
        double *w = realloc(S->work, sizeof(double) * 6 * cap);
        if (!w) return mpm_error(MPM_EINTERNAL, "out of memory: sgs (%d nodes)", n);
        S->work = w;
        S->cap = n;
    }
    S->n = n;
    S->H = in->H;
    S->col = in->coloring;
    int st = block_diag_invert(n, in->diag, S->dinv, "sgs");
    return st;
}

static int sgs_apply(InvApprox *self, const double *r, double *z)
{
    Sgs *S = (Sgs *)self;
    int st = sgs_sweep(S->H, S->dinv, S->col, r, z, S->work);
    return st;
}

static void sgs_view(const InvApprox *self, FILE *f, InvView *out)
{
    const Sgs *S = (const Sgs *)self;
    if (f) fprintf(f, "  symmetric block Gauss-Seidel, one sweep, 8 colours, %d nodes\n", S->n);
    inv_view_add(out, "nodes", S->n);
}

static void sgs_destroy(InvApprox *self)
{
    if (!self) return;
    Sgs *S = (Sgs *)self;
    free(S->dinv);
    free(S->work);
    free(S);
}

const InvApproxOps inv_sgs_ops = {"sgs", "one coloured symmetric block Gauss-Seidel sweep from zero (HOT Table 3)",
                                  sgs_create, sgs_setup, sgs_apply, sgs_view, sgs_destroy, NULL, NULL, NULL};
