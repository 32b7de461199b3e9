/* The scene file's key tables (scene_keys.h). */
#include "core/scene/scene_keys.h"

#include <string.h>

#include "core/scene/json_read.h"

#define SCENE_KEYS_MAX 32 /* keys of one table */

/* A key the reader needs, one it can do without, one only some variants have. */
#define REQUIRED(name) {name, 0, 0}
#define OPTIONAL(name) {name, 1, 0}
#define OPTIONAL_IN(name, variants) {name, 1, variants}
#define END {NULL, 0, 0}

const SceneKey scene_top_keys[] = {
    REQUIRED("name"),       OPTIONAL("description"), REQUIRED("dx"),        REQUIRED("fps"),
    REQUIRED("frames"),     OPTIONAL("cfl"),         OPTIONAL("max_dt"),    OPTIONAL("min_dt"),
    OPTIONAL("cfl_rule"),   REQUIRED("gravity"),     OPTIONAL("apic_ratio"), REQUIRED("domain"),
    OPTIONAL("domain_walls"), OPTIONAL("seed"),      REQUIRED("materials"), REQUIRED("objects"),
    OPTIONAL("colliders"),  OPTIONAL("sources"),     OPTIONAL("transfer"),  OPTIONAL("position_update"),
    OPTIONAL("particle_volume"), END};

const SceneKey scene_material_keys[] = {REQUIRED("E"), REQUIRED("nu"), REQUIRED("density"), OPTIONAL("plasticity"),
                                        END};

const SceneKey scene_plasticity_keys[] = {REQUIRED("type"),
                                          OPTIONAL_IN("yield_stress", SCENE_PLASTICITY_VON_MISES),
                                          OPTIONAL_IN("theta_c", SCENE_PLASTICITY_SNOW),
                                          OPTIONAL_IN("theta_s", SCENE_PLASTICITY_SNOW),
                                          OPTIONAL_IN("hardening", SCENE_PLASTICITY_SNOW),
                                          OPTIONAL_IN("min_Jp", SCENE_PLASTICITY_SNOW),
                                          OPTIONAL_IN("max_Jp", SCENE_PLASTICITY_SNOW),
                                          END};

const SceneKey scene_object_keys[] = {
    OPTIONAL("name"),     REQUIRED("material"), REQUIRED("shape"),     REQUIRED("ppc"),
    OPTIONAL("sampling"), OPTIONAL("velocity"), OPTIONAL("initial_F"), OPTIONAL("surface_particles"),
    OPTIONAL("variation"), OPTIONAL("stiffness_variation"), END};

const SceneKey scene_collider_keys[] = {
    OPTIONAL("name"),        OPTIONAL("type"),   REQUIRED("shape"),          OPTIONAL("pivot"),
    OPTIONAL("motion"),      OPTIONAL("oscillation"), OPTIONAL("material_velocity"), OPTIONAL("cfl_speed"),
    OPTIONAL("friction"),    END};

const SceneKey scene_source_keys[] = {
    OPTIONAL("name"),   REQUIRED("material"), REQUIRED("shape"),       REQUIRED("ppc"),
    REQUIRED("velocity"), OPTIONAL("from"),   OPTIONAL("until"),       OPTIONAL("pivot"),
    OPTIONAL("motion"), OPTIONAL("oscillation"), OPTIONAL("collider"), OPTIONAL("particle_volume"), END};

int scene_keys_check(json_t *obj, const char *file, const char *path, const SceneKey *keys, unsigned variant)
{
    const char *names[SCENE_KEYS_MAX + 1];
    int n = 0;
    for (const SceneKey *k = keys; k->name && n < SCENE_KEYS_MAX; ++k)
        if (!variant || !k->only || (k->only & variant)) names[n++] = k->name;
    names[n] = NULL;
    return sj_check_object(obj, file, path, names);
}

int scene_key_optional(const SceneKey *keys, const char *name)
{
    for (const SceneKey *k = keys; k->name; ++k)
        if (!strcmp(k->name, name)) return k->optional;
    return 0;
}
