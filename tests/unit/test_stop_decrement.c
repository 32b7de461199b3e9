/* floor: solvers */
/* The Newton-decrement stopping rule (SPEC 4.1) on a quadratic fixture
 * q(x) = 1/2 x^T A x + c^T x (A a synthetic SPD block matrix with Dirichlet
 * nodes, c projected):
 *  - with an exact PCG solve, the decrement -g^T p / 2 at an iterate x_k
 *    equals the remaining gap q(x_k) - q(x*), x* from an independent solve,
 *    to round-off, and stop_decrement_measure equals the exact relative gap
 *    (q(x_k) - q*) / (q(0) - q*);
 *  - an inexact PCG (forcing 0.5) underestimates it (CG from zero minimises
 *    the model over its Krylov space), and adding rho^2 / 2 (PN's
 *    correction) never overshoots by more than the preconditioner allows;
 *  - the guards: the first iterate (nothing gained) gives 1, a non-descent or
 *    non-finite direction gives no estimate (INFINITY), g = 0 gives 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"
#include "solvers/stop_rule.h"
#include "tests/common/synthetic.h"
#include "tests/common/testutil.h"

/* q(x) = 1/2 x^T A x + c^T x */
static double q_eval(const SynthProblem *p, const double *c, const double *x, double *tmp)
{
    size_t len = 3 * (size_t)p->n;
    bsr_spmv(&p->A, x, tmp);
    return 0.5 * vec_dot(len, x, tmp) + vec_dot(len, c, x);
}

/* g = A x + c, projected */
static void q_grad(const SynthProblem *p, const double *c, const double *x, double *g)
{
    size_t len = 3 * (size_t)p->n;
    bsr_spmv(&p->A, x, g);
    vec_axpy(len, 1.0, c, g);
    projection_apply(&p->proj, g);
}

/* p = A^-1 (-g) by PCG; returns g^T p, *rho2 the final rho^2 */
static double newton(const SynthProblem *p, InvApprox *M, const double *g, double *dir, const PcgOptions *o,
                     PcgWork *w, double *rho2)
{
    size_t len = 3 * (size_t)p->n;
    double *rhs = malloc(sizeof(double) * len);
    for (size_t k = 0; k < len; ++k) rhs[k] = -g[k];
    PcgResult r;
    int st = pcg_solve(&p->op, M, &p->proj, rhs, dir, o, w, &r);
    CHECK(st == MPM_OK, "pcg: %s", mpm_last_error());
    free(rhs);
    if (rho2) *rho2 = r.rho * r.rho;
    return vec_dot(len, g, dir);
}

