/* A worked example of an inverse approximation (docs/solvers.md, "Adding a
 * solver"): "trace-jacobi", a damped diagonal preconditioner that scales each
 * node's residual by the mean of its diagonal block's diagonal,
 *
 *     z_i = omega * 3 / trace(D_i) * r_i,
 *
 * D_i the node's 3x3 diagonal block of the BC-projected Hessian. It is a
 * cruder cousin of block Jacobi (solvers/inverse/jacobi.c): a scalar per node
 * instead of an inverted 3x3 block. It needs only the diagonal blocks, so it
 * works matrix-free, and it is symmetric and positive whenever every trace is
 * positive (true for an SPD Hessian; a Dirichlet node's block is I).
 *
 * It is not registered (`mpmbench list solvers` does not show it);
 * tests/conformance/test_example_inverse.c compiles this file, composes it
 * with projected Newton and L-BFGS and checks it. To make it a part of the
 * program, move it to solvers/inverse/ and add one line,
 * X(inv_trace_jacobi_ops), to INVERSE_APPROXIMATIONS in
 * experiments/run/registry.c: `--solver pn:trace-jacobi` then works, and
 * tests/conformance/test_conformance.c checks it with every other part. */
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "solvers/inverse_approx.h"

/* The object: the interface's base first, then the private context. */
typedef struct {
    InvApprox base;
    double omega;  /* option "omega": damping factor in (0, 2] */
    int n, cap;    /* nodes of the last setup, capacity of scale */
    double *scale; /* n: omega * 3 / trace(D_i) */
} TraceJacobi;

extern const InvApproxOps inv_trace_jacobi_ops;

/* create: read and validate the options (an option nobody reads is reported
 * by the solver layer as unknown), allocate, set the capabilities. No step
 * problem is needed, so a bad option is refused before any scene loads. */
static int trace_jacobi_create(SolverOptions *opt, InvApprox **out)
{
    int st = MPM_OK;
    double omega = solver_opt_number(opt, "omega", 1.0, &st);
    if (st) return st;
    if (!(omega > 0.0 && omega <= 2.0))
        return mpm_error(MPM_EINPUT, "solver option omega=%g: expected a number in (0, 2]", omega);
    TraceJacobi *T = calloc(1, sizeof *T);
    if (!T) return mpm_error(MPM_EINTERNAL, "out of memory: trace-jacobi");
    T->base.ops = &inv_trace_jacobi_ops;
    T->base.caps = INV_MATRIX_FREE | INV_SYMMETRIC | INV_POSITIVE;
    T->omega = omega;
    *out = &T->base;
    return MPM_OK;
}

/* setup: from the diagonal blocks, always given (assembled or matrix-free).
 * Storage grows but is reused across steps. A non-positive trace is a
 * numerical breakdown of the step (MPM_ENUMERIC), reported with the node. */
static int trace_jacobi_setup(InvApprox *self, const InvSetupInput *in)
{
    TraceJacobi *T = (TraceJacobi *)self;
    int n = in->n_nodes;
    if (n > T->cap) {
        double *s = realloc(T->scale, sizeof(double) * (size_t)n);
        if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: trace-jacobi (%d nodes)", n);
        T->scale = s;
        T->cap = n;
    }
    T->n = n;
    int bad = n; /* the lowest failing node: a min-reduction keeps the message deterministic */
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (int i = 0; i < n; ++i) {
        const double *D = in->diag + 9 * (size_t)i;
        double trace = D[0] + D[4] + D[8];
        T->scale[i] = trace > 0.0 && isfinite(trace) ? T->omega * 3.0 / trace : 0.0;
        if (!(trace > 0.0 && isfinite(trace)) && i < bad) bad = i;
    }
    if (bad < n) return mpm_error(MPM_ENUMERIC, "trace-jacobi: non-positive diagonal trace at node %d", bad);
    return MPM_OK;
}

/* apply: z ~= H^-1 r. The wrappers (inv_apply) refuse it before a
 * successful setup and time it; nothing here reads a clock. */
static int trace_jacobi_apply(InvApprox *self, const double *r, double *z)
{
    TraceJacobi *T = (TraceJacobi *)self;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < T->n; ++i)
        for (int k = 0; k < 3; ++k) z[3 * (size_t)i + k] = T->scale[i] * r[3 * (size_t)i + k];
    return MPM_OK;
}

/* view: a line for the run's summary (f may be NULL) and named statistics
 * for inverse_stats.csv (out may be NULL). */
static void trace_jacobi_view(const InvApprox *self, FILE *f, InvView *out)
{
    const TraceJacobi *T = (const TraceJacobi *)self;
    if (f) fprintf(f, "  trace Jacobi (omega %g) on %d nodes\n", T->omega, T->n);
    inv_view_add(out, "nodes", T->n);
}

static void trace_jacobi_destroy(InvApprox *self)
{
    if (!self) return;
    TraceJacobi *T = (TraceJacobi *)self;
    free(T->scale);
    free(T);
}

/* The ops table (designated initialisers: fields added to the interface
 * later default to NULL). No library to start, so no library_startup. */
const InvApproxOps inv_trace_jacobi_ops = {
    .name = "trace-jacobi",
    .description = "diagonal blocks' mean diagonal, damped by omega (a worked example)",
    .create = trace_jacobi_create,
    .setup = trace_jacobi_setup,
    .apply = trace_jacobi_apply,
    .view = trace_jacobi_view,
    .destroy = trace_jacobi_destroy,
};
