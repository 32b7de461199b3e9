/* floor: scene */
/* The snow model of Stomakhin et al. 2013 as Gast et al. 2015 use it:
 * fixed corotated on the elastic F with mu = mu0 exp(xi (1 - J_p)),
 * lambda = lambda0 exp(xi (1 - J_p)) (Stomakhin Eq. 2), singular values of
 * F clamped to [1 - theta_c, 1 + theta_s] after each step with
 * J_p <- J_p det(F_old) / det(F_new). core/plasticity.c covers the clamp and
 * the J_p update (tests/unit/test_plasticity.c); this test checks that the
 * hardening reaches the step problem and the clumpy "variation":
 *  - a snow cube with "variation": J_p = 1 / (1 + a nu(x_p)) and
 *    m_p = m0 (1 + a nu(x_p)) from value_noise3, and the step problem's
 *    per-particle Lame parameters equal mu0, lambda0 times
 *    exp(xi (1 - J_p)) (to round-off), its CN stiffness uses them;
 *  - compressing every particle past theta_c (F = 0.9 I, clamped to
 *    0.975 I) lowers J_p by 0.729 / 0.975^3 and the next step's Lame
 *    parameters grow by exactly exp(xi (J_p,old - J_p,new));
 *  - the noise lies in [-1, 1], is deterministic, changes with the seed, is
 *    continuous (|nu(x + h) - nu(x)| <= 3 |h| / L) and flat across its
 *    lattice planes (C^1);
 *  - without hardening, variation changes masses only (no plastic state). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/fcr.h"
#include "core/scene/noise.h"
#include "core/plasticity.h"
#include "core/step.h"
#include "core/scene/scene_load.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static const char *k_snow =
    "{\"name\": \"snow-cube\", \"description\": \"clumpy snow\", \"dx\": 0.05, \"fps\": 24, \"frames\": 1,"
    " \"gravity\": [0, -9.8, 0], \"domain\": {\"min\": [-1, -1, -1], \"max\": [2, 2, 2]},"
    " \"materials\": {\"snow\": {\"E\": 1.4e5, \"nu\": 0.2, \"density\": 400,"
    "    \"plasticity\": {\"type\": \"snow\", \"theta_c\": 0.025, \"theta_s\": 0.0075, \"hardening\": 10}}},"
    " \"objects\": [{\"material\": \"snow\", \"ppc\": 8, \"sampling\": \"lattice\","
    "   \"variation\": {\"amplitude\": 0.2, \"length\": 0.1, \"seed\": 31},"
    "   \"shape\": {\"type\": \"box\", \"min\": [0, 0, 0], \"max\": [0.5, 0.5, 0.5]}}]}";

static void test_noise(void)
{
    unsigned long long rs = 5;
    double lo = 1, hi = -1, mean = 0, worst_slope = 0;
    int same = 1, differ = 0;
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
        double x[3];
        for (int d = 0; d < 3; ++d) x[d] = test_uniform(&rs, -3, 3);
        double v = value_noise3(7, 0.3, x);
        lo = fmin(lo, v);
        hi = fmax(hi, v);
        mean += v / n;
        same &= v == value_noise3(7, 0.3, x);
        differ += v != value_noise3(8, 0.3, x);
        double y[3] = {x[0] + 1e-4, x[1] - 1e-4, x[2] + 1e-4};
        worst_slope = fmax(worst_slope, fabs(value_noise3(7, 0.3, y) - v) / (sqrt(3) * 1e-4) * 0.3);
    }
    /* C^1: the smoothstep weights have zero slope on the lattice planes, so
     * nu is flat across them (a trilinear blend would have a kink there) */
    double worst_kink = 0;
    for (int k = 0; k < 2000; ++k) {
        double x[3];
        for (int d = 0; d < 3; ++d) x[d] = test_uniform(&rs, -3, 3);
        x[0] = 0.3 * floor(x[0] / 0.3);
        double a[3] = {x[0] - 3e-5, x[1], x[2]}, b[3] = {x[0] + 3e-5, x[1], x[2]};
        worst_kink = fmax(worst_kink, fabs(value_noise3(7, 0.3, b) - value_noise3(7, 0.3, a)));
    }
    printf("noise: range [%.3f, %.3f], mean %.3f, largest slope %.2f / L, change across lattice planes %.1e\n", lo,
           hi, mean, worst_slope, worst_kink);
    CHECK(worst_kink < 1e-6, "noise not flat across lattice planes: %g", worst_kink);
    CHECK(lo >= -1 && hi <= 1 && lo < -0.7 && hi > 0.7, "range [%g, %g]", lo, hi);
    CHECK(fabs(mean) < 0.05, "mean %g", mean);
    CHECK(same && differ > n - 10, "deterministic (%d), seed-dependent (%d of %d)", same, differ, n);
    CHECK(worst_slope <= 3.0, "continuity: slope %g / L", worst_slope);
}

