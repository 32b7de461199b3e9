/* floor: scene */
/* Backward-Euler particle positions (Gast et al. 2015 section 6.3):
 *  - a test built for the paper's argument: a lattice block moves at 1 m/s
 *    onto a resting sticky ground with dt = 2 dx / v. Where the whole
 *    B-spline stencil of a point consists of sticky nodes (the collider's
 *    core, phi <= -dx/2 for a ground surface on a node plane) the grid
 *    velocity is 0, so x^{n+1} = x^n + dt v(x^{n+1}) has no solution there
 *    for a particle that starts outside: backward Euler leaves no particle
 *    in the core, while forward Euler (x += dt v(x^n)) puts some there
 *    and more inside the collider (phi < 0), where this block's backward
 *    Euler puts none (its lowest row lands exactly on the surface);
 *  - away from the ground (uniform field) every particle moves by exactly
 *    dt v, and Newton converges for every particle;
 *  - grid_velocity_at: the gradient matches central differences of v(x)
 *    (the renormalised interpolation is C^1), and where the whole stencil
 *    exists it is the plain B-spline interpolation (weights sum to 1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/collider.h"
#include "core/error.h"
#include "core/position_update.h"
#include "core/step.h"
#include "core/scene/scene_load.h"
#include "tests/common/fixture.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static const char *k_block =
    "{\"name\": \"be-block\", \"description\": \"lattice block onto a sticky ground\", \"dx\": 0.1, \"fps\": 1,"
    " \"frames\": 1, \"cfl\": 2.0, \"gravity\": [0, 0, 0],"
    " \"domain\": {\"min\": [-1, -1, -1], \"max\": [2, 2, 2]},"
    " \"materials\": {\"soft\": {\"E\": 1e3, \"nu\": 0.3, \"density\": 1000}},"
    " \"objects\": [{\"material\": \"soft\", \"ppc\": 8, \"sampling\": \"lattice\", \"velocity\": [0, -1, 0],"
    "   \"shape\": {\"type\": \"box\", \"min\": [0, 0.02, 0], \"max\": [0.6, 0.62, 0.6]}}],"
    " \"colliders\": [{\"name\": \"ground\", \"type\": \"sticky\","
    "   \"shape\": {\"type\": \"half_space\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0]}}]}";

typedef struct {
    size_t in_collider, in_core;
    double min_phi;
    size_t moved_exactly, far; /* particles that started >= 3.5 dx above the ground */
    PositionUpdateStats stats;
} Outcome;

/* One step with dv = the initial guess: sticky nodes at rest, free nodes at
 * v^n (no gravity, no solve needed: the field is what the test is about). */
static int one_step(const char *position_update, Outcome *out)
{
    memset(out, 0, sizeof *out);
    const char *set[] = {"position_update", position_update};
    Scene sc;
    int st = test_scene_from_text(k_block, 1.0, set, 1, &sc);
    CHECK(st == 0, "scene: %s", mpm_last_error());
    if (st) return st;
    Simulation sim;
    st = sim_init(&sim, &sc);
    if (!st) st = step_begin(&sim);
    CHECK(st == 0 && fabs(sim.dt - 0.2) < 1e-12, "dt %g (expected 2 dx / v = 0.2)", sim.dt);
    double *y0 = malloc(sizeof(double) * sim.p.n);
    for (size_t k = 0; k < sim.p.n; ++k) y0[k] = sim.p.x[3 * k + 1];
    double *x0 = malloc(sizeof(double) * 3 * sim.p.n);
    memcpy(x0, sim.p.x, sizeof(double) * 3 * sim.p.n);
    double *dv = malloc(sizeof(double) * 3 * (size_t)sim.pb.n_nodes);
    problem_initial_guess(&sim.pb, dv);
    if (!st) st = step_end(&sim, dv);
    CHECK(st == 0, "step_end: %s", mpm_last_error());
    out->min_phi = HUGE_VAL;
    const Collider *ground = &sc.colliders[0];
    double dx = sc.dx;
    for (size_t k = 0; k < sim.p.n; ++k) {
        double phi = collider_phi(ground, 0.0, sim.p.x + 3 * k, NULL);
        out->in_collider += phi < 0.0;
        out->in_core += phi <= -0.5 * dx;
        if (phi < out->min_phi) out->min_phi = phi;
        if (y0[k] >= 3.5 * dx) { /* old and new stencils free: the field is uniform there */
            out->far++;
            double e = fabs(sim.p.x[3 * k + 1] - (y0[k] - sim.dt)) + fabs(sim.p.x[3 * k] - x0[3 * k]) +
                       fabs(sim.p.x[3 * k + 2] - x0[3 * k + 2]);
            out->moved_exactly += e < 1e-12;
        }
    }
    out->stats = sim.pos_stats;
    free(dv);
    free(x0);
    free(y0);
    sim_free(&sim);
    scene_free(&sc);
    return st;
}

