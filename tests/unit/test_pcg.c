/* floor: solvers */
/* PCG (SPEC 5) with block and scalar Jacobi on synthetic SPD block matrices:
 * convergence to tolerance, projection, the forcing-term and relative stops, the cap,
 * non-positive curvature, singular diagonal blocks, determinism, and flexible
 * CG for a variable preconditioner. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"
#include "solvers/inverse/inexact_pcg.h"
#include "tests/common/synthetic.h"
#include "tests/common/testutil.h"

static InvApprox *make_inv_until(const InvApproxOps *ops, const SynthProblem *p, Deadline deadline)
{
    InvApprox *M = NULL;
    int st = inv_create(ops, NULL, &M);
    CHECK(st == MPM_OK, "%s create: %s", ops->name, mpm_last_error());
    InvSetupInput in = {.n_nodes = p->n, .H = &p->A, .diag = p->diag, .coord = p->coord, .coloring = &p->col,
                        .op = &p->op, .proj = &p->proj, .deadline = deadline};
    st = inv_setup(M, &in);
    CHECK(st == MPM_OK, "%s setup: %s", ops->name, mpm_last_error());
    return M;
}

static InvApprox *make_inv(const InvApproxOps *ops, const SynthProblem *p)
{
    return make_inv_until(ops, p, (Deadline){0}); /* no deadline */
}

/* ||P(b - A x)|| / ||P b|| */
static double rel_residual(const SynthProblem *p, const double *b, const double *x)
{
    size_t len = 3 * (size_t)p->n;
    double *r = malloc(sizeof(double) * len), *pb = malloc(sizeof(double) * len);
    bsr_spmv(&p->A, x, r);
    for (size_t k = 0; k < len; ++k) r[k] = b[k] - r[k];
    projection_apply(&p->proj, r);
    vec_copy(len, b, pb);
    projection_apply(&p->proj, pb);
    double v = vec_norm(len, r) / vec_norm(len, pb);
    free(r);
    free(pb);
    return v;
}

static void neg_spmv(const void *ctx, const double *x, double *y)
{
    const Bsr *A = ctx;
    bsr_spmv(A, x, y);
    for (int k = 0; k < 3 * A->n; ++k) y[k] = -y[k];
}

