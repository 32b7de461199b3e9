/* floor: core */
/* The step problem's derivatives and products (SPEC 3, 4):
 *  - gradient of E against central differences of E;
 *  - Hessian-vector products (assembled and matrix-free, unprojected tangent)
 *    against central differences of the gradient;
 *  - assembled == matrix-free to 1e-12 relative, with and without Dirichlet nodes;
 *  - the assembled projected Hessian is symmetric positive semidefinite
 *    (GSL eigenvalues) on random, inverted and near-degenerate F;
 *  - each of the above with the MLS-MPM gradient substitute (SPEC 9);
 *  - CN: for one material the scaled residual equals the plain L2 norm times
 *    a constant scale. */
#include <gsl/gsl_eigen.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/vec.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

static double *alloc3(int n) { return calloc(3 * (size_t)n, sizeof(double)); }

static void random_vec(int n, double *v, unsigned long long *rs, double scale)
{
    for (int i = 0; i < 3 * n; ++i) v[i] = scale * test_uniform(rs, -1, 1);
}

static void test_gradient_fd(int mls)
{
    FixtureOptions o;
    fixture_default(&o);
    o.mls = mls;
    o.two_materials = 1;
    o.gravity[1] = -9.8;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    int n = f.pb.n_nodes;
    unsigned long long rs = 7;
    double *dv = alloc3(n), *g = alloc3(n), *d = alloc3(n), *tmp = alloc3(n);
    random_vec(n, dv, &rs, 0.05);
    random_vec(n, d, &rs, 1.0);
    problem_energy(&f.pb, dv);
    problem_gradient(&f.pb, dv, g);
    double gd = vec_dot(3 * (size_t)n, g, d);
    double h = 1e-6;
    for (int i = 0; i < 3 * n; ++i) tmp[i] = dv[i] + h * d[i];
    double Ep = problem_energy(&f.pb, tmp);
    for (int i = 0; i < 3 * n; ++i) tmp[i] = dv[i] - h * d[i];
    double Em = problem_energy(&f.pb, tmp);
    double fd = (Ep - Em) / (2 * h);
    CHECK(rel_diff(fd, gd, 1e-12) < 1e-6, "mls=%d: directional derivative fd %.12e vs g.d %.12e", mls, fd, gd);
    /* per-component check on a few entries */
    for (int k = 0; k < 20; ++k) {
        int idx = (int)test_uniform(&rs, 0, 3 * n);
        memcpy(tmp, dv, sizeof(double) * 3 * (size_t)n);
        tmp[idx] += h;
        double a = problem_energy(&f.pb, tmp);
        tmp[idx] -= 2 * h;
        double b = problem_energy(&f.pb, tmp);
        double fdk = (a - b) / (2 * h);
        CHECK(fabs(fdk - g[idx]) < 1e-6 * (fabs(g[idx]) + vec_norm(3 * (size_t)n, g) / sqrt(3.0 * n)),
              "mls=%d: dE/ddv[%d]: fd %.10e vs %.10e", mls, idx, fdk, g[idx]);
    }
    free(dv), free(g), free(d), free(tmp);
    fixture_free(&f);
}

