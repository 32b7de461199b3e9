/* floor: solvers */
/* Coloured symmetric block Gauss-Seidel (HOT reference §5.2): the operator
 * (D+U)^-1 D (D+L)^-1 in processing order is symmetric and positive, matches
 * a serial reference, is bitwise reproducible across runs and thread counts,
 * and as a PCG preconditioner (PN-SGS-PCG) beats block Jacobi. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/krylov/pcg.h"
#include "solvers/inverse/sgs.h"
#include "tests/common/synthetic.h"
#include "tests/common/testutil.h"

/* Serial reference: explicit processing order and rank, sums only over the
 * nodes before (forward) / after (backward) in that order, and the scaling
 * by the actual diagonal block D_i (reference §5.2 steps 1-3). */
static void sgs_reference(const SynthProblem *p, const double *Dinv, const double *r, double *delta)
{
    int n = p->n;
    const Bsr *A = &p->A;
    int *order = malloc(sizeof(int) * (size_t)n), *rank = malloc(sizeof(int) * (size_t)n);
    int t = 0;
    for (int c = 0; c < MPM_NUM_COLORS; ++c)
        for (int bi = p->col.color_start[c]; bi < p->col.color_start[c + 1]; ++bi) {
            int b = p->col.color_blocks[bi];
            for (int i = p->col.block_start[b]; i < p->col.block_start[b + 1]; ++i) order[t++] = i;
        }
    for (int k = 0; k < n; ++k) rank[order[k]] = k;
    double *h = calloc(3 * (size_t)n, sizeof(double));
    for (int k = 0; k < n; ++k) {
        int i = order[k];
        double s[3] = {r[3 * i], r[3 * i + 1], r[3 * i + 2]};
        for (int64_t e = A->row_ptr[i]; e < A->row_ptr[i + 1]; ++e) {
            int j = A->col[e];
            if (rank[j] >= rank[i]) continue;
            double y[3];
            m3_mulv(A->val + 9 * e, h + 3 * j, y);
            for (int d = 0; d < 3; ++d) s[d] -= y[d];
        }
        m3_mulv(Dinv + 9 * i, s, h + 3 * i);
    }
    for (int i = 0; i < n; ++i) { /* h <- D h */
        double y[3];
        m3_mulv(p->diag + 9 * i, h + 3 * i, y);
        memcpy(h + 3 * i, y, sizeof y);
    }
    memset(delta, 0, sizeof(double) * 3 * (size_t)n);
    for (int k = n - 1; k >= 0; --k) {
        int i = order[k];
        double s[3] = {h[3 * i], h[3 * i + 1], h[3 * i + 2]};
        for (int64_t e = A->row_ptr[i]; e < A->row_ptr[i + 1]; ++e) {
            int j = A->col[e];
            if (rank[j] <= rank[i]) continue;
            double y[3];
            m3_mulv(A->val + 9 * e, delta + 3 * j, y);
            for (int d = 0; d < 3; ++d) s[d] -= y[d];
        }
        m3_mulv(Dinv + 9 * i, s, delta + 3 * i);
    }
    free(h);
    free(order);
    free(rank);
}

