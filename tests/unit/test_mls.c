/* floor: core */
/* MLS-MPM transfers (SPEC 9; Hu et al. 2018 and its supplement):
 *  - the MLS gradient substitute in the stencils equals w_ip 4/dx^2 (x_i - x_p)
 *    computed directly from the node positions;
 *  - it reproduces affine velocity fields exactly: for v_i = A x_i + b,
 *    sum_i v_i (w_ip D^-1 (x_i - x_p))^T = A, and the MLS G2P gives
 *    v_p = A x_p + b, C_p = A and F <- (I + dt A) F;
 *  - APIC/MLS equivalence on velocities (supplement section 1.2): the
 *    linear MLS fit with weights N_i, solved with the full 4x4 moment
 *    matrix M (eq. 4, not assumed diagonal), gives the APIC v_p and
 *    C_p = B_p D_p^-1, and the MLS G2P stores the same v_p and C_p as APIC's
 *    (to round-off); its F update is (I + dt C_p) F;
 *  - P2G -> G2P (dt = 0) -> P2G under MLS conserves mass, linear and angular
 *    momentum; the fused P2G without force equals the APIC P2G;
 *  - the fused P2G with the explicit force (Q_p of supplement 3.1) equals the
 *    two-term P2G whose force uses the MLS gradients. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/mat3.h"
#include "core/transfer.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

static double max_abs(const double *a, size_t n)
{
    double m = 0;
    for (size_t k = 0; k < n; ++k) m = fmax(m, fabs(a[k]));
    return m;
}

static double max_diff(const double *a, const double *b, size_t n)
{
    double m = 0;
    for (size_t k = 0; k < n; ++k) m = fmax(m, fabs(a[k] - b[k]));
    return m;
}

static void node_position(const Stencils *st, size_t k, int s, double dx, double xi[3])
{
    const int *base = st->base + 3 * k;
    xi[0] = (base[0] + s / 9) * dx;
    xi[1] = (base[1] + (s / 3) % 3) * dx;
    xi[2] = (base[2] + s % 3) * dx;
}

static void build(Fixture *f, int mls, int per_axis)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = per_axis;
    o.mls = mls;
    CHECK(fixture_build(f, &o) == 0, "fixture");
}

static void test_substitute_direct(void)
{
    Fixture f;
    build(&f, 1, 6);
    double dx = f.g.dx, worst = 0, scale = 0;
    for (size_t k = 0; k < f.p.n; ++k) {
        double w[27], dw[81];
        stencil_weights(&f.st, k, w, dw);
        for (int s = 0; s < 27; ++s) {
            double xi[3];
            node_position(&f.st, k, s, dx, xi);
            for (int d = 0; d < 3; ++d) {
                double want = w[s] * 4.0 / (dx * dx) * (xi[d] - f.p.x[3 * k + d]);
                worst = fmax(worst, fabs(dw[3 * s + d] - want));
                scale = fmax(scale, fabs(want));
            }
        }
    }
    CHECK(f.st.mls == 1, "stencils marked MLS");
    CHECK(worst <= 1e-13 * scale, "MLS substitute vs w 4/dx^2 (x_i - x_p): max diff %.3e of %.3e", worst, scale);
    fixture_free(&f);
}

static void test_affine_reproduction(void)
{
    Fixture f;
    build(&f, 1, 7);
    const double A[9] = {0.3, -1.2, 0.7, 2.1, 0.4, -0.5, -0.9, 1.6, -0.2}, b[3] = {0.25, -0.5, 1.0};
    int n = f.g.n;
    double dx = f.g.dx, dt = 0.01;
    double *vnew = malloc(sizeof(double) * 3 * (size_t)n);
    for (int i = 0; i < n; ++i) {
        double xi[3] = {f.g.coord[3 * i] * dx, f.g.coord[3 * i + 1] * dx, f.g.coord[3 * i + 2] * dx};
        m3_mulv(A, xi, vnew + 3 * i);
        for (int d = 0; d < 3; ++d) vnew[3 * i + d] += b[d];
    }
    /* the gradient substitute itself */
    double worst = 0;
    for (size_t k = 0; k < f.p.n; ++k) {
        double G[9] = {0}, w[27], dw[81];
        stencil_weights(&f.st, k, w, dw);
        for (int s = 0; s < 27; ++s) {
            int i = f.st.node[27 * k + s];
            if (i < 0) continue;
            for (int a = 0; a < 3; ++a)
                for (int c = 0; c < 3; ++c) G[3 * a + c] += vnew[3 * i + a] * dw[3 * s + c];
        }
        worst = fmax(worst, max_diff(G, A, 9));
    }
    CHECK(worst <= 1e-12 * max_abs(A, 9), "sum v_i dw_mls^T = A: max diff %.3e", worst);
    /* the MLS G2P */
    Particles q = {0};
    particles_copy(&q, &f.p);
    G2POptions opt = {.kind = TRANSFER_MLS, .apic_ratio = 1.0, .flip_alpha = 0.0, .advect = 0};
    transfer_g2p_opts(&f.g, &f.st, &q, vnew, dt, &opt);
    double ev = 0, eC = 0, eF = 0;
    for (size_t k = 0; k < f.p.n; ++k) {
        double v[3], L[9], F[9];
        m3_mulv(A, f.p.x + 3 * k, v);
        for (int d = 0; d < 3; ++d) v[d] += b[d];
        ev = fmax(ev, max_diff(q.v + 3 * k, v, 3) / (fabs(v[0]) + fabs(v[1]) + fabs(v[2])));
        eC = fmax(eC, max_diff(q.C + 9 * k, A, 9));
        for (int e = 0; e < 9; ++e) L[e] = dt * A[e] + (e % 4 == 0);
        m3_mul(L, f.p.F + 9 * k, F);
        eF = fmax(eF, max_diff(q.F + 9 * k, F, 9));
    }
    CHECK(ev <= 1e-13, "MLS G2P v_p = A x_p + b: rel %.3e", ev);
    CHECK(eC <= 1e-12 * max_abs(A, 9), "MLS G2P C_p = A: %.3e", eC);
    CHECK(eF <= 1e-14, "MLS G2P F = (I + dt A) F^n: %.3e", eF);
    particles_free(&q);
    free(vnew);
    fixture_free(&f);
}

