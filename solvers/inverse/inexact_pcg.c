#include "solvers/inverse/inexact_pcg.h"

#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"

typedef struct {
    InvApprox base;
    InvApprox *jacobi;
    const LinearOp *op;
    const Projection *proj;
    PcgWork work;
    double *z;
    int cap, n, max_iters;
    Deadline deadline;               /* InvSetupInput.deadline of the last setup */
    long applies, capped, timed_out; /* since the last setup */
} InexactPcg;

static int ipcg_create(SolverOptions *opt, InvApprox **out)
{
    int st = MPM_OK;
    int max_iters = solver_opt_int(opt, "max_iters", 10000, 1, 1000000000, &st);
    if (st) return st;
    InexactPcg *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: inexact PCG");
    s->max_iters = max_iters;
    if ((st = inv_create(&inv_block_jacobi_ops, opt, &s->jacobi))) {
        free(s);
        return st;
    }
    s->base.ops = &inv_inexact_pcg_ops;
    /* an adaptive inner PCG: not a fixed linear map, but r^T z > 0 (CG's
     * iterate minimises the energy over a Krylov space holding it) */
    s->base.caps = INV_MATRIX_FREE | INV_VARIABLE | INV_POSITIVE | INV_INNER_ITERS | INV_DISTRIBUTED;
    s->base.flexible = 1;
    *out = &s->base;
    return MPM_OK;
}

static int ipcg_setup(InvApprox *self, const InvSetupInput *in)
{
    InexactPcg *s = (InexactPcg *)self;
    s->op = in->op;
    s->proj = in->proj;
    s->n = in->n_nodes;
    s->deadline = in->deadline;
    s->applies = s->capped = s->timed_out = 0;
    if (in->n_nodes > s->cap) {
        double *z = realloc(s->z, sizeof(double) * 3 * (size_t)in->n_nodes);
        if (!z) return mpm_error(MPM_EINTERNAL, "out of memory: inexact PCG");
        s->z = z;
        s->cap = in->n_nodes;
    }
    int st = inv_setup(s->jacobi, in);
    self->stats.inner_iters = 0;
    return st;
}

static int ipcg_apply(InvApprox *self, const double *r, double *z)
{
    InexactPcg *s = (InexactPcg *)self;
    size_t len = 3 * (size_t)s->n;
    /* tolerance from the input: 1/2 sqrt(q^T D^-1 q) */
    int st = inv_apply(s->jacobi, r, s->z);
    if (st) return st;
    double ref = sqrt(fmax(vec_dot(len, r, s->z), 0.0));
    PcgOptions po = {.stop = PCG_ABSOLUTE, .abs_tol = 0.5 * ref, .max_iters = s->max_iters, .deadline = s->deadline};
    PcgResult res;
    st = pcg_solve(s->op, s->jacobi, s->proj, r, z, &po, &s->work, &res);
    /* past the step's deadline the outer method stops at its next test; until
     * then it needs a descent direction: with no inner iteration done that is
     * the block-Jacobi one (z = 0 would stall its line search) */
    if (!st && res.timed_out && res.iters == 0) { /* z = P D^-1 P r, PCG's first direction */
        vec_copy(len, r, s->z);
        projection_apply(s->proj, s->z);
        st = precondition_projected(s->jacobi, s->proj, len, s->z, z);
    }
    s->timed_out += res.timed_out;
    self->stats.inner_iters += res.iters;
    s->applies++;
    s->capped += res.capped;
    return st;
}

static void ipcg_view(const InvApprox *self, FILE *f, InvView *out)
{
    const InexactPcg *s = (const InexactPcg *)self;
    if (f)
        fprintf(f, "  inexact block-Jacobi PCG (stop at 1/2 the input's norm, cap %d): %ld applications, %ld "
                   "iterations, %ld capped, %ld at the deadline\n",
                s->max_iters, s->applies, self->stats.inner_iters, s->capped, s->timed_out);
    inv_view_add(out, "applications", (double)s->applies);
    inv_view_add(out, "inner_iters", (double)self->stats.inner_iters);
    inv_view_add(out, "capped", (double)s->capped);
    inv_view_add(out, "timed_out", (double)s->timed_out);
}

static void ipcg_destroy(InvApprox *self)
{
    InexactPcg *s = (InexactPcg *)self;
    inv_destroy(s->jacobi);
    pcg_work_free(&s->work);
    free(s->z);
    free(s);
}

const InvApproxOps inv_inexact_pcg_ops = {
    "inexact-pcg", "block-Jacobi PCG from zero to 1/2 of the input's norm (HOT LBFGS-H, SPEC 7)",
    ipcg_create,   ipcg_setup,
    ipcg_apply,    ipcg_view,
    ipcg_destroy,  NULL, NULL, NULL};
