/* floor: driver */
/* Coulomb friction at slip colliders (Stomakhin et al. 2013 section 8;
 * Gast et al. 2015 section 5.1), applied to the grid velocity after the
 * solve:
 *  - collider_friction on random nodes (moving colliders included): the
 *    relative kinetic energy never increases (the world-frame one neither
 *    for a resting collider), the normal component is kept, and the
 *    tangential speed drops by exactly mu jn when it does not stick (to 0
 *    when |v_t| <= mu jn); jn <= 0 or mu = 0 leave v untouched;
 *  - through the step (pn-pcg solves): a block sliding at 1 m/s on a slip
 *    floor under gravity slows by mu (g T + v_y(T)), the Coulomb law with the
 *    normal impulse read off the block's vertical momentum balance
 *    (J_n = M (g T + v_y(T))), within 0.5 %, and a frictionless floor keeps
 *    its horizontal momentum; "friction" on a sticky collider is an error.
 *    The block slides at 5 m/s on a floor between two node planes so that
 *    one layer of light slip nodes carries the load and no node sticks:
 *    when |v_t| <= mu jn the after-solve rule can remove only the node's own
 *    tangential momentum (the limit Gast et al. note in section 5.3), and the
 *    block decelerates less than Coulomb's law says. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/collider.h"
#include "core/error.h"
#include "core/mat3.h"
#include "core/step.h"
#include "core/scene/scene_load.h"
#include "experiments/driver/registry.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static void random_unit(unsigned long long *rs, double n[3])
{
    double len;
    do {
        for (int d = 0; d < 3; ++d) n[d] = test_uniform(rs, -1, 1);
        len = v3_norm(n);
    } while (len < 0.1 || len > 1);
    for (int d = 0; d < 3; ++d) n[d] /= len;
}

static void test_node_rule(void)
{
    unsigned long long rs = 777;
    int slid = 0, stuck = 0, untouched = 0, ke_up = 0, ke_world_up = 0, bad_drop = 0, bad_normal = 0, bad_stick = 0;
    double worst = 0;
    for (int trial = 0; trial < 200000; ++trial) {
        double n[3], vc[3] = {0, 0, 0}, v[3];
        random_unit(&rs, n);
        int moving = trial % 2;
        if (moving)
            for (int d = 0; d < 3; ++d) vc[d] = test_uniform(&rs, -2, 2);
        for (int d = 0; d < 3; ++d) v[d] = test_uniform(&rs, -3, 3);
        double mu = trial % 7 == 0 ? 0.0 : test_uniform(&rs, 0, 1.5);
        double jn = trial % 5 == 0 ? test_uniform(&rs, -1, 0) : test_uniform(&rs, 0, 2);
        double rel0[3] = {v[0] - vc[0], v[1] - vc[1], v[2] - vc[2]};
        double vn0 = v3_dot(rel0, n), t0[3];
        for (int d = 0; d < 3; ++d) t0[d] = rel0[d] - vn0 * n[d];
        double s0 = v3_norm(t0), ke0 = v3_dot(rel0, rel0), kw0 = v3_dot(v, v);
        double v_in[3] = {v[0], v[1], v[2]};
        int r = collider_friction(n, vc, mu, jn, v);
        double rel[3] = {v[0] - vc[0], v[1] - vc[1], v[2] - vc[2]};
        double vn = v3_dot(rel, n), t[3];
        for (int d = 0; d < 3; ++d) t[d] = rel[d] - vn * n[d];
        double s = v3_norm(t);
        if (v3_dot(rel, rel) > ke0 * (1 + 1e-14) + 1e-300) ++ke_up;
        if (!moving && v3_dot(v, v) > kw0 * (1 + 1e-14) + 1e-300) ++ke_world_up;
        if (fabs(vn - vn0) > 1e-13 * (1 + fabs(vn0))) ++bad_normal;
        if (!(jn > 0) || mu == 0) {
            ++untouched;
            if (r != 0 || memcmp(v, v_in, sizeof v) != 0) ++bad_drop;
        } else if (s0 <= mu * jn) {
            ++stuck;
            if (r != 2 || s > 1e-14) ++bad_stick;
        } else {
            ++slid;
            /* exact up to the round-off of forming v_t from v (|v| <= 5 here) */
            double e = fabs((s0 - s) - mu * jn);
            worst = fmax(worst, e);
            /* the tangential direction is kept */
            double cosang = v3_dot(t, t0) / (s * s0);
            if (r != 1 || e > 1e-14 || cosang < 1 - 1e-12) ++bad_drop;
        }
    }
    printf("friction rule: %d slid (|v_t| drops by mu jn to %.1e m/s), %d stuck, %d untouched; energy increases: %d "
           "relative, %d world (resting colliders)\n",
           slid, worst, stuck, untouched, ke_up, ke_world_up);
    CHECK(slid > 50000 && stuck > 10000 && untouched > 30000, "coverage %d/%d/%d", slid, stuck, untouched);
    CHECK(ke_up == 0 && ke_world_up == 0, "kinetic energy increased %d + %d times", ke_up, ke_world_up);
    CHECK(bad_drop == 0 && bad_stick == 0 && bad_normal == 0, "wrong drop %d, stick %d, normal %d", bad_drop, bad_stick,
          bad_normal);
}

