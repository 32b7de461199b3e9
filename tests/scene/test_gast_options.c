/* floor: scene */
/* The scene fields of Gast et al. 2015 section 6 options: absent, they
 * keep the defaults (APIC, forward Euler, shape volumes, frictionless
 * colliders); each bad value is a one-line MPM_EINPUT naming the field and
 * the value. */
#include <string.h>

#include "core/error.h"
#include "core/scene/scene_load.h"
#include "tests/common/testutil.h"

typedef struct {
    const char *key, *value, *field;
} Bad;

int main(void)
{
    Scene s;
    CHECK(scene_load("drop", NULL, &s) == 0, "drop: %s", mpm_last_error());
    CHECK(s.transfer == TRANSFER_APIC && s.position_update == POSITION_FORWARD_EULER && !s.volumes_from_density &&
              s.colliders[0].friction == 0.0,
          "defaults");
    scene_free(&s);
    /* good values */
    SceneOverride good[] = {{"transfer", "{\"type\": \"pic_flip\", \"alpha\": 0}"}, {"position_update", "backward_euler"},
                            {"particle_volume", "grid_density"}, {"colliders.0.type", "slip"},
                            {"colliders.0.friction", "0.4"},
                            {"objects.0.variation", "{\"amplitude\": 0.1, \"length\": 0.03}"}};
    SceneLoadOptions go = {.scale = 1.0, .overrides = good, .n_overrides = 6};
    mpm_clear_error();
    CHECK(scene_load("drop", &go, &s) == 0, "good values: %s", mpm_last_error());
    CHECK(s.transfer == TRANSFER_PIC_FLIP && s.flip_alpha == 0.0 && s.position_update == POSITION_BACKWARD_EULER &&
              s.volumes_from_density && s.colliders[0].friction == 0.4,
          "parsed");
    scene_free(&s);

    static const Bad bad[] = {
        {"transfer", "flip", "transfer"},
        {"transfer", "3", "transfer"},
        {"transfer", "{\"type\": \"apic\"}", "transfer.type"},
        {"transfer", "{\"type\": \"pic_flip\", \"alpha\": 1.5}", "transfer.alpha"},
        {"transfer", "{\"type\": \"pic_flip\", \"beta\": 1}", "transfer.beta"},
        {"flip_alpha", "0.9", "flip_alpha"}, /* not a field */
        {"position_update", "midpoint", "position_update"},
        {"particle_volume", "density", "particle_volume"},
        {"colliders.0.friction", "0.2", "colliders.0.friction"}, /* drop's ground is sticky */
        {"objects.0.variation", "{\"amplitude\": 1.5, \"length\": 0.03}", "objects.0.variation.amplitude"},
        {"objects.0.variation", "{\"amplitude\": 0.1, \"length\": 0}", "objects.0.variation.length"},
        {"objects.0.variation", "{\"amplitude\": 0.1}", "objects.0.variation.length"},
        {"objects.0.variation", "{\"amplitude\": 0.1, \"length\": 0.1, \"seed\": -3}", "objects.0.variation.seed"},
        {"objects.0.variation", "{\"amplitude\": 0.1, \"length\": 0.1, \"size\": 2}", "objects.0.variation"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        SceneOverride ov = {bad[k].key, bad[k].value};
        SceneLoadOptions o = {.scale = 1.0, .overrides = &ov, .n_overrides = 1};
        mpm_clear_error();
        int st = scene_load("drop", &o, &s);
        const char *msg = mpm_last_error();
        CHECK(st == MPM_EINPUT && strstr(msg, bad[k].field) && !strchr(msg, '\n') && strstr(msg, "drop.json"),
              "%s=%s: status %d, message: %s", bad[k].key, bad[k].value, st, msg);
        printf("  %s=%s -> %s\n", bad[k].key, bad[k].value, msg);
        if (!st) scene_free(&s);
    }
    /* "transfer" switches on any scene, apic_ratio (bar3 has one) notwithstanding; the default alpha is 0.95 */
    SceneOverride sw[] = {{"transfer", "pic_flip"}};
    SceneLoadOptions o2 = {.scale = 4.0, .overrides = sw, .n_overrides = 1};
    mpm_clear_error();
    int st = scene_load("bar3", &o2, &s);
    CHECK(st == 0 && s.transfer == TRANSFER_PIC_FLIP && s.flip_alpha == 0.95, "bar3 with pic_flip: %s",
          mpm_last_error());
    if (!st) scene_free(&s);
    SceneOverride back[] = {{"transfer", "apic"}};
    SceneLoadOptions o3 = {.scale = 4.0, .overrides = back, .n_overrides = 1};
    mpm_clear_error();
    st = scene_load("snowball-drop", &o3, &s);
    CHECK(st == 0 && s.transfer == TRANSFER_APIC, "snowball-drop with apic: %s", mpm_last_error());
    if (!st) scene_free(&s);
    SceneOverride alpha[] = {{"transfer.alpha", "0.5"}};
    SceneLoadOptions o4 = {.scale = 4.0, .overrides = alpha, .n_overrides = 1};
    mpm_clear_error();
    st = scene_load("snowball-drop", &o4, &s);
    CHECK(st == 0 && s.transfer == TRANSFER_PIC_FLIP && s.flip_alpha == 0.5, "transfer.alpha=0.5: %s",
          mpm_last_error());
    if (!st) scene_free(&s);
    return test_summary("test_gast_options");
}
