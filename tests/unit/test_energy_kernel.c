/* floor: scene */
/* The line search's kernels: problem_energy (F(dv), SVD, psi, P per particle,
 * four particles in SIMD lanes, core/fcr4.h) and problem_gradient (by cells,
 * core/gradient_cell.h), for every variant the dispatch can choose (AUTO:
 * AVX, AVX2+FMA where the CPU has them; PORTABLE):
 *  - fcr_psi_P4 against fcr_psi_P and fcr_dPdF4 against fcr_dPdF (plain
 *    and projected) lane by lane, bit for bit (same operations in the same
 *    order, no FMA), on near-identity, large, inverted, rank-deficient,
 *    zero, huge, tiny and NaN inputs and near-degenerate singular values;
 *  - problem_tangent (fcr_dPdF4 by four, the rest alone) against fcr_dPdF
 *    per particle, bit for bit, on the scenes below;
 *  - on a scene's first step (bar3) and on the two-material fixture (with
 *    inverted particles and Dirichlet nodes, B-spline and MLS gradients, and
 *    with zero-weight stencil nodes that differ within a cell),
 *    energy and gradient at a perturbed dv against plain triple loops written
 *    here from the formulas (SPEC 3): a_ip = F^nT grad w_ip,
 *    F = F^n + dt sum_i (v_i + dv_i) a_ip^T, psi and P by fcr_psi_P,
 *    E = sum_i m_i (|dv_i|^2/2 - dt g.dv_i) + sum_p V_p psi_p,
 *    g_i = m_i (dv_i - dt g) + dt sum_p V_p P_p a_ip, projected.
 *    Bounds: the cached F_p and P_p equal the reference's bit for bit (the
 *    same sums in the same order). E differs only by summation order; g by
 *    summation order and by forming (P F^nT) grad w for P (F^nT grad w)
 *    (with FMA in the AVX2 variant). So |E - E_ref| <= 1e-13 sum |terms|, and
 *    |g_ic - g_ref,ic| <= 1e-13 (sum of the node's |inertial terms| +
 *    sum_p |dt V_p| |P_p| |F_p^nT| |grad w_ip|): recursive summation of N
 *    terms errs by at most N u sum |terms| (u = 2^-53, products of three
 *    factors add a few u), and N is a few hundred here: reduce_sum adds
 *    chunks of 64 particles in order and < 100 chunk sums at this size
 *    (164 u = 1.8e-14); a node gathers the particles of the 27 cells around
 *    it (~8 a cell: ~220 terms, 2.4e-14). The reference sums in long double,
 *    so its own error is below that. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fcr.h"
#include "core/fcr4.h"
#include "core/gradient_cell.h"
#include "core/problem.h"
#include "tests/common/fixture.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static double urand(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

/* ------------------------------------------------ fcr_psi_P4 vs fcr_psi_P */

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static void check_lanes(const double F[36], const double mu[4], const double la[4], int kernel, const char *what)
{
    double P[36], psi[4];
    fcr_psi_P4(F, mu, la, P, psi, kernel);
    int bad = 0;
    for (int l = 0; l < 4; ++l) {
        double Pr[9];
        double pr = fcr_psi_P(F + 9 * l, mu[l], la[l], Pr);
        if (!same_bits(pr, psi[l])) ++bad;
        for (int e = 0; e < 9; ++e)
            if (!same_bits(Pr[e], P[9 * l + e])) ++bad;
        if (bad) {
            printf("%s kernel=%d lane %d: psi %.17g vs %.17g, P[0] %.17g vs %.17g\n", what, kernel, l, psi[l], pr,
                   P[9 * l], Pr[0]);
            break;
        }
    }
    CHECK(bad == 0, "%s (kernel %d): fcr_psi_P4 differs from fcr_psi_P", what, kernel);
    /* the tangent, plain and projected */
    for (int proj = 0; proj <= 1; ++proj) {
        double A[4 * 81], Ar[81];
        fcr_dPdF4(F, mu, la, proj, A, kernel);
        int tbad = 0;
        for (int l = 0; l < 4 && !tbad; ++l) {
            fcr_dPdF(F + 9 * l, mu[l], la[l], proj, Ar);
            for (int e = 0; e < 81; ++e)
                if (!same_bits(Ar[e], A[81 * l + e])) {
                    printf("%s kernel=%d projected=%d lane %d: A[%d] %.17g vs %.17g\n", what, kernel, proj, l, e,
                           A[81 * l + e], Ar[e]);
                    tbad = 1;
                    break;
                }
        }
        CHECK(tbad == 0, "%s (kernel %d, projected %d): fcr_dPdF4 differs from fcr_dPdF", what, kernel, proj);
    }
}