static void test_sticky_ground(void)
{
    Outcome fe, be;
    if (one_step("forward_euler", &fe) || one_step("backward_euler", &be)) return;
    printf("forward Euler:  %zu particles inside the ground, %zu in its core (phi <= -dx/2), min phi %.4f\n",
           fe.in_collider, fe.in_core, fe.min_phi);
    printf("backward Euler: %zu particles inside the ground, %zu in its core, min phi %.4f; Newton: %ld iterations "
           "(max %d per particle), %ld halvings, %zu unconverged\n",
           be.in_collider, be.in_core, be.min_phi, be.stats.newton_iters, be.stats.max_newton_iters,
           be.stats.halvings, be.stats.unconverged);
    CHECK(fe.in_core > 100, "forward Euler should carry particles into the core (%zu)", fe.in_core);
    CHECK(be.in_core == 0, "backward Euler put %zu particles into the sticky core", be.in_core);
    /* here the lowest row (0.25 dx up) lands exactly on the surface: x = x^n + dt v(x) has its root at
     * phi = 0 (v(surface) = 0.125 v for a ground on a node plane, times dt v = 2 dx) */
    CHECK(be.min_phi > -1e-9 * 0.1, "backward Euler: deepest particle at phi %g", be.min_phi);
    CHECK(fe.in_collider > 500 && fe.min_phi < -0.6 * 0.1, "forward Euler: %zu particles inside, min phi %g",
          fe.in_collider, fe.min_phi);
    CHECK(be.stats.unconverged == 0 && be.stats.max_newton_iters <= 8, "Newton: %zu unconverged, max %d iterations",
          be.stats.unconverged, be.stats.max_newton_iters);
    CHECK(be.far >= 720 && be.moved_exactly == be.far, "uniform field: %zu of %zu moved by exactly dt v",
          be.moved_exactly, be.far);
    CHECK(fe.far >= 720 && fe.moved_exactly == fe.far, "forward Euler, uniform field: %zu of %zu", fe.moved_exactly,
          fe.far);
}