/* Solves the 4x4 system M c = r by Gaussian elimination with partial pivoting. */
static void solve4(double M[4][4], double r[4][3], double c[4][3])
{
    for (int col = 0; col < 4; ++col) {
        int piv = col;
        for (int i = col + 1; i < 4; ++i)
            if (fabs(M[i][col]) > fabs(M[piv][col])) piv = i;
        for (int j = 0; j < 4; ++j) {
            double t = M[col][j];
            M[col][j] = M[piv][j];
            M[piv][j] = t;
        }
        for (int d = 0; d < 3; ++d) {
            double t = r[col][d];
            r[col][d] = r[piv][d];
            r[piv][d] = t;
        }
        for (int i = col + 1; i < 4; ++i) {
            double m = M[i][col] / M[col][col];
            for (int j = col; j < 4; ++j) M[i][j] -= m * M[col][j];
            for (int d = 0; d < 3; ++d) r[i][d] -= m * r[col][d];
        }
    }
    for (int i = 3; i >= 0; --i)
        for (int d = 0; d < 3; ++d) {
            double s = r[i][d];
            for (int j = i + 1; j < 4; ++j) s -= M[i][j] * c[j][d];
            c[i][d] = s / M[i][i];
        }
}

static void test_apic_mls_equivalence(void)
{
    Fixture f;
    build(&f, 1, 8);
    int n = f.g.n;
    double dx = f.g.dx, dt = 4e-3;
    double *vnew = malloc(sizeof(double) * 3 * (size_t)n);
    unsigned long long rs = 77;
    for (int i = 0; i < 3 * n; ++i) vnew[i] = f.g.v[i] + test_uniform(&rs, -1, 1);
    Particles pa = {0}, pm = {0};
    particles_copy(&pa, &f.p);
    particles_copy(&pm, &f.p);
    /* APIC on B-spline stencils of the same positions */
    Fixture fa;
    build(&fa, 0, 8);
    CHECK(fa.g.n == n, "same grid");
    G2POptions oa = {.kind = TRANSFER_APIC, .apic_ratio = 1.0, .advect = 1};
    G2POptions om = {.kind = TRANSFER_MLS, .apic_ratio = 1.0, .advect = 1};
    transfer_g2p_opts(&fa.g, &fa.st, &pa, vnew, dt, &oa);
    transfer_g2p_opts(&f.g, &f.st, &pm, vnew, dt, &om);
    size_t np = f.p.n;
    double vs = max_abs(pa.v, 3 * np), cs = max_abs(pa.C, 9 * np);
    CHECK(max_diff(pa.v, pm.v, 3 * np) <= 1e-15 * vs, "APIC vs MLS v_p: %.3e", max_diff(pa.v, pm.v, 3 * np));
    CHECK(max_diff(pa.C, pm.C, 9 * np) <= 1e-15 * cs, "APIC vs MLS C_p: %.3e", max_diff(pa.C, pm.C, 9 * np));
    CHECK(max_diff(pa.x, pm.x, 3 * np) == 0.0, "APIC vs MLS positions bitwise");
    /* the full MLS fit (eq. 1 with the 4x4 moment matrix of eq. 4) and the MLS F update */
    double ev = 0, eC = 0, eF = 0, moff = 0;
    for (size_t k = 0; k < np; ++k) {
        double M[4][4] = {{0}}, r[4][3] = {{0}}, c[4][3];
        double wk[27];
        stencil_weights(&f.st, k, wk, NULL);
        for (int s = 0; s < 27; ++s) {
            int i = f.st.node[27 * k + s];
            if (i < 0) continue;
            double xi[3], P[4];
            node_position(&f.st, k, s, dx, xi);
            P[0] = 1.0;
            for (int d = 0; d < 3; ++d) P[d + 1] = xi[d] - f.p.x[3 * k + d];
            double w = wk[s];
            for (int a = 0; a < 4; ++a) {
                for (int b = 0; b < 4; ++b) M[a][b] += w * P[a] * P[b];
                for (int d = 0; d < 3; ++d) r[a][d] += w * P[a] * vnew[3 * i + d];
            }
        }
        /* quadratic B-spline: M = diag(1, dx^2/4 I) (supplement 1.2) */
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                moff = fmax(moff, fabs(M[a][b] - (a != b ? 0.0 : a == 0 ? 1.0 : 0.25 * dx * dx)) / (a == 0 && b == 0 ? 1.0 : dx * dx));
        solve4(M, r, c);
        double Cfit[9], L[9], F[9];
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) Cfit[3 * a + b] = c[b + 1][a];
        ev = fmax(ev, fabs(c[0][0] - pm.v[3 * k]) + fabs(c[0][1] - pm.v[3 * k + 1]) + fabs(c[0][2] - pm.v[3 * k + 2]));
        eC = fmax(eC, max_diff(Cfit, pm.C + 9 * k, 9));
        for (int e = 0; e < 9; ++e) L[e] = dt * pm.C[9 * k + e] + (e % 4 == 0);
        m3_mul(L, f.p.F + 9 * k, F);
        eF = fmax(eF, max_diff(F, pm.F + 9 * k, 9));
    }
    CHECK(moff <= 1e-13, "moment matrix = diag(1, dx^2/4 I): %.3e", moff);
    CHECK(ev <= 1e-13 * vs, "MLS fit value = v_p: %.3e", ev);
    CHECK(eC <= 1e-12 * cs, "MLS fit gradient = C_p: %.3e of %.3e", eC, cs);
    CHECK(eF <= 1e-14, "MLS F update = (I + dt C_p) F: %.3e", eF);
    particles_free(&pa);
    particles_free(&pm);
    free(vnew);
    fixture_free(&fa);
    fixture_free(&f);
}