int main(void)
{
    SynthProblem p;
    SynthParams sp = {.center = {3, -2, 5}, .radius = 7.0, .reach = 2, .mass = 1.0, .stiff = 1000.0,
                      .dirichlet = 1, .core_ratio = 100.0, .seed = 11};
    int st = synth_build(&p, &sp);
    CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
    if (st) return test_summary("test_stop_decrement");
    const size_t len = 3 * (size_t)p.n;
    double *c = malloc(sizeof(double) * len), *xs = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len),
           *g = malloc(sizeof(double) * len), *d = malloc(sizeof(double) * len), *tmp = malloc(sizeof(double) * len),
           *zero = calloc(len, sizeof(double));
    synth_random_vector(p.n, 5, c);
    projection_apply(&p.proj, c);
    InvApprox *M = NULL;
    st = inv_create(&inv_block_jacobi_ops, NULL, &M);
    InvSetupInput in = {.n_nodes = p.n, .H = &p.A, .diag = p.diag, .coord = p.coord, .coloring = &p.col,
                        .op = &p.op, .proj = &p.proj};
    st = st ? st : inv_setup(M, &in);
    CHECK(st == MPM_OK, "block Jacobi: %s", mpm_last_error());
    PcgWork w = {0};
    PcgOptions exact = {.stop = PCG_RELATIVE_L2, .rel_tol = 1e-14, .max_iters = 100000};

    /* x* from x = 0 */
    q_grad(&p, c, zero, g);
    newton(&p, M, g, xs, &exact, &w, NULL);
    const double q0 = q_eval(&p, c, zero, tmp), qs = q_eval(&p, c, xs, tmp);
    CHECK(q0 - qs > 0.0, "the fixture has something to gain: q0 %.6e q* %.6e", q0, qs);

    /* x_k = x* / 2 + a smooth perturbation A^-1 r (a random r would sit in
     * the stiff modes and raise q above q(0)), the decrement there against
     * the gap */
    synth_random_vector(p.n, 9, g);
    projection_apply(&p.proj, g);
    newton(&p, M, g, d, &exact, &w, NULL);
    const double pert = 0.1 * vec_norm(len, xs) / vec_norm(len, d);
    for (size_t k = 0; k < len; ++k) x[k] = 0.5 * xs[k] + pert * d[k];
    const double qk = q_eval(&p, c, x, tmp);
    q_grad(&p, c, x, g);
    double gTp = newton(&p, M, g, d, &exact, &w, NULL);
    const double dec = -0.5 * gTp, gap = qk - qs;
    /* both sides carry the round-off of q (|q0| u per evaluation) and the
     * 1e-14 solves' error, relative to the gap (measured 1e-15) */
    const double tol = 1e-12;
    printf("quadratic (%d nodes): decrement %.15e, gap %.15e, relative difference %.2e\n", p.n, dec, gap,
           fabs(dec - gap) / gap);
    CHECK(fabs(dec - gap) <= tol * gap, "exact solve: decrement %.15e != gap %.15e", dec, gap);
    double m = stop_decrement_measure(gTp, q0, qk), m_exact = gap / (q0 - qs);
    printf("measure %.15e, exact relative gap %.15e\n", m, m_exact);
    CHECK(fabs(m - m_exact) <= tol * m_exact, "measure %.15e != relative gap %.15e", m, m_exact);

    /* an inexact solve: a lower bound, and rho^2/2 added gets closer */
    PcgOptions loose = {.stop = PCG_RELATIVE, .rel_tol = 0.5, .max_iters = 100000};
    double rho2;
    double gTp_in = newton(&p, M, g, d, &loose, &w, &rho2);
    double dec_in = -0.5 * gTp_in, dec_corr = dec_in + 0.5 * rho2;
    printf("inexact (forcing 0.5): decrement %.6e (%.3f of the gap), corrected %.6e (%.3f)\n", dec_in, dec_in / gap,
           dec_corr, dec_corr / gap);
    CHECK(dec_in > 0.0 && dec_in <= gap * (1.0 + tol), "inexact decrement %.6e not in (0, gap %.6e]", dec_in, gap);
    CHECK(fabs(dec_corr - gap) < fabs(dec_in - gap), "correction moves away from the gap: %.6e %.6e %.6e", dec_in,
          dec_corr, gap);

    /* guards */
    CHECK(stop_decrement_measure(gTp, q0, q0) == 1.0, "first iterate: %g", stop_decrement_measure(gTp, q0, q0));
    CHECK(isinf(stop_decrement_measure(-gTp, q0, qk)), "ascent direction gives no estimate");
    CHECK(isinf(stop_decrement_measure(NAN, q0, qk)), "NaN gives no estimate");
    CHECK(isinf(stop_decrement_measure(gTp, q0, NAN)), "NaN energy gives no estimate");
    CHECK(stop_decrement_measure(0.0, q0, qk) == 0.0, "g = 0: nothing left");
    CHECK(stop_decrement_measure(-1e-30, 1.0, 0.5) == 0.0, "below the energy's round-off: nothing resolvable left");
    CHECK(fabs(stop_decrement_measure(-2.0, 3.0, 2.0) - 0.5) < 1e-15, "d 1, gained 1: 1/2");
    const StopRuleOps *r = stop_rule_find("decrement");
    CHECK(r && r->direction_measure == stop_decrement_measure && !r->tol_key, "registered, tolerance = the run's eps");
    const StopRuleOps *cn = stop_rule_find("cn");
    CHECK(cn && isinf(cn->direction_measure(gTp, q0, qk)), "cn never decides on the direction");

    inv_destroy(M);
    pcg_work_free(&w);
    free(c), free(xs), free(x), free(g), free(d), free(tmp), free(zero);
    synth_free(&p);
    return test_summary("test_stop_decrement");
}