static void test_hessian_fd(int mls)
{
    FixtureOptions o;
    fixture_default(&o);
    o.mls = mls;
    o.two_materials = 1;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    int n = f.pb.n_nodes;
    size_t len = 3 * (size_t)n;
    unsigned long long rs = 11;
    double *dv = alloc3(n), *d = alloc3(n), *gp = alloc3(n), *gm = alloc3(n), *tmp = alloc3(n), *Hd = alloc3(n),
           *Hd_mf = alloc3(n);
    random_vec(n, dv, &rs, 0.02);
    random_vec(n, d, &rs, 1.0);
    double h = 1e-6;
    for (size_t i = 0; i < len; ++i) tmp[i] = dv[i] + h * d[i];
    problem_energy(&f.pb, tmp);
    problem_gradient(&f.pb, tmp, gp);
    for (size_t i = 0; i < len; ++i) tmp[i] = dv[i] - h * d[i];
    problem_energy(&f.pb, tmp);
    problem_gradient(&f.pb, tmp, gm);
    problem_energy(&f.pb, dv);
    problem_tangent(&f.pb, 0); /* unprojected: exact second derivative */
    Bsr H = {0};
    CHECK(problem_assemble(&f.pb, &H) == 0, "assemble");
    bsr_spmv(&H, d, Hd);
    problem_hessvec(&f.pb, d, Hd_mf);
    double err = 0, nrm = 0, err_mf = 0;
    for (size_t i = 0; i < len; ++i) {
        double fd = (gp[i] - gm[i]) / (2 * h);
        err += (fd - Hd[i]) * (fd - Hd[i]);
        err_mf += (fd - Hd_mf[i]) * (fd - Hd_mf[i]);
        nrm += Hd[i] * Hd[i];
    }
    CHECK(sqrt(err / nrm) < 1e-6, "mls=%d: assembled H d vs gradient differences: rel err %.3e", mls, sqrt(err / nrm));
    CHECK(sqrt(err_mf / nrm) < 1e-6, "mls=%d: matrix-free H d vs gradient differences: rel err %.3e", mls,
          sqrt(err_mf / nrm));
    bsr_free(&H);
    free(dv), free(d), free(gp), free(gm), free(tmp), free(Hd), free(Hd_mf);
    fixture_free(&f);
}

static void mark_some_dirichlet(StepProblem *pb)
{
    for (int i = 0; i < pb->n_nodes; ++i) {
        double v[3] = {0.1, -0.2, 0.3};
        if (i % 7 == 0) problem_set_dirichlet(pb, i, v, NULL);
        else if (i % 11 == 0) {
            double nrm[3] = {0.6, 0.8, 0.0};
            problem_set_dirichlet(pb, i, v, nrm);
        }
    }
    problem_finish_dirichlet(pb);
}

/* Energy and projected tangent at a random dv, then the assembled Hessian. */
static int assemble_at_random_dv(Fixture *f, unsigned long long seed, double *dv, double *x, Bsr *H)
{
    int n = f->pb.n_nodes;
    random_vec(n, dv, &seed, 0.05);
    random_vec(n, x, &seed, 1.0);
    problem_energy(&f->pb, dv);
    problem_tangent(&f->pb, 1);
    return problem_assemble(&f->pb, H);
}

/* ||H x - (H x)_matrix-free|| / ||H x||, the products left in y1, y2. */
static double assembled_vs_matrix_free(Fixture *f, const Bsr *H, const double *x, double *y1, double *y2)
{
    bsr_spmv(H, x, y1);
    problem_hessvec(&f->pb, x, y2);
    double err = 0, nrm = 0;
    for (size_t i = 0; i < 3 * (size_t)f->pb.n_nodes; ++i) {
        err += (y1[i] - y2[i]) * (y1[i] - y2[i]);
        nrm += y1[i] * y1[i];
    }
    return sqrt(err / nrm);
}

/* Two materials, F with 30 % noise and 10 % of the particles inverted: the
 * projection of the tangent is active. */
static void build_mixed_fixture(Fixture *f, int mls)
{
    FixtureOptions o;
    fixture_default(&o);
    o.mls = mls;
    o.two_materials = 1;
    o.per_axis = 8;
    o.F_noise = 0.3;
    o.inverted_fraction_pct = 10;
    CHECK(fixture_build(f, &o) == 0, "fixture");
}

