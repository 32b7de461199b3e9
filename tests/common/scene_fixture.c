/* floor: scene */
#include "tests/common/scene_fixture.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "core/scene/scene_load.h"

static int step_open(SceneStep *s, const char *scene, double scale, int set_transfer, TransferKind transfer)
{
    memset(s, 0, sizeof *s);
    SceneLoadOptions lo = {.scale = scale};
    int st = scene_load(scene, &lo, &s->sc);
    if (st) return st;
    s->loaded = 1;
    if (set_transfer) s->sc.transfer = transfer;
    if ((st = sim_init(&s->sim, &s->sc))) return st;
    s->started = 1;
    return step_begin(&s->sim);
}

int scene_step_open(SceneStep *s, const char *scene, double scale) { return step_open(s, scene, scale, 0, TRANSFER_APIC); }

int scene_step_open_transfer(SceneStep *s, const char *scene, double scale, TransferKind transfer)
{
    return step_open(s, scene, scale, 1, transfer);
}

void scene_step_close(SceneStep *s)
{
    if (s->started) sim_free(&s->sim);
    if (s->loaded) scene_free(&s->sc);
}

int test_scene_from_text(const char *json, double scale, const char *const *set, int n_set, Scene *out)
{
    static int counter = 0;
    char path[128];
    snprintf(path, sizeof path, "/tmp/mpm_test_text_%d_%d.json", (int)getpid(), counter++);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(json, f);
    fclose(f);
    SceneOverride ov[16];
    if (n_set > 16) n_set = 16;
    for (int k = 0; k < n_set; ++k) ov[k] = (SceneOverride){set[2 * k], set[2 * k + 1]};
    SceneLoadOptions opt = {.scale = scale, .overrides = ov, .n_overrides = n_set};
    int st = scene_load(path, &opt, out);
    remove(path);
    return st;
}
