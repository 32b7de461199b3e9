/* The InvApprox wrappers: object state and counters every implementation
 * shares (see inverse_approx.h). */
#include "solvers/inverse_approx.h"

#include <omp.h>
#include <string.h>

#include "core/error.h"

void inv_view_add(InvView *v, const char *key, double value)
{
    if (!v || v->n_stats >= INV_VIEW_MAX_STATS) return;
    snprintf(v->stat[v->n_stats].key, sizeof v->stat[0].key, "%s", key);
    v->stat[v->n_stats].value = value;
    v->n_stats++;
}

int inv_create(const InvApproxOps *ops, SolverOptions *opt, InvApprox **out)
{
    *out = NULL;
    InvApprox *M = NULL;
    int st = ops->create(opt, &M);
    if (st) return st;
    M->ops = ops;
    M->ready = 0;
    M->inner_banked = 0;
    *out = M;
    return MPM_OK;
}

int inv_setup(InvApprox *M, const InvSetupInput *in)
{
    M->inner_banked += M->stats.inner_iters; /* the implementation restarts its count */
    M->stats.inner_iters = 0;
    M->stats.apply_s = 0.0;
    M->ready = 0;
    double t0 = omp_get_wtime();
    int st = M->ops->setup(M, in);
    M->stats.setup_s = omp_get_wtime() - t0;
    M->ready = st == MPM_OK;
    return st;
}

int inv_apply(InvApprox *M, const double *r, double *z)
{
    if (!M->ready) return mpm_error(MPM_EINTERNAL, "%s: applied without a successful setup", M->ops->name);
    double t0 = omp_get_wtime();
    int st = M->ops->apply(M, r, z);
    M->stats.apply_s += omp_get_wtime() - t0;
    return st;
}

void inv_view(const InvApprox *M, FILE *f, InvView *out)
{
    if (out) memset(out, 0, sizeof *out);
    if (M->ops->view) M->ops->view(M, f, out);
}

void inv_destroy(InvApprox *M)
{
    if (M) M->ops->destroy(M);
}

long inv_inner_iters(const InvApprox *M) { return M->inner_banked + M->stats.inner_iters; }

void inv_caps_describe(unsigned caps, char *buf, size_t len)
{
    static const struct {
        unsigned flag;
        const char *text;
    } names[] = {{INV_NEEDS_MATRIX, "needs the assembled matrix"}, {INV_MATRIX_FREE, "works matrix-free"},
                 {INV_NEEDS_PROBLEM, "needs the step problem"},    {INV_VARIABLE, "variable"},
                 {INV_SYMMETRIC, "symmetric"},                     {INV_POSITIVE, "positive"},
                 {INV_INNER_ITERS, "inner iterations"}};
    size_t used = 0;
    if (len) buf[0] = '\0';
    for (size_t k = 0; k < sizeof names / sizeof names[0] && used < len; ++k)
        if (caps & names[k].flag)
            used += (size_t)snprintf(buf + used, len - used, "%s%s", used ? ", " : "", names[k].text);
}