static void test_assembled_equals_matrix_free(int with_bc, int mls)
{
    Fixture f;
    build_mixed_fixture(&f, mls);
    if (with_bc) mark_some_dirichlet(&f.pb);
    int n = f.pb.n_nodes;
    double *dv = alloc3(n), *x = alloc3(n), *y1 = alloc3(n), *y2 = alloc3(n);
    Bsr H = {0};
    CHECK(assemble_at_random_dv(&f, 5, dv, x, &H) == 0, "assemble");
    double rel = assembled_vs_matrix_free(&f, &H, x, y1, y2);
    CHECK(rel < 1e-14, "assembled vs matrix-free (bc=%d, mls=%d): rel diff %.3e", with_bc, mls, rel);
    /* diagonal blocks agree too */
    double *D1 = calloc(9 * (size_t)n, sizeof(double)), *D2 = calloc(9 * (size_t)n, sizeof(double));
    bsr_diagonal(&H, D1);
    problem_diagonal(&f.pb, D2);
    double derr = 0, dn = 0;
    for (size_t i = 0; i < 9 * (size_t)n; ++i) {
        derr += (D1[i] - D2[i]) * (D1[i] - D2[i]);
        dn += D1[i] * D1[i];
    }
    CHECK(sqrt(derr / dn) < 1e-12, "diagonal blocks (bc=%d): rel diff %.3e", with_bc, sqrt(derr / dn));
    /* structure: sorted columns, symmetric blocks */
    int sorted = 1, symmetric = 1;
    for (int i = 0; i < H.n; ++i)
        for (int64_t k = H.row_ptr[i]; k < H.row_ptr[i + 1]; ++k) {
            if (k > H.row_ptr[i] && H.col[k] <= H.col[k - 1]) sorted = 0;
            int64_t kt = bsr_find(&H, H.col[k], i);
            if (kt < 0) {
                symmetric = 0;
                continue;
            }
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    if (fabs(H.val[9 * k + 3 * r + c] - H.val[9 * kt + 3 * c + r]) >
                        1e-10 * (fabs(H.val[9 * k + 3 * r + c]) + 1e-300) + 1e-300)
                        symmetric = 0;
        }
    CHECK(sorted, "columns sorted within rows");
    CHECK(symmetric, "H is symmetric block-wise");
    CHECK(H.nnzb <= 125LL * n, "no padded rows");
    bsr_free(&H);
    free(D1), free(D2), free(dv), free(x), free(y1), free(y2);
    fixture_free(&f);
}

/* problem_assemble_fused: the Hessian of tangent + assemble bit for bit
 * (projected and not, with Dirichlet nodes), without pb->A; afterwards
 * H x matrix-free computes the tangent it needs, and problem_assemble
 * refuses to run on a stale tangent. */
static void test_fused_assembly(int mls)
{
    Fixture f;
    build_mixed_fixture(&f, mls);
    mark_some_dirichlet(&f.pb);
    int n = f.pb.n_nodes;
    double *dv = alloc3(n), *x = alloc3(n), *y1 = alloc3(n), *y2 = alloc3(n);
    unsigned long long seed = 11;
    random_vec(n, dv, &seed, 0.05);
    random_vec(n, x, &seed, 1.0);
    for (int projected = 0; projected <= 1; ++projected) {
        Bsr H1 = {0}, H2 = {0};
        problem_energy(&f.pb, dv);
        CHECK(problem_assemble(&f.pb, &H1) != 0, "problem_assemble without a tangent is refused");
        problem_tangent(&f.pb, projected);
        CHECK(problem_assemble(&f.pb, &H1) == 0, "assemble");
        problem_energy(&f.pb, dv);
        CHECK(problem_assemble_fused(&f.pb, projected, &H2) == 0, "fused assembly");
        CHECK(!f.pb.tangent_stored, "the fused assembly keeps no tangent");
        int same = H1.nnzb == H2.nnzb && memcmp(H1.val, H2.val, sizeof(double) * 9 * (size_t)H1.nnzb) == 0;
        CHECK(same, "mls=%d projected=%d: fused and stored-tangent Hessians differ", mls, projected);
        double rel = assembled_vs_matrix_free(&f, &H2, x, y1, y2);
        CHECK(rel < 1e-14, "mls=%d projected=%d: fused H x vs matrix-free after it: rel diff %.3e", mls, projected,
              rel);
        CHECK(f.pb.tangent_stored && f.pb.tangent_projected == projected, "H x stored the tangent it needed");
        bsr_free(&H1);
        bsr_free(&H2);
    }
    free(dv), free(x), free(y1), free(y2);
    fixture_free(&f);
}