static const char *k_slide =
    "{\"name\": \"slide\", \"description\": \"a block sliding on a slip floor\", \"dx\": 0.02, \"fps\": 48,"
    " \"frames\": 1, \"gravity\": [0, -9.8, 0], \"domain\": {\"min\": [-1, -0.5, -1], \"max\": [2, 1, 1]},"
    " \"materials\": {\"stiff\": {\"E\": 1e6, \"nu\": 0.3, \"density\": 1000}},"
    " \"objects\": [{\"material\": \"stiff\", \"ppc\": 8, \"sampling\": \"lattice\", \"velocity\": [5, 0, 0],"
    "   \"shape\": {\"type\": \"box\", \"min\": [0, 0.095, 0], \"max\": [0.2, 0.195, 0.2]}}],"
    " \"colliders\": [{\"name\": \"floor\", \"type\": \"slip\", \"friction\": 0.3,"
    "   \"shape\": {\"type\": \"half_space\", \"point\": [0, 0.09, 0], \"normal\": [0, 1, 0]}}]}";

typedef struct {
    double vx, vy, t;
    int steps, ok;
} SlideResult;

static double mean_velocity(const Particles *p, int d)
{
    double m = 0, mv = 0;
    for (size_t k = 0; k < p->n; ++k) {
        m += p->mass[k];
        mv += p->mass[k] * p->v[3 * k + d];
    }
    return mv / m;
}

/* Runs the block for `frames` frames with pn-pcg. */
static void slide(const char *friction, int frames, SlideResult *out)
{
    memset(out, 0, sizeof *out);
    const char *set[] = {"colliders.0.friction", friction};
    Scene sc;
    int st = test_scene_from_text(k_slide, 1.0, set, 1, &sc);
    CHECK(st == 0, "scene: %s", mpm_last_error());
    if (st) return;
    Simulation sim;
    st = sim_init(&sim, &sc);
    Solver *solver = NULL;
    if (!st) st = solver_from_spec("pn-pcg", NULL, 0, &solver);
    SolveSettings set_;
    solve_settings_default(&set_);
    set_.eps = 1e-9;
    double *dv = NULL;
    while (!st && sim.frame < frames) {
        if ((st = step_begin(&sim))) break;
        dv = realloc(dv, sizeof(double) * 3 * (size_t)sim.pb.n_nodes);
        problem_initial_guess(&sim.pb, dv);
        SolveStats ss;
        if ((st = solver_solve(solver, &sim.pb, &set_, dv, &ss, NULL, NULL, NULL))) break;
        CHECK(ss.status == SOLVE_CONVERGED, "step %d not converged", out->steps);
        if ((st = step_end(&sim, dv))) break;
        out->steps++;
    }
    CHECK(st == 0, "slide: %s", mpm_last_error());
    out->ok = st == 0;
    out->vx = mean_velocity(&sim.p, 0);
    out->vy = mean_velocity(&sim.p, 1);
    out->t = sim.t;
    free(dv);
    solver_destroy(solver);
    sim_free(&sim);
    scene_free(&sc);
}

static void test_sliding_block(void)
{
    SlideResult fr, free_;
    slide("0.3", 2, &fr);
    slide("0", 2, &free_);
    if (!fr.ok || !free_.ok) return;
    double g = 9.8, want = 5.0 - 0.3 * (g * fr.t + fr.vy);
    printf("sliding block, %d steps to t = %.4f s: v_x %.5f with mu 0.3 (Coulomb: 5 - mu (g T + v_y(T)) = %.5f, "
           "v_y %.2e), %.6f without friction\n",
           fr.steps, fr.t, fr.vx, want, fr.vy, free_.vx);
    CHECK(fabs((5.0 - fr.vx) - (5.0 - want)) < 0.005 * (5.0 - want), "deceleration %.5f vs Coulomb %.5f", 5.0 - fr.vx,
          5.0 - want);
    CHECK(fabs(free_.vx - 5.0) < 1e-4, "frictionless floor keeps v_x: %.9f", free_.vx);
}

static void test_bad_input(void)
{
    const char *set[] = {"colliders.0.type", "sticky"};
    Scene sc;
    mpm_clear_error();
    int st = test_scene_from_text(k_slide, 1.0, set, 1, &sc);
    const char *msg = mpm_last_error();
    CHECK(st == MPM_EINPUT && strstr(msg, "colliders.0.friction") && strstr(msg, "slip") && !strchr(msg, '\n'),
          "friction on a sticky collider: %s", msg);
    if (!st) scene_free(&sc);
    const char *neg[] = {"colliders.0.friction", "-0.1"};
    mpm_clear_error();
    st = test_scene_from_text(k_slide, 1.0, neg, 1, &sc);
    msg = mpm_last_error();
    CHECK(st == MPM_EINPUT && strstr(msg, "colliders.0.friction") && strstr(msg, "-0.1"), "negative friction: %s",
          msg);
    if (!st) scene_free(&sc);
}

int main(void)
{
    test_node_rule();
    test_sliding_block();
    test_bad_input();
    return test_summary("test_friction");
}
