/* Block and scalar Jacobi (SPEC 5; HOT reference §4 step 4). */
#include "solvers/inverse/jacobi.h"

#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/mat3.h"
#include "core/vec.h"

int block_diag_invert(int n, const double *diag, double *dinv, const char *what)
{
    int bad = n; /* lowest failing node, n = none (min-reduction keeps it deterministic) */
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (int i = 0; i < n; ++i) {
        double *Di = dinv + 9 * (size_t)i;
        int ok = m3_inverse(diag + 9 * (size_t)i, Di);
        for (int k = 0; ok && k < 9; ++k) ok = isfinite(Di[k]);
        if (!ok && i < bad) bad = i;
    }
    if (bad < n) {
        const double *D = diag + 9 * (size_t)bad;
        return mpm_error(MPM_ENUMERIC, "%s: singular diagonal block at node %d (det %g, trace %g)", what, bad,
                         m3_det(D), D[0] + D[4] + D[8]);
    }
    return MPM_OK;
}

typedef struct {
    InvApprox base;
    int n, cap;
    double *dinv; /* 9 n (block) or 3 n (scalar) */
    int scalar;
} Jacobi;

static int jacobi_create(int scalar, InvApprox **out)
{
    Jacobi *J = calloc(1, sizeof *J);
    if (!J) return mpm_error(MPM_EINTERNAL, "out of memory: jacobi");
    J->base.ops = scalar ? &inv_scalar_jacobi_ops : &inv_block_jacobi_ops;
    J->base.caps = INV_MATRIX_FREE | INV_SYMMETRIC | INV_POSITIVE | INV_DISTRIBUTED; /* reads diag only */
    J->scalar = scalar;
    *out = &J->base;
    return MPM_OK;
}

static int block_create(SolverOptions *opt, InvApprox **out)
{
    (void)opt;
    return jacobi_create(0, out);
}
static int scalar_create(SolverOptions *opt, InvApprox **out)
{
    (void)opt;
    return jacobi_create(1, out);
}

static int jacobi_setup(InvApprox *self, const InvSetupInput *in)
{
    Jacobi *J = (Jacobi *)self;
    self->stats = (InvStats){0};
    int n = in->n_nodes;
    if (!in->diag) return mpm_error(MPM_EINTERNAL, "jacobi: no diagonal given");
    size_t per = J->scalar ? 3 : 9;
    if (n > J->cap) {
        double *d = realloc(J->dinv, sizeof(double) * per * (size_t)(n > 0 ? n : 1));
        if (!d) return mpm_error(MPM_EINTERNAL, "out of memory: jacobi (%d nodes)", n);
        J->dinv = d;
        J->cap = n;
    }
    J->n = n;
    int st = MPM_OK;
    if (!J->scalar) {
        st = block_diag_invert(n, in->diag, J->dinv, "block jacobi");
    } else {
        int bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad)
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) {
                double d = in->diag[9 * (size_t)i + 4 * k];
                if (d == 0.0 || !isfinite(d)) {
                    if (i < bad) bad = i;
                    J->dinv[3 * (size_t)i + k] = 0.0;
                } else {
                    J->dinv[3 * (size_t)i + k] = 1.0 / d;
                }
            }
        if (bad < n) st = mpm_error(MPM_ENUMERIC, "scalar jacobi: zero or non-finite diagonal entry at node %d", bad);
    }
    return st;
}

static int jacobi_apply(InvApprox *self, const double *r, double *z)
{
    Jacobi *J = (Jacobi *)self;
    if (!J->scalar) {
        vec_block_apply((size_t)J->n, J->dinv, r, z);
    } else {
        const size_t len = 3 * (size_t)J->n;
        const double *d = J->dinv;
#pragma omp parallel for schedule(static)
        for (size_t k = 0; k < len; ++k) z[k] = d[k] * r[k];
    }
    return MPM_OK;
}

static void jacobi_view(const InvApprox *self, FILE *f, InvView *out)
{
    const Jacobi *J = (const Jacobi *)self;
    if (f) fprintf(f, "  %s Jacobi on %d nodes\n", J->scalar ? "scalar" : "3x3 block", J->n);
    inv_view_add(out, "nodes", J->n);
}

static void jacobi_destroy(InvApprox *self)
{
    if (!self) return;
    Jacobi *J = (Jacobi *)self;
    free(J->dinv);
    free(J);
}

const InvApproxOps inv_block_jacobi_ops = {"block-jacobi",
                                           "inverse 3x3 diagonal blocks of the Hessian (HOT's default Jacobi)",
                                           block_create, jacobi_setup, jacobi_apply, jacobi_view, jacobi_destroy, NULL, NULL, NULL};
const InvApproxOps inv_scalar_jacobi_ops = {"jacobi", "inverse diagonal entries of the Hessian (scalar Jacobi)",
                                            scalar_create, jacobi_setup, jacobi_apply, jacobi_view, jacobi_destroy, NULL, NULL, NULL};
