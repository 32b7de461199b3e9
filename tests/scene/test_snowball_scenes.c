/* floor: scene */
/* Gast et al. 2015's three snowball scenes (Fig. 14, 17, 16): each is a
 * built-in, loads at --scale 1 with the particle count its description
 * states (the paper's 2.8e5 per ball) and at its benchmark scale with about
 * 35k, and has the paper's MPM choices (PIC/FLIP 0.95, backward-Euler
 * positions, volumes from the grid density, CFL 0.6, sticky colliders) and
 * Stomakhin's reference snow. Running them is the smoke matrix's job
 * (experiments/matrices/smoke.json, tests/scene/test_scenes_run.sh). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/scene_load.h"
#include "tests/common/testutil.h"

typedef struct {
    const char *name;
    double bench_scale;
    double count1, count_bench; /* as stated in the description */
    const char *stated1, *stated_bench;
    int balls;
} Expect;

static void on_scene(const char *name, const char *desc, void *ctx)
{
    int *found = ctx;
    if (strncmp(name, "snowball-", 9) == 0 && strlen(desc) > 100) ++*found;
}

int main(void)
{
    int listed = 0;
    CHECK(scene_list(on_scene, &listed) == 0 && listed == 3, "three snowball scenes listed (%d)", listed);
    static const Expect want[] = {
        {"snowball-drop", 2.0, 277e3, 34.6e3, "277k particles at scale 1", "34.6k at --scale 2", 1},
        {"snowball-wall", 2.0, 277e3, 34.6e3, "277k particles at scale 1", "34.6k at --scale 2", 1},
        {"snowball-collide", 2.5, 554e3, 35.5e3, "554k particles at scale 1", "35.5k at --scale 2.5", 2},
    };
    for (size_t w = 0; w < sizeof want / sizeof want[0]; ++w) {
        const Expect *e = &want[w];
        for (int pass = 0; pass < 2; ++pass) {
            SceneLoadOptions opt = {.scale = pass ? e->bench_scale : 1.0};
            Scene s;
            mpm_clear_error();
            int st = scene_load(e->name, &opt, &s);
            CHECK(st == 0, "%s: %s", e->name, mpm_last_error());
            if (st) continue;
            double want_n = pass ? e->count_bench : e->count1;
            printf("%-17s --scale %.1f: %zu particles (stated %.0f)\n", e->name, opt.scale, s.particles.n, want_n);
            CHECK(fabs((double)s.particles.n - want_n) < 0.01 * want_n, "%s: %zu particles, stated %.0f", e->name,
                  s.particles.n, want_n);
            CHECK(strstr(s.description, pass ? e->stated_bench : e->stated1) != NULL, "%s: description states %s",
                  e->name, pass ? e->stated_bench : e->stated1);
            CHECK(s.transfer == TRANSFER_PIC_FLIP && s.flip_alpha == 0.95 &&
                      s.position_update == POSITION_BACKWARD_EULER && s.volumes_from_density && s.cfl == 0.6,
                  "%s: Gast's MPM options", e->name);
            const Material *m = &s.materials[0];
            CHECK(s.n_materials == 1 && m->E == 1.4e5 && m->nu == 0.2 && m->density == 400 &&
                      m->plasticity == PLASTICITY_SNOW && m->theta_c == 0.025 && m->theta_s == 0.0075 &&
                      m->hardening == 10,
                  "%s: Stomakhin's reference snow", e->name);
            CHECK(s.n_objects == e->balls && s.particles.Jp != NULL, "%s: %d snowballs with plastic state", e->name,
                  e->balls);
            int sticky = 1;
            for (int c = 0; c < s.n_colliders; ++c) sticky &= s.colliders[c].kind == COLLIDER_STICKY;
            CHECK(sticky && s.n_colliders >= 7, "%s: sticky colliders and domain walls (%d)", e->name, s.n_colliders);
            /* clumps: J_p spread around 1 */
            double lo = 2, hi = 0;
            for (size_t k = 0; k < s.particles.n; ++k) {
                lo = fmin(lo, s.particles.Jp[k]);
                hi = fmax(hi, s.particles.Jp[k]);
            }
            CHECK(lo < 0.95 && hi > 1.05 && lo > 1 / 1.1 - 1e-12 && hi < 1 / 0.9 + 1e-12, "%s: J_p in [%g, %g]",
                  e->name, lo, hi);
            scene_free(&s);
        }
    }
    return test_summary("test_snowball_scenes");
}