static void test_projected_hessian_spd(int inverted_pct, double F_noise, const char *what, int mls)
{
    FixtureOptions o;
    fixture_default(&o);
    o.mls = mls;
    o.per_axis = 4;
    o.two_materials = 1;
    o.F_noise = F_noise;
    o.inverted_fraction_pct = inverted_pct;
    o.dt = 0.05; /* large dt so the stiffness term dominates the mass */
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    if (strcmp(what, "near-degenerate") == 0) {
        /* flatten particles: one singular value ~ 1e-6, two equal */
        for (size_t k = 0; k < f.p.n; ++k) {
            double *F = f.p.F + 9 * k;
            memset(F, 0, 9 * sizeof(double));
            F[0] = F[4] = 1.0;
            F[8] = (k % 2) ? 1e-6 : -1e-6;
        }
        problem_prepare(&f.pb, &f.g, &f.st, &f.p, f.mats, 2, o.dt, o.gravity);
    }
    int n = f.pb.n_nodes;
    size_t N = 3 * (size_t)n;
    double *dv = alloc3(n);
    problem_energy(&f.pb, dv);
    problem_tangent(&f.pb, 1);
    Bsr H = {0};
    problem_assemble(&f.pb, &H);
    gsl_matrix *M = gsl_matrix_calloc(N, N);
    for (int i = 0; i < n; ++i)
        for (int64_t k = H.row_ptr[i]; k < H.row_ptr[i + 1]; ++k)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    gsl_matrix_set(M, 3 * (size_t)i + r, 3 * (size_t)H.col[k] + c, H.val[9 * k + 3 * r + c]);
    /* remove the mass term: K alone must be PSD for the projected tangent */
    for (int i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r) {
            size_t q = 3 * (size_t)i + r;
            gsl_matrix_set(M, q, q, gsl_matrix_get(M, q, q) - f.g.mass[i]);
        }
    double asym = 0, mx = 0;
    for (size_t i = 0; i < N; ++i)
        for (size_t j = 0; j < N; ++j) {
            asym = fmax(asym, fabs(gsl_matrix_get(M, i, j) - gsl_matrix_get(M, j, i)));
            mx = fmax(mx, fabs(gsl_matrix_get(M, i, j)));
        }
    CHECK(asym <= 1e-12 * mx, "%s: stiffness part symmetric (max asym %.3e of %.3e)", what, asym, mx);
    gsl_vector *ev = gsl_vector_alloc(N);
    gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(N);
    gsl_eigen_symm(M, ev, w);
    double mn = gsl_vector_min(ev), mxe = gsl_vector_max(ev);
    CHECK(mn >= -1e-10 * mxe, "%s: projected stiffness PSD: min eig %.3e, max %.3e", what, mn, mxe);
    gsl_eigen_symm_free(w);
    gsl_vector_free(ev);
    gsl_matrix_free(M);
    bsr_free(&H);
    free(dv);
    fixture_free(&f);
}

static void test_cn_single_material(void)
{
    FixtureOptions o;
    fixture_default(&o);
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    int n = f.pb.n_nodes;
    unsigned long long rs = 3;
    double *g = alloc3(n);
    random_vec(n, g, &rs, 1.0);
    double s = problem_cn_residual(&f.pb, g);
    double a = f.mats[0].stiffness;
    double scale = 24.0 * o.dx * o.dx * o.dt * a;
    double l2 = vec_norm(3 * (size_t)n, g);
    double expect = l2 / (sqrt((double)n) * scale);
    CHECK(rel_diff(s, expect, 1e-300) < 1e-12, "CN residual %.15e vs L2/(sqrt(n) 24 dx^2 dt a) %.15e", s, expect);
    /* every node's abar equals the material stiffness */
    double worst = 0;
    for (int i = 0; i < n; ++i) worst = fmax(worst, rel_diff(f.pb.kappa[i], scale, 1e-300));
    CHECK(worst < 1e-12, "kappa_i constant for one material (worst rel dev %.3e)", worst);
    free(g);
    fixture_free(&f);
}