int main(void)
{
    SynthProblem p;
    SynthParams sp = {.center = {-5, 7, -3}, .radius = 9.0, .reach = 2, .mass = 1.0, .stiff = 1000.0,
                      .dirichlet = 1, .seed = 42};
    int st = synth_build(&p, &sp);
    CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
    if (st) return test_summary("test_pcg");
    printf("synthetic problem: %d nodes, %d Dirichlet, %lld blocks (%.1f per row)\n", p.n, p.n_fixed,
           (long long)p.A.nnzb, (double)p.A.nnzb / p.n);
    size_t len = 3 * (size_t)p.n;
    double *b = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len), *x2 = malloc(sizeof(double) * len);
    synth_random_vector(p.n, 7, b);

    InvApprox *bj = make_inv(&inv_block_jacobi_ops, &p);
    InvApprox *sj = make_inv(&inv_scalar_jacobi_ops, &p);
    PcgWork work = {0};
    PcgResult res;

    /* 1. solve to a tight absolute tolerance with each preconditioner */
    int iters_block = 0, iters_scalar = 0, iters_none = 0;
    {
        PcgOptions o = {.stop = PCG_ABSOLUTE, .abs_tol = 0.0, .max_iters = 10000};
        /* abs_tol relative to rho0: first learn rho0 with a zero-iteration cap */
        o.max_iters = 0;
        pcg_solve(&p.op, bj, &p.proj, b, x, &o, &work, &res);
        CHECK(res.capped == 1 && res.iters == 0, "cap 0: capped %d iters %d", res.capped, res.iters);
        o.abs_tol = 1e-10 * res.rho0;
        o.max_iters = 10000;
        st = pcg_solve(&p.op, bj, &p.proj, b, x, &o, &work, &res);
        CHECK(st == MPM_OK, "pcg block: %s", mpm_last_error());
        CHECK(!res.capped && res.rho < o.abs_tol, "block: capped %d rho %g tol %g", res.capped, res.rho, o.abs_tol);
        double rr = rel_residual(&p, b, x);
        CHECK(rr < 1e-8, "block-Jacobi PCG relative residual %g", rr);
        iters_block = res.iters;
        int fixed_ok = 1;
        for (int i = 0; i < p.n; ++i)
            if (p.fixed[i] && (x[3 * i] != 0.0 || x[3 * i + 1] != 0.0 || x[3 * i + 2] != 0.0)) fixed_ok = 0;
        CHECK(fixed_ok, "Dirichlet nodes must stay exactly zero");

        /* determinism: same input, same bits */
        st = pcg_solve(&p.op, bj, &p.proj, b, x2, &o, &work, &res);
        CHECK(memcmp(x, x2, sizeof(double) * len) == 0 && res.iters == iters_block, "pcg not deterministic");

        st = pcg_solve(&p.op, sj, &p.proj, b, x, &o, &work, &res); /* tolerance in its own norm */
        CHECK(st == MPM_OK && !res.capped, "scalar: st %d capped %d", st, res.capped);
        o.abs_tol = 1e-10 * res.rho0;
        st = pcg_solve(&p.op, sj, &p.proj, b, x, &o, &work, &res);
        rr = rel_residual(&p, b, x);
        CHECK(rr < 1e-8, "scalar-Jacobi PCG relative residual %g", rr);
        iters_scalar = res.iters;

        o.max_iters = 0;
        pcg_solve(&p.op, NULL, &p.proj, b, x, &o, &work, &res);
        o.abs_tol = 1e-10 * res.rho0;
        o.max_iters = 10000;
        st = pcg_solve(&p.op, NULL, &p.proj, b, x, &o, &work, &res);
        rr = rel_residual(&p, b, x);
        CHECK(st == MPM_OK && rr < 1e-8, "unpreconditioned CG relative residual %g", rr);
        iters_none = res.iters;
        printf("iterations to 1e-10: block Jacobi %d, scalar Jacobi %d, none %d\n", iters_block, iters_scalar,
               iters_none);
        CHECK(iters_block > 5 && iters_block < 1000, "block-Jacobi iterations %d", iters_block);
        CHECK(iters_block <= iters_scalar + 5, "block %d vs scalar %d", iters_block, iters_scalar);
    }

    /* 2. forcing term: stops at the first iteration with rho < eta rho0 */
    {
        const double scales[2] = {1.0, 1e-7};
        for (int si = 0; si < 2; ++si) {
            double *bs = malloc(sizeof(double) * len);
            for (size_t k = 0; k < len; ++k) bs[k] = b[k] * scales[si];
            PcgOptions o = {.stop = PCG_FORCING, .tau = 1e-5, .max_iters = 10000};
            st = pcg_solve(&p.op, bj, &p.proj, bs, x, &o, &work, &res);
            double eta = fmin(0.5, sqrt(fmax(res.rho0, o.tau)));
            CHECK(st == MPM_OK && !res.capped, "forcing: st %d capped %d", st, res.capped);
            CHECK(res.rho < eta * res.rho0, "forcing: rho %g >= eta rho0 %g", res.rho, eta * res.rho0);
            int it = res.iters;
            CHECK(it >= 1, "forcing: at least one iteration (%d)", it);
            PcgOptions o2 = o;
            o2.max_iters = it - 1;
            PcgResult r2;
            pcg_solve(&p.op, bj, &p.proj, bs, x2, &o2, &work, &r2);
            CHECK(r2.capped == 1 && r2.iters == it - 1 && r2.rho >= eta * r2.rho0,
                  "forcing: one iteration earlier must not satisfy the rule (capped %d iters %d rho %g)", r2.capped,
                  r2.iters, r2.rho);
            /* the same stop as an absolute tolerance eta rho0 */
            PcgOptions o3 = {.stop = PCG_ABSOLUTE, .abs_tol = eta * res.rho0, .max_iters = 10000};
            pcg_solve(&p.op, bj, &p.proj, bs, x2, &o3, &work, &r2);
            CHECK(r2.iters == it, "forcing vs absolute: %d vs %d iterations", it, r2.iters);
            printf("forcing rule (rho0 %.3g, eta %.3g): %d iterations\n", res.rho0, eta, it);
            if (si == 1) CHECK(fabs(eta - sqrt(o.tau)) < 1e-15, "tau floor: eta %g", eta);
            free(bs);
        }
    }

    /* 2b. relative stops: PCG_RELATIVE on the preconditioned norm (HOT's
     * Gast15 CG), PCG_RELATIVE_L2 on the plain residual (Gast §3.1); each
     * stops at the first iteration meeting its rule and not one earlier */
    for (int mode = 0; mode < 2; ++mode) {
        const double rel = 0.05;
        PcgOptions o = {.stop = mode ? PCG_RELATIVE_L2 : PCG_RELATIVE, .rel_tol = rel, .max_iters = 10000};
        st = pcg_solve(&p.op, bj, &p.proj, b, x, &o, &work, &res);
        int it = res.iters;
        double m_end = mode ? rel_residual(&p, b, x) : res.rho / res.rho0;
        PcgOptions o2 = o;
        o2.max_iters = it - 1;
        PcgResult r2;
        pcg_solve(&p.op, bj, &p.proj, b, x2, &o2, &work, &r2);
        double m_before = mode ? rel_residual(&p, b, x2) : r2.rho / r2.rho0;
        CHECK(st == MPM_OK && !res.capped && !res.indefinite && it >= 2 && m_end < rel && m_before >= rel,
              "%s: %d iterations, relative measure %.4f at the end, %.4f one iteration earlier",
              mode ? "PCG_RELATIVE_L2" : "PCG_RELATIVE", it, m_end, m_before);
        printf("%s %.2f: %d iterations\n", mode ? "relative L2 residual" : "relative preconditioned norm", rel, it);
    }

    /* 3. the cap */
    {
        PcgOptions o = {.stop = PCG_ABSOLUTE, .abs_tol = 0.0, .max_iters = 3};
        st = pcg_solve(&p.op, bj, &p.proj, b, x, &o, &work, &res);
        CHECK(st == MPM_OK && res.capped == 1 && res.iters == 3, "cap: st %d capped %d iters %d", st, res.capped,
              res.iters);
    }

    /* 4. zero right-hand side (in the free subspace) */
    {
        double *bz = calloc(len, sizeof(double));
        for (int i = 0; i < p.n; ++i)
            if (p.fixed[i]) bz[3 * i] = 1.0; /* projected away */
        PcgOptions o = {.stop = PCG_FORCING, .tau = 1e-5, .max_iters = 10000};
        st = pcg_solve(&p.op, bj, &p.proj, bz, x, &o, &work, &res);
        CHECK(st == MPM_OK && res.iters == 0 && res.rho0 == 0.0 && vec_norm(len, x) == 0.0,
              "zero rhs: iters %d rho0 %g", res.iters, res.rho0);
        free(bz);
    }

    /* 5. non-positive curvature: stop without dividing, return P(b) at iteration 0 */
    {
        LinearOp neg = {.n_nodes = p.n, .apply = neg_spmv, .ctx = &p.A};
        PcgOptions o = {.stop = PCG_FORCING, .tau = 1e-5, .max_iters = 10000};
        st = pcg_solve(&neg, NULL, &p.proj, b, x, &o, &work, &res);
        vec_copy(len, b, x2);
        projection_apply(&p.proj, x2);
        CHECK(st == MPM_OK && res.iters == 0 && res.capped == 0 && res.indefinite &&
                  memcmp(x, x2, sizeof(double) * len) == 0,
              "indefinite: st %d iters %d capped %d flag %d", st, res.iters, res.capped, res.indefinite);
    }

    /* 6. work arrays grow: a larger problem after a smaller one */
    {
        SynthProblem q;
        SynthParams sq = sp;
        sq.radius = 11.0;
        sq.dirichlet = 0;
        st = synth_build(&q, &sq);
        CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
        size_t lq = 3 * (size_t)q.n;
        double *bq = malloc(sizeof(double) * lq), *xq = malloc(sizeof(double) * lq);
        synth_random_vector(q.n, 9, bq);
        InvApprox *bq_j = make_inv(&inv_block_jacobi_ops, &q);
        PcgOptions o = {.stop = PCG_FORCING, .tau = 1e-5, .max_iters = 10000};
        st = pcg_solve(&q.op, bq_j, NULL, bq, xq, &o, &work, &res);
        CHECK(st == MPM_OK && work.cap_nodes >= q.n && !res.capped, "grown work: st %d cap %d", st, work.cap_nodes);
        inv_destroy(bq_j);
        free(bq);
        free(xq);
        synth_free(&q);
    }

    /* 7. singular diagonal block -> MPM_ENUMERIC (a breakdown of the step) naming the node */
    {
        double *d = malloc(sizeof(double) * 9 * (size_t)p.n);
        memcpy(d, p.diag, sizeof(double) * 9 * (size_t)p.n);
        memset(d + 9 * 17, 0, 9 * sizeof(double));
        d[9 * 17] = 1.0;
        d[9 * 17 + 4] = 1.0; /* rank 2 */
        InvApprox *M = NULL;
        inv_create(&inv_block_jacobi_ops, NULL, &M);
        InvSetupInput in = {.n_nodes = p.n, .diag = d};
        mpm_clear_error();
        st = inv_setup(M, &in);
        CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "node 17"), "singular block: st %d msg '%s'", st,
              mpm_last_error());
        inv_destroy(M);
        inv_create(&inv_scalar_jacobi_ops, NULL, &M);
        mpm_clear_error();
        st = inv_setup(M, &in);
        CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "node 17"), "zero diagonal entry: st %d msg '%s'", st,
              mpm_last_error());
        inv_destroy(M);
        mpm_clear_error();
        free(d);
    }

    /* 8. a variable preconditioner (an inner PCG stopping at half its input's
     * norm, as in a V-cycle's coarsest solve): flexible CG reaches the
     * tolerance in far fewer iterations than plain PCG; with a fixed
     * preconditioner the flexible beta changes nothing but round-off. */
    {
        SynthProblem q;
        SynthParams sq = sp;
        sq.core_ratio = 1e4; /* a stiff inclusion, as in twist's balls */
        st = synth_build(&q, &sq);
        CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
        size_t lq = 3 * (size_t)q.n;
        double *bq = malloc(sizeof(double) * lq), *xq = malloc(sizeof(double) * lq);
        synth_random_vector(q.n, 11, bq);
        InvApprox *inner = make_inv(&inv_inexact_pcg_ops, &q);
        CHECK(inner->flexible == 1, "the inexact PCG must declare itself variable");
        InvApprox *fixed = make_inv(&inv_block_jacobi_ops, &q);
        PcgOptions o = {.stop = PCG_ABSOLUTE, .abs_tol = 0.0, .max_iters = 0};
        pcg_solve(&q.op, fixed, &q.proj, bq, xq, &o, &work, &res);
        o.abs_tol = 1e-10 * res.rho0;
        o.max_iters = 3000;
        int iters[2][2]; /* [fixed, variable preconditioner][plain, flexible] */
        double rr[2][2];
        InvApprox *pre[2] = {fixed, inner};
        for (int v = 0; v < 2; ++v) {
            for (int f = 0; f < 2; ++f) {
                pre[v]->flexible = f;
                if (v == 1) { /* same tolerance in the same (block-Jacobi) norm scale */
                    pcg_solve(&q.op, inner, &q.proj, bq, xq, &(PcgOptions){.stop = PCG_ABSOLUTE}, &work, &res);
                    o.abs_tol = 1e-10 * res.rho0;
                }
                st = pcg_solve(&q.op, pre[v], &q.proj, bq, xq, &o, &work, &res);
                CHECK(st == MPM_OK, "pcg (preconditioner %d, flexible %d): %s", v, f, mpm_last_error());
                iters[v][f] = res.capped ? o.max_iters + 1 : res.iters;
                rr[v][f] = rel_residual(&q, bq, xq);
            }
        }
        printf("stiff core 1e4, to 1e-10: block Jacobi plain %d / flexible %d iterations; inexact inner PCG "
               "plain %d%s / flexible %d (relative residual %.2g)\n",
               iters[0][0], iters[0][1], iters[1][0], iters[1][0] > o.max_iters ? " (capped)" : "", iters[1][1],
               rr[1][1]);
        CHECK(abs(iters[0][0] - iters[0][1]) <= 2, "fixed preconditioner: plain %d vs flexible %d iterations",
              iters[0][0], iters[0][1]);
        CHECK(rr[0][1] < 1e-8 && rr[1][1] < 1e-8, "flexible CG residuals %g %g", rr[0][1], rr[1][1]);
        CHECK(2 * iters[1][1] < iters[1][0], "variable preconditioner: flexible %d vs plain %d iterations",
              iters[1][1], iters[1][0]);

        /* the solve's deadline reaches the inner PCG: with it passed no inner
         * iteration starts and the direction is the block-Jacobi one; a far
         * deadline changes nothing */
        double *zj = malloc(sizeof(double) * lq), *zf = malloc(sizeof(double) * lq);
        projection_apply(&q.proj, bq); /* a gradient: in the free subspace */
        InvApprox *late = make_inv_until(&inv_inexact_pcg_ops, &q, deadline_in(-1.0, "a test deadline"));
        InvApprox *far = make_inv_until(&inv_inexact_pcg_ops, &q, deadline_in(1e6, "a far deadline"));
        st = inv_apply(late, bq, zj);
        CHECK(st == MPM_OK && inv_inner_iters(late) == 0, "past the deadline: %ld inner iterations (st %d)",
              inv_inner_iters(late), st);
        inv_apply(fixed, bq, zf);
        projection_apply(&q.proj, zf);
        double dmax = 0.0;
        for (size_t k = 0; k < lq; ++k) dmax = fmax(dmax, fabs(zj[k] - zf[k]));
        CHECK(dmax == 0.0, "past the deadline: not the block-Jacobi direction (max difference %g)", dmax);
        long before = inv_inner_iters(inner);
        inv_apply(inner, bq, xq);
        long again = inv_inner_iters(inner) - before;
        st = inv_apply(far, bq, zf);
        dmax = 0.0;
        for (size_t k = 0; k < lq; ++k) dmax = fmax(dmax, fabs(xq[k] - zf[k]));
        CHECK(st == MPM_OK && inv_inner_iters(far) == again && again > 0 && dmax == 0.0,
              "a far deadline: %ld inner iterations against %ld without (difference %g)", inv_inner_iters(far),
              again, dmax);
        inv_destroy(late);
        inv_destroy(far);
        free(zj);
        free(zf);

        inv_destroy(inner);
        inv_destroy(fixed);
        free(bq);
        free(xq);
        synth_free(&q);
    }

    inv_destroy(bj);
    inv_destroy(sj);
    pcg_work_free(&work);
    free(b);
    free(x);
    free(x2);
    synth_free(&p);
    return test_summary("test_pcg");
}