static void grid_moments(const Grid *g, double *mass, double P[3], double L[3])
{
    *mass = 0;
    memset(P, 0, 3 * sizeof(double));
    memset(L, 0, 3 * sizeof(double));
    for (int i = 0; i < g->n; ++i) {
        double x[3] = {g->coord[3 * i] * g->dx, g->coord[3 * i + 1] * g->dx, g->coord[3 * i + 2] * g->dx};
        double mv[3] = {g->mass[i] * g->v[3 * i], g->mass[i] * g->v[3 * i + 1], g->mass[i] * g->v[3 * i + 2]};
        double c[3];
        v3_cross(x, mv, c);
        *mass += g->mass[i];
        for (int d = 0; d < 3; ++d) {
            P[d] += mv[d];
            L[d] += c[d];
        }
    }
}

static void test_conservation(void)
{
    Fixture f;
    build(&f, 1, 10);
    double pm = 0, pP[3] = {0}, pL[3] = {0};
    for (size_t k = 0; k < f.p.n; ++k) {
        /* particle angular momentum with APIC's affine part: x_p x m v_p + m (D C^T)_eps (Jiang 2015) */
        double mv[3], c[3];
        for (int d = 0; d < 3; ++d) mv[d] = f.p.mass[k] * f.p.v[3 * k + d];
        v3_cross(f.p.x + 3 * k, mv, c);
        const double *C = f.p.C + 9 * k;
        double D = 0.25 * f.g.dx * f.g.dx, m = f.p.mass[k];
        /* eps : (C D)^T -> components of the axial vector of m D (C^T - C)/2... */
        double aff[3] = {m * D * (C[7] - C[5]), m * D * (C[2] - C[6]), m * D * (C[3] - C[1])};
        pm += f.p.mass[k];
        for (int d = 0; d < 3; ++d) {
            pP[d] += mv[d];
            pL[d] += c[d] + aff[d];
        }
    }
    double m0, P0[3], L0[3];
    grid_moments(&f.g, &m0, P0, L0);
    double Lscale = fabs(L0[0]) + fabs(L0[1]) + fabs(L0[2]);
    CHECK(rel_diff(m0, pm, 1e-300) < 1e-13, "mass: grid %.15e particles %.15e", m0, pm);
    for (int d = 0; d < 3; ++d) {
        CHECK(fabs(P0[d] - pP[d]) < 1e-13 * (fabs(pm) + 1), "P2G linear momentum %d", d);
        CHECK(fabs(L0[d] - pL[d]) < 1e-12 * Lscale, "P2G angular momentum %d: grid %.15e particles %.15e", d, L0[d],
              pL[d]);
    }
    /* fused P2G without force = APIC P2G */
    {
        Fixture fa;
        build(&fa, 0, 10);
        double ma, Pa[3], La[3];
        grid_moments(&fa.g, &ma, Pa, La);
        CHECK(fa.g.n == f.g.n, "same grid");
        double e = max_diff(fa.g.v, f.g.v, 3 * (size_t)f.g.n), s = max_abs(fa.g.v, 3 * (size_t)f.g.n);
        CHECK(e <= 1e-14 * s, "fused MLS P2G (no force) = APIC P2G: %.3e of %.3e", e, s);
        CHECK(max_diff(fa.g.mass, f.g.mass, (size_t)f.g.n) <= 1e-15 * max_abs(fa.g.mass, (size_t)f.g.n), "masses");
        fixture_free(&fa);
    }
    /* G2P (dt = 0) then P2G again */
    double *vgrid = malloc(sizeof(double) * 3 * (size_t)f.g.n);
    memcpy(vgrid, f.g.v, sizeof(double) * 3 * (size_t)f.g.n);
    G2POptions om = {.kind = TRANSFER_MLS, .apic_ratio = 1.0, .advect = 1};
    transfer_g2p_opts(&f.g, &f.st, &f.p, vgrid, 0.0, &om);
    transfer_p2g_mls(&f.g, &f.st, &f.p, NULL);
    double m1, P1[3], L1[3];
    grid_moments(&f.g, &m1, P1, L1);
    CHECK(rel_diff(m1, m0, 1e-300) < 1e-14, "mass after G2P/P2G");
    for (int d = 0; d < 3; ++d) {
        CHECK(fabs(P1[d] - P0[d]) < 1e-12 * (fabs(P0[d]) + pm), "linear momentum %d: %.15e vs %.15e", d, P1[d], P0[d]);
        CHECK(fabs(L1[d] - L0[d]) < 1e-11 * Lscale, "angular momentum %d: %.15e vs %.15e", d, L1[d], L0[d]);
    }
    free(vgrid);
    fixture_free(&f);
}