static void test_lanes(int kernel)
{
    unsigned long long rs = 99;
    double F[36], mu[4], la[4];
    for (int l = 0; l < 4; ++l) {
        mu[l] = 1e5 * (1.5 + urand(&rs));
        la[l] = 4e5 * (1.5 + urand(&rs));
    }
    static const double noise[] = {1e-6, 1e-3, 0.1, 1.0, 5.0};
    for (size_t ni = 0; ni < sizeof noise / sizeof noise[0]; ++ni)
        for (int rep = 0; rep < 2000; ++rep) {
            for (int l = 0; l < 4; ++l)
                for (int e = 0; e < 9; ++e) F[9 * l + e] = (e % 4 == 0 ? 1.0 : 0.0) + noise[ni] * urand(&rs);
            if (rep % 3 == 1) /* an inverted lane */
                for (int e = 0; e < 3; ++e) F[9 * (rep % 4) + e] = -F[9 * (rep % 4) + e];
            char what[64];
            snprintf(what, sizeof what, "noise %g", noise[ni]);
            check_lanes(F, mu, la, kernel, what);
            if (ni == 2 && rep == 0) { /* special lanes among ordinary ones */
                double G[36];
                memcpy(G, F, sizeof G);
                memset(G, 0, 9 * sizeof(double)); /* zero */
                for (int e = 0; e < 9; ++e) G[9 + e] = 0x1p200 * F[9 + e]; /* scaled up */
                for (int e = 0; e < 9; ++e) G[18 + e] = 0x1p-600 * F[18 + e]; /* scaled down */
                check_lanes(G, mu, la, kernel, "zero, huge, tiny");
                memcpy(G, F, sizeof G);
                for (int r = 0; r < 3; ++r) /* rank one: u v^T */
                    for (int c = 0; c < 3; ++c) G[3 * r + c] = (1.0 + r) * (0.5 - c);
                G[9 + 4] = NAN;
                for (int e = 0; e < 9; ++e) G[18 + e] = e == 0 ? 2.0 : 0.0; /* rank one, axis */
                check_lanes(G, mu, la, kernel, "rank one, NaN");
                memcpy(G, F, sizeof G);
                for (int e = 0; e < 9; ++e) G[27 + e] = (e % 4 == 0) ? 1.0 : 0.0; /* identity */
                for (int e = 0; e < 9; ++e) G[e] = (e == 0 || e == 4) ? 1.5 : 0.0; /* rank two */
                check_lanes(G, mu, la, kernel, "identity, rank two");
                /* near-degenerate singular values, rotated by the other lanes'
                 * F (not orthogonal: a well-conditioned mix), and a pair
                 * sigma_1 + sigma_2 below the tangent's 1e-6 clamp */
                static const double sv[4][3] = {
                    {1.0, 1.0 + 1e-12, 1.0 - 1e-12}, {2.0, 2.0, -2.0}, {1.5, 1.5 * (1 + 1e-9), 0.3}, {2.0, 3e-7, -2.5e-7}};
                memcpy(G, F, sizeof G);
                for (int l = 0; l < 4; ++l) {
                    const double *M = F + 9 * ((l + 1) % 4);
                    for (int r = 0; r < 3; ++r)
                        for (int c = 0; c < 3; ++c) G[9 * l + 3 * r + c] = M[3 * r + c] * sv[l][c];
                }
                check_lanes(G, mu, la, kernel, "near-degenerate, mixed");
                for (int l = 0; l < 4; ++l)
                    for (int e = 0; e < 9; ++e) G[9 * l + e] = e % 4 == 0 ? sv[l][e / 4] : 0.0;
                check_lanes(G, mu, la, kernel, "near-degenerate, diagonal");
            }
        }
}

/* ------------------------------------------------ energy and gradient */

typedef struct {
    double E, Escale;       /* reference energy, sum of |terms| */
    double *g, *gscale;     /* reference gradient, per-entry sum of |terms| */
    double *F, *P;          /* per particle */
} Reference;