/* grid_velocity_at against central differences, and against the stencil. */
static void test_field(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 8;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    int n = f.g.n;
    double *vel = malloc(sizeof(double) * 3 * (size_t)n);
    unsigned long long rs = 99;
    for (int i = 0; i < n; ++i) /* a smooth field plus noise */
        for (int d = 0; d < 3; ++d)
            vel[3 * i + d] = sin(3.0 * f.g.coord[3 * i + (d + 1) % 3] * f.g.dx) + 0.3 * test_uniform(&rs, -1, 1);
    double worst_g = 0, worst_v = 0;
    int full = 0, partial = 0;
    for (size_t k = 0; k < f.p.n; k += 7) {
        /* points around particle k, some reaching the block's edge where nodes are missing */
        double x[3];
        for (int d = 0; d < 3; ++d) x[d] = f.p.x[3 * k + d] + test_uniform(&rs, -1.5, 1.5) * f.g.dx;
        double v[3], G[9];
        double W = grid_velocity_at(&f.g, vel, x, NULL, NULL, v, G);
        if (!(W > 0)) continue;
        if (W > 1 - 1e-12) ++full;
        else ++partial;
        double h = 1e-6 * f.g.dx;
        for (int b = 0; b < 3; ++b) {
            double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]}, vp[3], vm[3], Gt[9];
            xp[b] += h;
            xm[b] -= h;
            grid_velocity_at(&f.g, vel, xp, NULL, NULL, vp, Gt);
            grid_velocity_at(&f.g, vel, xm, NULL, NULL, vm, Gt);
            for (int a = 0; a < 3; ++a) {
                double fd = (vp[a] - vm[a]) / (2 * h);
                double e = fabs(fd - G[3 * a + b]) / (1.0 / f.g.dx);
                if (e > worst_g) worst_g = e;
            }
        }
        /* hinted evaluation (a particle's own stencil) equals the hashed one */
        double vh[3], Gh[9];
        grid_velocity_at(&f.g, vel, f.p.x + 3 * k, f.st.base + 3 * k, f.st.node + 27 * k, vh, Gh);
        double vn[3], Gn[9];
        grid_velocity_at(&f.g, vel, f.p.x + 3 * k, NULL, NULL, vn, Gn);
        /* at its own position a particle's stencil is complete: plain interpolation sum w v */
        double ref[3] = {0, 0, 0}, wk[27];
        stencil_weights(&f.st, k, wk, NULL);
        for (int s = 0; s < 27; ++s) {
            int i = f.st.node[27 * k + s];
            if (i < 0) continue;
            for (int d = 0; d < 3; ++d) ref[d] += wk[s] * vel[3 * i + d];
        }
        for (int d = 0; d < 3; ++d) {
            worst_v = fmax(worst_v, fabs(vh[d] - vn[d]));
            worst_v = fmax(worst_v, fabs(vn[d] - ref[d]));
        }
    }
    printf("grid_velocity_at: %d points with a full stencil, %d with missing nodes; gradient vs central "
           "differences %.2e (relative to 1/dx), hinted/plain/stencil values agree to %.2e\n",
           full, partial, worst_g, worst_v);
    CHECK(full > 10 && partial > 10, "coverage: %d full, %d partial stencils", full, partial);
    CHECK(worst_g < 1e-6, "gradient vs central differences: %g", worst_g);
    CHECK(worst_v < 1e-14, "hinted, hashed and stencil interpolation differ by %g", worst_v);
    free(vel);
    fixture_free(&f);
}

/* A rough random field (dt |grad v| of order 1, CFL 1): full Newton steps
 * overshoot for some particles, and the halving rule keeps every particle's
 * residual ||x - x^n - dt v(x)|| from growing (it starts at dt |v(x^n)|). */
static void test_rough_field(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 12;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    int n = f.g.n;
    double *vel = malloc(sizeof(double) * 3 * (size_t)n), V = 1.0, dt = f.g.dx / V;
    unsigned long long rs = 2024;
    for (int i = 0; i < 3 * n; ++i) vel[i] = V * test_uniform(&rs, -1, 1);
    size_t np = f.p.n;
    double *x0 = malloc(sizeof(double) * 3 * np);
    memcpy(x0, f.p.x, sizeof(double) * 3 * np);
    PositionUpdateStats ps;
    position_update_backward_euler(&f.g, &f.st, &f.p, vel, dt, &ps);
    size_t grew = 0;
    double worst = 0;
    for (size_t k = 0; k < np; ++k) {
        double v[3], G[9], r[3];
        grid_velocity_at(&f.g, vel, x0 + 3 * k, NULL, NULL, v, G);
        double r0 = dt * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        grid_velocity_at(&f.g, vel, f.p.x + 3 * k, NULL, NULL, v, G);
        for (int d = 0; d < 3; ++d) r[d] = f.p.x[3 * k + d] - x0[3 * k + d] - dt * v[d];
        double r1 = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        worst = fmax(worst, r1 / f.g.dx);
        grew += r1 > r0 * (1 + 1e-12);
    }
    printf("rough field: %ld Newton iterations over %zu particles (max %d), %ld halvings, %zu unconverged, "
           "%zu residuals grew, largest final residual %.2e dx\n",
           ps.newton_iters, np, ps.max_newton_iters, ps.halvings, ps.unconverged, grew, worst);
    CHECK(ps.halvings > 0, "the field should need step halvings");
    CHECK(grew == 0, "%zu particles ended with a larger residual than they started with", grew);
    free(x0);
    free(vel);
    fixture_free(&f);
}

int main(void)
{
    test_sticky_ground();
    test_field();
    test_rough_field();
    return test_summary("test_position_update");
}