static void test_fused_force(void)
{
    Fixture f;
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 8;
    o.two_materials = 1;
    o.F_noise = 0.2;
    o.mls = 1;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    ExplicitForce force = {.dt = 2e-3, .mats = f.mats, .gravity = {0, -9.8, 0}};
    size_t len = 3 * (size_t)f.g.n;
    transfer_p2g_mls(&f.g, &f.st, &f.p, &force);
    double *fused = malloc(sizeof(double) * len);
    memcpy(fused, f.g.v, sizeof(double) * len);
    transfer_p2g_apic_force(&f.g, &f.st, &f.p, &force); /* reads the MLS gradient factors in st->f1d */
    double e = max_diff(fused, f.g.v, len), s = max_abs(f.g.v, len);
    CHECK(e <= 1e-12 * s, "fused Q_p P2G = momentum + dt f_i with MLS gradients: %.3e of %.3e", e, s);
    /* and the force matters (not a vacuous comparison) */
    transfer_p2g_mls(&f.g, &f.st, &f.p, NULL);
    CHECK(max_diff(fused, f.g.v, len) > 1e-3 * s, "force changes the grid velocity");
    free(fused);
    fixture_free(&f);
}

int main(void)
{
    test_substitute_direct();
    test_affine_reproduction();
    test_apic_mls_equivalence();
    test_conservation();
    test_fused_force();
    return test_summary("test_mls");
}