static void reference(StepProblem *pb, const double *dv, Reference *R)
{
    const Particles *p = pb->parts;
    const Stencils *st = pb->st;
    const Grid *gr = pb->grid;
    int n = pb->n_nodes;
    double dt = pb->dt;
    long double E = 0.0L, S = 0.0L;
    long double *g = calloc(3 * (size_t)n, sizeof(long double));
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) {
            double t = gr->mass[i] * (dv[3 * i + d] - dt * pb->gravity[d]);
            g[3 * i + d] = t;
            R->gscale[3 * i + d] = fabs(gr->mass[i] * dv[3 * i + d]) + fabs(gr->mass[i] * dt * pb->gravity[d]);
        }
    for (int i = 0; i < n; ++i) {
        const double *d = dv + 3 * i;
        double t = gr->mass[i] * (0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) -
                                  dt * (pb->gravity[0] * d[0] + pb->gravity[1] * d[1] + pb->gravity[2] * d[2]));
        E += t;
        S += fabsl((long double)t);
    }
    for (size_t k = 0; k < p->n; ++k) {
        const double *Fn = p->F + 9 * k;
        double wk[27], dw[81];
        stencil_weights(st, k, wk, dw);
        const int *node = st->node + 27 * k;
        double a[27][3], F[9], P[9];
        for (int s = 0; s < 27; ++s)
            for (int b = 0; b < 3; ++b)
                a[s][b] = Fn[b] * dw[3 * s] + Fn[3 + b] * dw[3 * s + 1] + Fn[6 + b] * dw[3 * s + 2];
        memcpy(F, Fn, sizeof F);
        for (int s = 0; s < 27; ++s) {
            int i = node[s];
            if (i < 0) continue;
            for (int r = 0; r < 3; ++r) {
                double u = dt * (gr->v[3 * i + r] + dv[3 * i + r]);
                for (int c = 0; c < 3; ++c) F[3 * r + c] += u * a[s][c];
            }
        }
        double psi = fcr_psi_P(F, pb->mu[k], pb->lambda[k], P);
        memcpy(R->F + 9 * k, F, sizeof F);
        memcpy(R->P + 9 * k, P, sizeof P);
        E += (long double)(p->vol[k] * psi);
        S += fabsl((long double)(p->vol[k] * psi));
        double sc = dt * p->vol[k];
        for (int s = 0; s < 27; ++s) {
            int i = node[s];
            if (i < 0) continue;
            double abar[3]; /* |F^nT| |grad w| */
            for (int b = 0; b < 3; ++b)
                abar[b] = fabs(Fn[b] * dw[3 * s]) + fabs(Fn[3 + b] * dw[3 * s + 1]) + fabs(Fn[6 + b] * dw[3 * s + 2]);
            for (int r = 0; r < 3; ++r) {
                double f = sc * (P[3 * r] * a[s][0] + P[3 * r + 1] * a[s][1] + P[3 * r + 2] * a[s][2]);
                g[3 * (size_t)i + r] += f;
                R->gscale[3 * (size_t)i + r] +=
                    fabs(sc) * (fabs(P[3 * r]) * abar[0] + fabs(P[3 * r + 1]) * abar[1] + fabs(P[3 * r + 2]) * abar[2]);
            }
        }
    }
    R->E = (double)E;
    R->Escale = (double)S;
    for (size_t e = 0; e < 3 * (size_t)n; ++e) R->g[e] = (double)g[e];
    problem_project(pb, R->g);
    free(g);
}

