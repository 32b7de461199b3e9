/* floor: scene */
/* Particle volumes from the grid density (Gast et al. 2015 section 6.1 step
 * 2): on a uniform lattice of ppc = 8 particles per cell (spacing dx/2) the
 * quadratic B-spline sums to 2 per axis over the lattice, so m_i = 8 m_p at
 * every node whose support lies inside the block and V_p = m_p dx^3 / sum_i
 * w_ip m_i = dx^3 / 8 exactly (to round-off) for particles at least 3 dx
 * inside; near the faces the density falls and V_p grows. The estimate is
 * made once (the first step), the scene's own copy keeps the shape volumes,
 * and without the option nothing changes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/step.h"
#include "core/scene/scene_load.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static const char *k_cube =
    "{\"name\": \"vol-cube\", \"description\": \"lattice cube\", \"dx\": 0.1, \"fps\": 24, \"frames\": 1,"
    " \"gravity\": [0, -9.8, 0], \"domain\": {\"min\": [-1, -1, -1], \"max\": [2, 2, 2]},"
    " \"materials\": {\"soft\": {\"E\": 1e4, \"nu\": 0.3, \"density\": 500}},"
    " \"objects\": [{\"material\": \"soft\", \"ppc\": 8, \"sampling\": \"lattice\","
    "   \"shape\": {\"type\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 1, 1]}}]}";

int main(void)
{
    const char *set[] = {"particle_volume", "grid_density"};
    Scene sc;
    int st = test_scene_from_text(k_cube, 1.0, set, 1, &sc);
    CHECK(st == 0 && sc.volumes_from_density, "scene: %s", mpm_last_error());
    if (st) return test_summary("test_volume_density");
    double dx = sc.dx, want = dx * dx * dx / 8.0, shape_vp = 1.0 / (double)sc.particles.n;
    CHECK(sc.particles.n == 8000, "8000 lattice particles, got %zu", sc.particles.n);
    Simulation sim;
    st = sim_init(&sim, &sc);
    if (!st) st = step_begin(&sim);
    CHECK(st == 0, "step_begin: %s", mpm_last_error());
    size_t interior = 0, bad = 0, surface = 0, surface_larger = 0;
    double worst = 0, vmax = 0;
    for (size_t k = 0; k < sim.p.n; ++k) {
        const double *x = sim.p.x + 3 * k;
        double depth = HUGE_VAL;
        for (int d = 0; d < 3; ++d) depth = fmin(depth, fmin(x[d], 1.0 - x[d]));
        double v = sim.p.vol[k];
        vmax = fmax(vmax, v);
        if (depth > 3 * dx) {
            ++interior;
            double e = fabs(v - want) / want;
            worst = fmax(worst, e);
            bad += e > 1e-13;
        } else if (depth < dx) {
            ++surface;
            surface_larger += v > want * (1 + 1e-3);
        }
    }
    printf("interior particles: %zu, V_p = dx^3/8 to %.2e; surface particles: %zu, %zu with larger V_p "
           "(largest %.3f dx^3/8)\n",
           interior, worst, surface, surface_larger, vmax / want);
    CHECK(interior == 512 && bad == 0, "%zu of %zu interior volumes differ from dx^3/8 (worst %g)", bad, interior, worst);
    CHECK(surface > 3000 && surface_larger == surface, "surface: %zu of %zu have a larger volume", surface_larger,
          surface);
    CHECK(sc.particles.vol[0] == shape_vp, "the scene keeps the shape volumes");
    /* only the first step estimates: mark a volume, step again */
    double *dv = malloc(sizeof(double) * 3 * (size_t)sim.pb.n_nodes);
    problem_initial_guess(&sim.pb, dv);
    if (!st) st = step_end(&sim, dv);
    sim.p.vol[0] = 1.2345;
    if (!st) st = step_begin(&sim);
    CHECK(st == 0 && sim.p.vol[0] == 1.2345, "second step left the volumes alone");
    free(dv);
    sim_free(&sim);
    scene_free(&sc);

    /* default: shape volumes */
    st = test_scene_from_text(k_cube, 1.0, NULL, 0, &sc);
    CHECK(st == 0 && !sc.volumes_from_density, "default scene");
    if (!st) {
        st = sim_init(&sim, &sc);
        if (!st) st = step_begin(&sim);
        int same = st == 0;
        for (size_t k = 0; k < sim.p.n && same; ++k) same = sim.p.vol[k] == shape_vp;
        CHECK(same, "without particle_volume the volumes stay shape volume / count");
        sim_free(&sim);
        scene_free(&sc);
    }
    return test_summary("test_volume_density");
}