/* The Hessian's pattern is, per cell (a run of particles with one base
 * node), every pair of the cell's node union: what the assembly's cell
 * scatter adds to. With every particle's far node in one axis at weight
 * exactly 0, some cells hold node pairs no single particle touches; the
 * pattern must hold those too (they receive exact zeros) and nothing else. */
static void test_pattern_cell_union(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.dx = 0.125; /* cell centres exact in binary */
    o.per_axis = 8;
    o.snap_to_centre = 1;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    int n = f.pb.n_nodes;
    const Stencils *st = &f.st;
    char *ref = calloc((size_t)n * (size_t)n, 1), *single = calloc((size_t)n * (size_t)n, 1);
    int missing_nodes = 0;
    const NodeColoring *pc = &st->pcolor;
    for (int q = 0; q < pc->n_blocks; ++q) {
        int k = pc->block_start[q], kend = pc->block_start[q + 1];
        while (k < kend) {
            int k1 = k, node[27];
            for (int t = 0; t < 27; ++t) node[t] = -1;
            for (; k1 < kend && memcmp(st->base + 3 * (size_t)k1, st->base + 3 * (size_t)k, 3 * sizeof(int)) == 0; ++k1) {
                const int *nk = st->node + 27 * (size_t)k1;
                for (int s = 0; s < 27; ++s) {
                    missing_nodes += nk[s] < 0;
                    if (nk[s] >= 0) node[s] = nk[s];
                    for (int t = 0; t < 27; ++t)
                        if (nk[s] >= 0 && nk[t] >= 0) single[(size_t)nk[s] * n + nk[t]] = 1;
                }
            }
            for (int s = 0; s < 27; ++s)
                for (int t = 0; t < 27; ++t)
                    if (node[s] >= 0 && node[t] >= 0) ref[(size_t)node[s] * n + node[t]] = 1;
            k = k1;
        }
    }
    size_t only_union = 0, nref = 0;
    for (size_t e = 0; e < (size_t)n * n; ++e) {
        nref += ref[e];
        only_union += ref[e] && !single[e];
    }
    CHECK(missing_nodes > 0 && only_union > 0, "the fixture exercises zero weights (%d missing stencil nodes) and pairs "
          "of a cell no particle touches (%zu)", missing_nodes, only_union);
    double *dv = alloc3(n), *x = alloc3(n), *y1 = alloc3(n), *y2 = alloc3(n);
    Bsr H = {0};
    CHECK(assemble_at_random_dv(&f, 9, dv, x, &H) == 0, "assemble");
    size_t wrong = 0;
    for (int i = 0; i < H.n; ++i)
        for (int64_t k = H.row_ptr[i]; k < H.row_ptr[i + 1]; ++k) wrong += !ref[(size_t)i * n + H.col[k]];
    CHECK(wrong == 0 && (size_t)H.nnzb == nref, "pattern = the cells' node-union pairs: %lld blocks, %zu expected, %zu "
          "not expected", (long long)H.nnzb, nref, wrong);
    double rel = assembled_vs_matrix_free(&f, &H, x, y1, y2);
    CHECK(rel < 1e-14, "zero weights: assembled vs matrix-free rel diff %.3e", rel);
    bsr_free(&H);
    free(ref), free(single), free(dv), free(x), free(y1), free(y2);
    fixture_free(&f);
}

int main(void)
{
    for (int mls = 0; mls <= 1; ++mls) { /* B-spline gradients, then the MLS substitute (SPEC 9) */
        test_gradient_fd(mls);
        test_hessian_fd(mls);
        test_assembled_equals_matrix_free(0, mls);
        test_assembled_equals_matrix_free(1, mls);
        test_fused_assembly(mls);
        test_projected_hessian_spd(0, 0.4, "random", mls);
        test_projected_hessian_spd(50, 0.3, "inverted", mls);
        test_projected_hessian_spd(0, 0.0, "near-degenerate", mls);
    }
    test_cn_single_material();
    test_pattern_cell_union();
    return test_summary("test_problem");
}