static void check_problem(StepProblem *pb, const char *what)
{
    int n = pb->n_nodes;
    size_t np = pb->n_particles;
    double *dv = malloc(sizeof(double) * 3 * (size_t)n), *d = malloc(sizeof(double) * 3 * (size_t)n);
    double *g = malloc(sizeof(double) * 3 * (size_t)n);
    Reference R = {0, 0, malloc(sizeof(double) * 3 * (size_t)n), malloc(sizeof(double) * 3 * (size_t)n),
                   malloc(sizeof(double) * 9 * np), malloc(sizeof(double) * 9 * np)};
    unsigned long long rs = 5;
    /* a line-search point: the initial guess plus a projected direction of
     * the velocities' magnitude */
    double vmax = 0.0;
    for (int i = 0; i < 3 * n; ++i) vmax = fmax(vmax, fabs(pb->grid->v[i]));
    problem_initial_guess(pb, dv);
    for (int i = 0; i < 3 * n; ++i) d[i] = (0.1 + vmax) * urand(&rs);
    problem_project(pb, d);
    for (int i = 0; i < 3 * n; ++i) dv[i] += d[i];
    reference(pb, dv, &R);
    for (int kernel = FCR4_AUTO; kernel <= FCR4_PORTABLE; ++kernel) {
        pb->stress_kernel = kernel;
        pb->gradient_kernel = kernel;
        double E = problem_energy(pb, dv);
        problem_gradient(pb, dv, g);
        long fbad = 0, pbad = 0;
        for (size_t e = 0; e < 9 * np; ++e) {
            fbad += !same_bits(pb->F[e], R.F[e]);
            pbad += !same_bits(pb->P[e], R.P[e]);
        }
        double gerr = 0.0; /* max over entries of |g - g_ref| / (sum of |terms|) */
        for (size_t e = 0; e < 3 * (size_t)n; ++e)
            if (R.gscale[e] > 0.0) gerr = fmax(gerr, fabs(g[e] - R.g[e]) / R.gscale[e]);
            else if (g[e] != 0.0 || R.g[e] != 0.0) gerr = INFINITY;
        double eerr = fabs(E - R.E) / R.Escale;
        printf("%s (%zu particles, %d nodes), kernels %s, %s: F, P differ in %ld, %ld entries; energy %.17g, "
               "error %.2e of sum|terms|; gradient error %.2e of sum|terms|\n",
               what, np, n, kernel == FCR4_AUTO ? fcr4_isa() : "portable",
               kernel == GRADIENT_CELL_AUTO ? gradient_cell_isa() : "portable", fbad, pbad, E, eerr, gerr);
        CHECK(fbad == 0 && pbad == 0, "%s kernel %d: F_p, P_p differ from the reference in %ld, %ld entries", what,
              kernel, fbad, pbad);
        CHECK(eerr <= 1e-13, "%s kernel %d: energy %.17g vs reference %.17g (%.2e of sum|terms|)", what, kernel, E,
              R.E, eerr);
        CHECK(gerr <= 1e-13, "%s kernel %d: gradient error %.2e of sum|terms|", what, kernel, gerr);
        /* the tangent at the cached F: fcr_dPdF's bits for every particle
         * (four in lanes, the last n mod 4 alone) */
        for (int proj = 0; proj <= 1; ++proj) {
            problem_tangent(pb, proj);
            long abad = 0;
            double Ar[81];
            for (size_t k = 0; k < np; ++k) {
                fcr_dPdF(pb->F + 9 * k, pb->mu[k], pb->lambda[k], proj, Ar);
                for (int e = 0; e < 81; ++e) abad += !same_bits(pb->A[81 * k + e], Ar[e]);
            }
            printf("%s kernel %d: tangent (projected %d) differs from fcr_dPdF in %ld entries\n", what, kernel,
                   proj, abad);
            CHECK(abad == 0, "%s kernel %d: tangent (projected %d) differs in %ld entries", what, kernel, proj, abad);
        }
    }
    pb->stress_kernel = FCR4_AUTO;
    pb->gradient_kernel = GRADIENT_CELL_AUTO;
    free(R.g), free(R.gscale), free(R.F), free(R.P);
    free(dv), free(d), free(g);
}

static void test_scene(void)
{
    SceneStep ss;
    int st = scene_step_open(&ss, "bar3", 5.0);
    CHECK(st == 0, "open bar3");
    if (!st) check_problem(&ss.sim.pb, "bar3");
    scene_step_close(&ss);
}

/* Marks every seventh node sticky and every fifth slip (as test_problem). */
static void mark_some(StepProblem *pb)
{
    for (int i = 0; i < pb->n_nodes; ++i) {
        double v[3] = {0.1, -0.2, 0.05}, nrm[3] = {0.6, 0.0, 0.8};
        if (i % 7 == 0) problem_set_dirichlet(pb, i, v, NULL);
        else if (i % 5 == 0) problem_set_dirichlet(pb, i, v, nrm);
    }
    problem_finish_dirichlet(pb);
}

/* snap: one coordinate of each particle at its cell's centre, so a node of
 * its stencil has weight exactly 0 (id -1), a different one per particle
 * of a cell: the cell scatter must take those nodes' ids from the others. */
static void test_fixture(int mls, int snap)
{
    FixtureOptions o;
    fixture_default(&o);
    if (snap) {
        o.dx = 0.125; /* cell centres exact in binary */
        o.per_axis = 8;
        o.snap_to_centre = 1;
    }
    o.two_materials = 1;
    o.inverted_fraction_pct = 10;
    o.F_noise = 0.3;
    o.gravity[1] = -9.8;
    o.mls = mls;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    mark_some(&f.pb);
    long zero = 0;
    for (size_t e = 0; e < 27 * f.st.n; ++e) zero += f.st.node[e] < 0;
    if (snap) CHECK(zero > 0, "snap_to_centre: no zero-weight node");
    char what[64];
    snprintf(what, sizeof what, "fixture%s%s (%ld zero weights)", mls ? " MLS" : "", snap ? " snapped" : "", zero);
    check_problem(&f.pb, what);
    fixture_free(&f);
}

int main(void)
{
    for (int kernel = FCR4_AUTO; kernel <= FCR4_PORTABLE; ++kernel) test_lanes(kernel);
    test_scene();
    for (int snap = 0; snap <= 1; ++snap) {
        test_fixture(0, snap);
        test_fixture(1, snap);
    }
    return test_summary("test_energy_kernel");
}
