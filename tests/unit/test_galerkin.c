/* floor: solvers */
/* Galerkin consistency of the node-embedding hierarchy (HOT §4.1, eq. 6-8;
 * SPEC 6): for the fine Hessian H = M + dt^2 K of a real step problem,
 *   R H P = R M P + dt^2 K_c,
 * where K_c is assembled directly on the coarse grid from the *composed*
 * weight gradients a~_Jp = sum_i P_iJ a_ip (a_ip = F^nT grad w_ip), with the
 * same per-particle tangent A_p. Checked for the linear and quadratic
 * embeddings, to round-off, with B-spline and MLS-MPM gradients. Also: the coarse operators are symmetric PSD. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>

#include "solvers/mg/galerkin.h"
#include "solvers/mg/embedding.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

static void check_embedding(MgEmbedding kind, const char *name, int mls)
{
    FixtureOptions o;
    fixture_default(&o);
    o.mls = mls;
    o.per_axis = 6;
    o.two_materials = 1;
    o.F_noise = 0.3;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    StepProblem *pb = &f.pb;
    int n = pb->n_nodes;
    double *dv = calloc(3 * (size_t)n, sizeof(double));
    problem_energy(pb, dv);
    problem_tangent(pb, 1);
    Bsr H = {0}, Ac = {0};
    CHECK(problem_assemble(pb, &H) == 0, "assemble");
    MgTransfer T;
    memset(&T, 0, sizeof T);
    CHECK(mg_transfer_build(&T, kind, f.g.coord, n) == 0, "transfer");
    CHECK(mg_galerkin(&H, &T, &Ac, NULL) == 0, "galerkin");
    int nc = T.n_coarse;
    size_t N = 3 * (size_t)nc;
    double *direct = calloc(N * N, sizeof(double));
    /* R M P */
    for (int i = 0; i < n; ++i)
        for (int64_t a = T.p_ptr[i]; a < T.p_ptr[i + 1]; ++a)
            for (int64_t b = T.p_ptr[i]; b < T.p_ptr[i + 1]; ++b) {
                double v = T.p_w[a] * f.g.mass[i] * T.p_w[b];
                for (int d = 0; d < 3; ++d) direct[(3 * (size_t)T.p_col[a] + d) * N + 3 * (size_t)T.p_col[b] + d] += v;
            }
    /* dt^2 K_c with composed gradients, particle by particle */
    double dt2 = pb->dt * pb->dt;
    int *cn = malloc(sizeof(int) * 27 * 8);
    double *ca = malloc(sizeof(double) * 27 * 8 * 3);
    for (size_t p = 0; p < f.p.n; ++p) {
        int m = 0;
        const int *node = f.st.node + 27 * p;
        const double *a = pb->a + 81 * p, *A = pb->A + 81 * p;
        for (int s = 0; s < 27; ++s) {
            int i = node[s];
            if (i < 0) continue;
            for (int64_t e = T.p_ptr[i]; e < T.p_ptr[i + 1]; ++e) {
                int J = T.p_col[e], slot = -1;
                for (int q = 0; q < m; ++q)
                    if (cn[q] == J) slot = q;
                if (slot < 0) {
                    slot = m++;
                    cn[slot] = J;
                    ca[3 * slot] = ca[3 * slot + 1] = ca[3 * slot + 2] = 0;
                }
                for (int d = 0; d < 3; ++d) ca[3 * slot + d] += T.p_w[e] * a[3 * s + d];
            }
        }
        double sv = dt2 * f.p.vol[p];
        for (int x = 0; x < m; ++x)
            for (int y = 0; y < m; ++y)
                for (int al = 0; al < 3; ++al)
                    for (int ga = 0; ga < 3; ++ga) {
                        double v = 0;
                        for (int be = 0; be < 3; ++be)
                            for (int de = 0; de < 3; ++de)
                                v += A[9 * (3 * al + be) + 3 * ga + de] * ca[3 * x + be] * ca[3 * y + de];
                        direct[(3 * (size_t)cn[x] + al) * N + 3 * (size_t)cn[y] + ga] += sv * v;
                    }
    }
    /* compare with the sparse Galerkin product */
    double *gal = calloc(N * N, sizeof(double));
    for (int I = 0; I < nc; ++I)
        for (int64_t k = Ac.row_ptr[I]; k < Ac.row_ptr[I + 1]; ++k)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) gal[(3 * (size_t)I + r) * N + 3 * (size_t)Ac.col[k] + c] = Ac.val[9 * k + 3 * r + c];
    double err = 0, nrm = 0, asym = 0;
    for (size_t i = 0; i < N * N; ++i) {
        err = fmax(err, fabs(gal[i] - direct[i]));
        nrm = fmax(nrm, fabs(direct[i]));
    }
    for (size_t i = 0; i < N; ++i)
        for (size_t j = 0; j < N; ++j) asym = fmax(asym, fabs(gal[i * N + j] - gal[j * N + i]));
    printf("%s: %d fine nodes, %d coarse nodes, max |RHP - direct| = %.3e (max entry %.3e)\n", name, n, nc, err, nrm);
    CHECK(err <= 1e-12 * nrm, "%s: R H P differs from the direct coarse assembly by %.3e (scale %.3e)", name, err, nrm);
    CHECK(asym <= 1e-14 * nrm, "%s: coarse operator symmetric (%.3e)", name, asym);
    /* PSD: every eigenvalue of the (small, dense) coarse operator >= 0, up
     * to round-off relative to the largest (GSL symmetric eigensolver) */
    double *work_mat = malloc(sizeof(double) * N * N);
    memcpy(work_mat, gal, sizeof(double) * N * N);
    gsl_matrix_view mv = gsl_matrix_view_array(work_mat, N, N);
    gsl_vector *eval = gsl_vector_alloc(N);
    gsl_eigen_symm_workspace *ws = gsl_eigen_symm_alloc(N);
    gsl_eigen_symm(&mv.matrix, eval, ws);
    double lmin = gsl_vector_min(eval), lmax = gsl_vector_max(eval);
    printf("%s: coarse operator eigenvalues in [%.3e, %.3e]\n", name, lmin, lmax);
    CHECK(lmax > 0 && lmin >= -1e-12 * lmax, "%s: A_c PSD (lambda_min %.3e, lambda_max %.3e)", name, lmin, lmax);
    gsl_eigen_symm_free(ws);
    gsl_vector_free(eval);
    free(work_mat);
    free(gal), free(direct), free(cn), free(ca), free(dv);
    mg_transfer_free(&T);
    bsr_free(&H);
    bsr_free(&Ac);
    fixture_free(&f);
}

int main(void)
{
    check_embedding(MG_EMBED_LINEAR, "linear", 0);
    check_embedding(MG_EMBED_QUADRATIC, "quadratic", 0);
    /* the MLS Hessian (SPEC 9): a_ip from the MLS gradient substitute */
    check_embedding(MG_EMBED_LINEAR, "linear/mls", 1);
    check_embedding(MG_EMBED_QUADRATIC, "quadratic/mls", 1);
    return test_summary("test_galerkin");
}
