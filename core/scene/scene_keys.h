/* The keys of the scene file's objects (docs/scenes.md): one table per kind
 * of object, each key once, with whether it may be absent. The readers check
 * an object against its table (an unknown key is an error listing the known
 * ones in table order), and --set may add a key its table lets be absent. */
#ifndef MPM_SCENE_KEYS_H
#define MPM_SCENE_KEYS_H

#include <jansson.h>

typedef struct {
    const char *name;
    int optional;   /* may be absent (the reader has a default), so --set may add it */
    unsigned only;  /* 0: in every variant of the object; else the variants (bits) that have it */
} SceneKey;

/* Each ends with an entry whose name is NULL. */
extern const SceneKey scene_top_keys[];        /* the file's top level */
extern const SceneKey scene_material_keys[];   /* materials.NAME */
extern const SceneKey scene_plasticity_keys[]; /* materials.NAME.plasticity, variants by "type" below */
extern const SceneKey scene_object_keys[];     /* objects[i] */
extern const SceneKey scene_collider_keys[];   /* colliders[i] */
extern const SceneKey scene_source_keys[];     /* sources[i] */

/* The variants of plasticity ("type"). */
enum { SCENE_PLASTICITY_NONE = 1u << 0, SCENE_PLASTICITY_VON_MISES = 1u << 1, SCENE_PLASTICITY_SNOW = 1u << 2 };

/* Is obj an object whose keys are all in keys (those of `variant`; 0: of
 * every variant)? Else MPM_EINPUT: "FILE: PATH.KEY: unknown key (known: ...)"
 * (core/scene/json_read.h sj_check_object). */
int scene_keys_check(json_t *obj, const char *file, const char *path, const SceneKey *keys, unsigned variant);

/* May the key `name` of keys be absent? 0 also when keys has no such key. */
int scene_key_optional(const SceneKey *keys, const char *name);

#endif
