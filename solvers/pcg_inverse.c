#include "solvers/pcg_inverse.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/jacobi.h"
#include "solvers/pcg.h"

typedef struct {
    InvApprox base;
    InvApprox *jacobi;
    const LinearOp *op;
    const Projection *proj;
    PcgWork work;
    double *z;
    int cap, n, max_iters;
} InexactPcg;

static int ipcg_create(SolverOptions *opt, InvApprox **out)
{
    InexactPcg *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: inexact PCG");
    int st = MPM_OK;
    s->max_iters = (int)solver_opt_number(opt, "max_iters", 10000, &st);
    if (!st && s->max_iters < 1) st = mpm_error(MPM_EINPUT, "--solver-opt max_iters=%d: expected >= 1", s->max_iters);
    if (!st) st = inv_block_jacobi_ops.create(opt, &s->jacobi);
    if (st) {
        free(s);
        return st;
    }
    s->base.ops = &inv_inexact_pcg_ops;
    s->base.variable = 1; /* an adaptive inner PCG: not a fixed linear map */
    *out = &s->base;
    return MPM_OK;
}

static int ipcg_setup(InvApprox *self, const InvSetupInput *in)
{
    InexactPcg *s = (InexactPcg *)self;
    double t0 = omp_get_wtime();
    s->op = in->op;
    s->proj = in->proj;
    s->n = in->n_nodes;
    if (in->n_nodes > s->cap) {
        double *z = realloc(s->z, sizeof(double) * 3 * (size_t)in->n_nodes);
        if (!z) return mpm_error(MPM_EINTERNAL, "out of memory: inexact PCG");
        s->z = z;
        s->cap = in->n_nodes;
    }
    int st = s->jacobi->ops->setup(s->jacobi, in);
    self->stats.inner_iters = 0;
    self->stats.apply_s = 0;
    self->stats.setup_s = omp_get_wtime() - t0;
    return st;
}

static int ipcg_apply(InvApprox *self, const double *r, double *z)
{
    InexactPcg *s = (InexactPcg *)self;
    double t0 = omp_get_wtime();
    size_t len = 3 * (size_t)s->n;
    /* tolerance from the input: 1/2 sqrt(q^T D^-1 q) */
    int st = s->jacobi->ops->apply(s->jacobi, r, s->z);
    if (st) return st;
    double ref = sqrt(fmax(vec_dot(len, r, s->z), 0.0));
    PcgOptions po = {PCG_ABSOLUTE, 0.0, 0.5 * ref, s->max_iters};
    PcgResult res;
    st = pcg_solve(s->op, s->jacobi, s->proj, r, z, &po, &s->work, &res);
    self->stats.inner_iters += res.iters;
    self->stats.apply_s += omp_get_wtime() - t0;
    return st;
}

static void ipcg_destroy(InvApprox *self)
{
    InexactPcg *s = (InexactPcg *)self;
    if (s->jacobi) s->jacobi->ops->destroy(s->jacobi);
    pcg_work_free(&s->work);
    free(s->z);
    free(s);
}

const InvApproxOps inv_inexact_pcg_ops = {"inexact-pcg", ipcg_create, ipcg_setup, ipcg_apply, ipcg_destroy};
