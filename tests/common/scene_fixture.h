/* floor: scene */
/* Scene-based fixtures for the tests of the scene floor and above
 * (mpm_test_scene): a built-in scene's first step problem, and a scene
 * loaded from JSON text. */
#ifndef MPM_TEST_SCENE_FIXTURE_H
#define MPM_TEST_SCENE_FIXTURE_H

#include "core/step.h"

/* The first step problem of a built-in scene (or scene file) at --scale,
 * ready for a solve (step_begin done). Close it whatever open returned. */
typedef struct {
    Scene sc;
    Simulation sim;
    int loaded, started;
} SceneStep;
int scene_step_open(SceneStep *s, const char *scene, double scale);
/* The same with the scene's transfer replaced (as --set transfer=X). */
int scene_step_open_transfer(SceneStep *s, const char *scene, double scale, TransferKind transfer);
void scene_step_close(SceneStep *s);

/* Writes `json` to a temporary file, loads it as a scene with scale `scale`
 * and the given --set overrides (key, value pairs; n_set of them), removes
 * the file. Returns scene_load's status. */
int test_scene_from_text(const char *json, double scale, const char *const *set, int n_set, Scene *out);

#endif