int main(void)
{
    SynthProblem p;
    SynthParams sp = {.center = {-6, 3, 10}, .radius = 10.0, .reach = 2, .mass = 1.0, .stiff = 1000.0,
                      .dirichlet = 1, .seed = 3};
    int st = synth_build(&p, &sp);
    CHECK(st == MPM_OK, "synth_build: %s", mpm_last_error());
    if (st) return test_summary("test_sgs");
    int n = p.n;
    size_t len = 3 * (size_t)n;
    printf("synthetic problem: %d nodes, %d blocks of 4^3 nodes, %lld nonzero blocks\n", n, p.col.n_blocks,
           (long long)p.A.nnzb);
    CHECK(sgs_check_coloring(&p.A, &p.col) == MPM_OK, "colouring premise: %s", mpm_last_error());

    double *Dinv = malloc(sizeof(double) * 9 * (size_t)n);
    st = block_diag_invert(n, p.diag, Dinv, "test");
    CHECK(st == MPM_OK, "invert: %s", mpm_last_error());
    double *work = malloc(sizeof(double) * 6 * (size_t)n);
    double *x = malloc(sizeof(double) * len), *y = malloc(sizeof(double) * len);
    double *Sx = malloc(sizeof(double) * len), *Sy = malloc(sizeof(double) * len), *ref = malloc(sizeof(double) * len);

    /* symmetry and positivity */
    for (int trial = 0; trial < 3; ++trial) {
        synth_random_vector(n, 100 + trial, x);
        synth_random_vector(n, 200 + trial, y);
        sgs_sweep(&p.A, Dinv, &p.col, x, Sx, work);
        sgs_sweep(&p.A, Dinv, &p.col, y, Sy, work);
        double xSy = vec_dot(len, x, Sy), ySx = vec_dot(len, y, Sx), xSx = vec_dot(len, x, Sx);
        CHECK(rel_diff(xSy, ySx, 1e-300) < 1e-10, "symmetry: x^T S y %.17g vs y^T S x %.17g", xSy, ySx);
        CHECK(xSx > 0.0, "positivity: x^T S x = %g", xSx);
        if (trial == 0) printf("x^T S y = %.15g, y^T S x = %.15g, x^T S x = %.6g\n", xSy, ySx, xSx);
    }

    /* serial reference */
    synth_random_vector(n, 5, x);
    sgs_sweep(&p.A, Dinv, &p.col, x, Sx, work);
    sgs_reference(&p, Dinv, x, ref);
    double maxd = 0.0, maxv = 0.0;
    for (size_t k = 0; k < len; ++k) {
        maxd = fmax(maxd, fabs(Sx[k] - ref[k]));
        maxv = fmax(maxv, fabs(ref[k]));
    }
    CHECK(maxd <= 1e-12 * maxv, "SGS vs serial reference: max diff %g (max value %g)", maxd, maxv);
    printf("SGS vs serial reference: max |diff| / max |value| = %.3g\n", maxd / maxv);

    /* reproducibility: same run twice, 1 vs 2 threads */
    int nt = omp_get_max_threads();
    sgs_sweep(&p.A, Dinv, &p.col, x, Sy, work);
    CHECK(memcmp(Sx, Sy, sizeof(double) * len) == 0, "two runs differ");
    omp_set_num_threads(1);
    sgs_sweep(&p.A, Dinv, &p.col, x, Sy, work);
    CHECK(memcmp(Sx, Sy, sizeof(double) * len) == 0, "1 thread differs from %d threads", nt);
    omp_set_num_threads(2);
    sgs_sweep(&p.A, Dinv, &p.col, x, Sy, work);
    CHECK(memcmp(Sx, Sy, sizeof(double) * len) == 0, "2 threads differ from %d threads", nt);
    omp_set_num_threads(3);
    sgs_sweep(&p.A, Dinv, &p.col, x, Sy, work);
    CHECK(memcmp(Sx, Sy, sizeof(double) * len) == 0, "3 threads differ from %d threads", nt);
    omp_set_num_threads(nt);

    /* single-precision values (SPEC 6.10): the sweep and the residual update
     * on a float copy equal, bitwise, the double code on the same values
     * widened back to double (products and sums stay in double), and differ
     * from the double sweep on the unrounded matrix (the copy is used) */
    {
        float *vf = NULL;
        int64_t capf = 0;
        CHECK(bsr_values_single(&p.A, &vf, &capf) == MPM_OK && capf >= p.A.nnzb, "single copy");
        Bsr Ar = {0};
        CHECK(bsr_copy(&Ar, &p.A) == MPM_OK, "copy");
        for (size_t e = 0; e < 9 * (size_t)Ar.nnzb; ++e) Ar.val[e] = (double)vf[e];
        synth_random_vector(n, 7, x);
        sgs_sweep_single(&p.A, vf, Dinv, &p.col, x, Sx, work);
        sgs_sweep(&Ar, Dinv, &p.col, x, Sy, work);
        CHECK(memcmp(Sx, Sy, sizeof(double) * len) == 0, "single-precision sweep != double sweep on the rounded values");
        sgs_sweep(&p.A, Dinv, &p.col, x, ref, work);
        double dmax = 0.0, vmax = 0.0;
        for (size_t k = 0; k < len; ++k) {
            dmax = fmax(dmax, fabs(Sx[k] - ref[k]));
            vmax = fmax(vmax, fabs(ref[k]));
        }
        CHECK(dmax > 0.0 && dmax < 1e-5 * vmax, "single vs double values: max diff %g of %g (rounding, not more)", dmax,
              vmax);
        printf("SGS on single-precision values: max |diff| / max |value| = %.3g against the doubles\n", dmax / vmax);
        synth_random_vector(n, 8, y);
        memcpy(Sx, y, sizeof(double) * len);
        memcpy(Sy, y, sizeof(double) * len);
        bsr_spmv_sub_single(&p.A, vf, x, Sx);
        bsr_spmv_sub(&Ar, x, Sy);
        CHECK(memcmp(Sx, Sy, sizeof(double) * len) == 0, "single-precision r -= A x != double on the rounded values");
        bsr_free(&Ar);
        free(vf);
    }

    /* Dirichlet rows: decoupled, so a projected input gives zero there */
    projection_apply(&p.proj, x);
    sgs_sweep(&p.A, Dinv, &p.col, x, Sx, work);
    int fixed_zero = 1;
    for (int i = 0; i < n; ++i)
        if (p.fixed[i] && (Sx[3 * i] != 0.0 || Sx[3 * i + 1] != 0.0 || Sx[3 * i + 2] != 0.0)) fixed_zero = 0;
    CHECK(fixed_zero, "Dirichlet nodes must stay zero");

    /* PN-SGS-PCG vs block-Jacobi PCG */
    {
        InvSetupInput in = {.n_nodes = n, .H = &p.A, .diag = p.diag, .coord = p.coord, .coloring = &p.col,
                            .op = &p.op, .proj = &p.proj};
        InvApprox *S = NULL, *J = NULL;
        CHECK(inv_create(&inv_sgs_ops, NULL, &S) == MPM_OK, "sgs create");
        CHECK(inv_setup(S, &in) == MPM_OK, "sgs setup: %s", mpm_last_error());
        inv_create(&inv_block_jacobi_ops, NULL, &J);
        inv_setup(J, &in);
        synth_random_vector(n, 11, y);
        PcgWork w = {0};
        PcgResult rs, rj;
        PcgOptions o = {.stop = PCG_ABSOLUTE, .max_iters = 10000};
        /* tolerance: 1e-8 of the unpreconditioned residual, converted per run */
        o.abs_tol = 0.0;
        o.max_iters = 0;
        pcg_solve(&p.op, J, &p.proj, y, x, &o, &w, &rj);
        o.max_iters = 10000;
        o.abs_tol = 1e-8 * rj.rho0;
        st = pcg_solve(&p.op, J, &p.proj, y, x, &o, &w, &rj);
        o.max_iters = 0;
        o.abs_tol = 0.0;
        pcg_solve(&p.op, S, &p.proj, y, x, &o, &w, &rs);
        o.max_iters = 10000;
        o.abs_tol = 1e-8 * rs.rho0;
        st |= pcg_solve(&p.op, S, &p.proj, y, x, &o, &w, &rs);
        CHECK(st == MPM_OK && !rs.capped && !rj.capped, "pcg runs");
        printf("PCG to 1e-8 (preconditioned norm): block Jacobi %d iterations, SGS %d iterations\n", rj.iters,
               rs.iters);
        CHECK(rs.iters < rj.iters, "SGS-PCG (%d) should need fewer iterations than Jacobi-PCG (%d)", rs.iters,
              rj.iters);
        pcg_work_free(&w);

        InvSetupInput mf = in;
        mf.H = NULL;
        mpm_clear_error();
        st = inv_setup(S, &mf);
        CHECK(st != MPM_OK && strstr(mpm_last_error(), "assembled matrix"), "matrix-free sgs must fail: '%s'",
              mpm_last_error());
        mpm_clear_error();
        inv_destroy(S);
        inv_destroy(J);
    }

    /* the colouring check catches a too-wide stencil */
    {
        SynthProblem w5;
        SynthParams s5 = {.center = {0, 0, 0}, .radius = 6.0, .reach = 5, .mass = 1.0, .stiff = 1.0, .seed = 1};
        st = synth_build(&w5, &s5);
        CHECK(st == MPM_OK, "synth reach 5");
        mpm_clear_error();
        CHECK(sgs_check_coloring(&w5.A, &w5.col) == MPM_EINTERNAL, "reach-5 stencil must violate the colouring");
        mpm_clear_error();
        synth_free(&w5);
    }

    free(Dinv);
    free(work);
    free(x);
    free(y);
    free(Sx);
    free(Sy);
    free(ref);
    synth_free(&p);
    return test_summary("test_sgs");
}