static void test_hardening(void)
{
    Scene sc;
    int st = test_scene_from_text(k_snow, 1.0, NULL, 0, &sc);
    CHECK(st == 0, "scene: %s", mpm_last_error());
    if (st) return;
    const Material *m = &sc.materials[0];
    const Particles *P = &sc.particles;
    CHECK(P->Jp != NULL, "snow with hardening stores J_p");
    if (!P->Jp) return;
    double m0 = 400.0 * 0.125 / (double)P->n, worst_init = 0, jmin = 2, jmax = 0;
    for (size_t k = 0; k < P->n; ++k) {
        double ratio = 1.0 + 0.2 * value_noise3(31, 0.1, P->x + 3 * k);
        worst_init = fmax(worst_init, fabs(P->mass[k] - m0 * ratio) / (m0 * ratio));
        worst_init = fmax(worst_init, fabs(P->Jp[k] - 1.0 / ratio) * ratio);
        jmin = fmin(jmin, P->Jp[k]);
        jmax = fmax(jmax, P->Jp[k]);
    }
    printf("variation: J_p in [%.3f, %.3f], masses and J_p match the noise to %.1e\n", jmin, jmax, worst_init);
    CHECK(worst_init < 1e-15, "initial masses / J_p: %g", worst_init);
    CHECK(jmin < 0.9 && jmax > 1.1, "J_p spread [%g, %g]", jmin, jmax);

    Simulation sim;
    st = sim_init(&sim, &sc);
    if (!st) st = step_begin(&sim);
    CHECK(st == 0, "step_begin: %s", mpm_last_error());
    if (st) return;
    double worst = 0, worst_stiff = 0;
    for (size_t k = 0; k < sim.p.n; ++k) {
        double h = exp(10.0 * (1.0 - sim.p.Jp[k]));
        worst = fmax(worst, fabs(sim.pb.mu[k] - h * m->mu) / (h * m->mu));
        worst = fmax(worst, fabs(sim.pb.lambda[k] - h * m->lambda) / (h * m->lambda));
        double a = fcr_rest_stiffness(h * m->mu, h * m->lambda);
        worst_stiff = fmax(worst_stiff, fabs(sim.pb.stiff[k] - a) / a);
    }
    printf("step problem: Lame parameters = exp(xi (1 - J_p)) (mu0, lambda0) to %.1e, CN stiffness to %.1e\n", worst,
           worst_stiff);
    CHECK(worst < 1e-14 && worst_stiff < 1e-14, "hardened Lame parameters %g, stiffness %g", worst, worst_stiff);

    /* compress past theta_c, return-map, and look at the next step's problem */
    double *jold = malloc(sizeof(double) * sim.p.n), *mu_old = malloc(sizeof(double) * sim.p.n);
    for (size_t k = 0; k < sim.p.n; ++k) {
        jold[k] = sim.p.Jp[k];
        mu_old[k] = sim.pb.mu[k];
        double *F = sim.p.F + 9 * k;
        memset(F, 0, 9 * sizeof(double));
        F[0] = F[4] = F[8] = 0.9;
    }
    st = plasticity_apply(&sim.p, sc.materials, sc.n_materials);
    if (!st) st = step_begin(&sim); /* same positions: the grid and stencils are rebuilt the same */
    CHECK(st == 0, "second step: %s", mpm_last_error());
    double ratio = 0.729 / (0.975 * 0.975 * 0.975), worst_jp = 0, worst_growth = 0;
    size_t harder = 0;
    for (size_t k = 0; k < sim.p.n; ++k) {
        /* the particles were not moved, so the sort kept their order */
        worst_jp = fmax(worst_jp, fabs(sim.p.Jp[k] - jold[k] * ratio) / jold[k]);
        double growth = exp(10.0 * (jold[k] - sim.p.Jp[k]));
        worst_growth = fmax(worst_growth, fabs(sim.pb.mu[k] / mu_old[k] - growth) / growth);
        harder += sim.pb.mu[k] > mu_old[k];
    }
    printf("compression 0.9 -> 0.975: J_p x %.4f (to %.1e), mu grows by exp(xi dJ_p) to %.1e, %zu of %zu stiffer\n",
           ratio, worst_jp, worst_growth, harder, sim.p.n);
    CHECK(worst_jp < 1e-13 && worst_growth < 1e-12 && harder == sim.p.n, "hardening after compression: %g %g %zu",
          worst_jp, worst_growth, harder);
    free(jold);
    free(mu_old);
    sim_free(&sim);
    scene_free(&sc);

    /* without hardening: masses vary, no plastic state */
    const char *set[] = {"materials.snow.plasticity.hardening", "0"};
    st = test_scene_from_text(k_snow, 1.0, set, 1, &sc);
    CHECK(st == 0 && sc.particles.Jp == NULL, "no hardening: no J_p (%s)", mpm_last_error());
    if (!st) {
        double lo = 1e30, hi = 0;
        for (size_t k = 0; k < sc.particles.n; ++k) {
            lo = fmin(lo, sc.particles.mass[k]);
            hi = fmax(hi, sc.particles.mass[k]);
        }
        CHECK(hi > 1.15 * lo, "masses still vary: [%g, %g]", lo, hi);
        scene_free(&sc);
    }
}

int main(void)
{
    test_noise();
    test_hardening();
    return test_summary("test_snow_hardening");
}
