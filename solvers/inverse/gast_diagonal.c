/* Gast et al. 2015's rest-configuration diagonal preconditioner (§6.2), an
 * inverse approximation "gast-diagonal":
 *
 *   L_ii = sum_p diag( m_p w_ip I + dt^2 V_p^0 H_ip ),
 *   H_ip = (lambda_p + mu_p) grad w_ip grad w_ip^T + mu_p |grad w_ip|^2 I,
 *
 * and z = L^-1 r entrywise. (The extracted text of §6.2 prints the second
 * term of H as "mu_p grad w^T grad w I"; grad w^T grad w is the scalar
 * |grad w|^2, and with it H_ip is exactly the diagonal 3x3 block that
 * particle p adds to the stiffness matrix of fixed corotated elasticity
 * linearised at the rest configuration, dP = mu (dF + dF^T) + lambda tr(dF) I
 * with F^n = I: K_ii = sum_p V_p [(lambda + mu) grad w grad w^T + mu |grad w|^2 I].
 * "diag" keeps its three diagonal entries, so L is a diagonal matrix, and
 * sum_p m_p w_ip = m_i is the grid mass.) tests/conformance/test_gast15.c checks L
 * against the assembled Hessian's diagonal at F = F^n = I.
 *
 * It needs neither the Hessian nor the current deformation: only the step
 * problem's weight gradients, volumes and (hardened) Lame parameters, so it
 * is matrix-free and the same at every Newton iteration of a step; it is
 * positive whatever the current tangent, which Gast's unprojected Newton
 * needs from a CG preconditioner. Sticky nodes get L = 1 (the identity rows
 * of the BC-projected Hessian); vectors are projected by the caller. */
#include <stdlib.h>
#include <string.h>

#include "core/block_traversal.h"
#include "core/error.h"
#include "core/problem.h"
#include "solvers/inverse_approx.h"

typedef struct {
    InvApprox base;
    int n, cap;
    double *inv_l; /* 3 n: 1 / L_ii entries */
} GastDiagonal;

extern const InvApproxOps inv_gast_diagonal_ops;

static int gd_create(SolverOptions *opt, InvApprox **out)
{
    (void)opt;
    GastDiagonal *G = calloc(1, sizeof *G);
    if (!G) return mpm_error(MPM_EINTERNAL, "out of memory: gast-diagonal");
    G->base.ops = &inv_gast_diagonal_ops;
    G->base.caps = INV_MATRIX_FREE | INV_NEEDS_PROBLEM | INV_SYMMETRIC | INV_POSITIVE;
    *out = &G->base;
    return MPM_OK;
}

static int gd_setup(InvApprox *self, const InvSetupInput *in)
{
    GastDiagonal *G = (GastDiagonal *)self;
    self->stats = (InvStats){0};
    const StepProblem *pb = in->problem;
    if (!pb) return mpm_error(MPM_EINTERNAL, "gast-diagonal: needs the step problem (weight gradients, volumes)");
    const int n = in->n_nodes;
    if (pb->n_nodes != n)
        return mpm_error(MPM_EINTERNAL, "gast-diagonal: %d nodes given, the step problem has %d", n, pb->n_nodes);
    if (n > G->cap) {
        double *d = realloc(G->inv_l, sizeof(double) * 3 * (size_t)n);
        if (!d) return mpm_error(MPM_EINTERNAL, "out of memory: gast-diagonal (%d nodes)", n);
        G->inv_l = d;
        G->cap = n;
    }
    G->n = n;
    double *L = G->inv_l; /* L first, inverted in place below */
    const double *m = pb->grid->mass;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) L[3 * i] = L[3 * i + 1] = L[3 * i + 2] = m[i];
    const Stencils *st = pb->st;
    const Particles *p = pb->parts;
    const double dt2 = pb->dt * pb->dt;
    /* the scatter of every particle's term: race-free and in a fixed order
     * by the coloured traversal (core/block_traversal.h) */
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const int *node = st->node + 27 * (size_t)k;
        double w[27], dw[81];
        stencil_weights(st, (size_t)k, w, dw);
        const double s = dt2 * p->vol[k], lm = pb->lambda[k] + pb->mu[k], mu = pb->mu[k];
        for (int t = 0; t < 27; ++t) {
            int i = node[t];
            if (i < 0) continue;
            const double *gw = dw + 3 * t;
            double g2 = gw[0] * gw[0] + gw[1] * gw[1] + gw[2] * gw[2];
            for (int a = 0; a < 3; ++a) L[3 * (size_t)i + a] += s * (lm * gw[a] * gw[a] + mu * g2);
        }
    }
    int bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (int i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) {
            double *l = L + 3 * (size_t)i + a;
            if (pb->bc[i] == BC_STICKY) *l = 1.0;
            if (!(*l > 0.0) || !(*l < 1e300)) { /* also NaN: a bad volume or modulus */
                if (i < bad) bad = i;
                *l = 0.0;
            } else {
                *l = 1.0 / *l;
            }
        }
    }
    if (bad < n) return mpm_error(MPM_ENUMERIC, "gast-diagonal: non-positive or non-finite L_ii at node %d", bad);
    return MPM_OK;
}

static int gd_apply(InvApprox *self, const double *r, double *z)
{
    GastDiagonal *G = (GastDiagonal *)self;
    const size_t len = 3 * (size_t)G->n;
    const double *d = G->inv_l;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < len; ++k) z[k] = d[k] * r[k];
    return MPM_OK;
}

static void gd_view(const InvApprox *self, FILE *f, InvView *out)
{
    const GastDiagonal *G = (const GastDiagonal *)self;
    if (f) fprintf(f, "  Gast 2015 rest-configuration diagonal on %d nodes\n", G->n);
    inv_view_add(out, "nodes", G->n);
}

static void gd_destroy(InvApprox *self)
{
    if (!self) return;
    GastDiagonal *G = (GastDiagonal *)self;
    free(G->inv_l);
    free(G);
}

const InvApproxOps inv_gast_diagonal_ops = {
    "gast-diagonal",
    "diagonal of the rest-configuration stiffness, matrix-free (Gast et al. 2015 section 6.2)",
    gd_create, gd_setup, gd_apply, gd_view, gd_destroy, NULL, NULL, NULL};
