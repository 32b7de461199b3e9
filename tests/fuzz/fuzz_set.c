/* floor: scene */
/* libFuzzer harness: the --set override parser. Each input line is one
 * "key=value" override (split at the first '=' as the command line does)
 * applied by the scene loader to a fixed small scene (a box on a collider
 * with a source, so object, material, collider and source paths exist). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/sampler.h"
#include "core/scene/scene_load.h"
#include "tests/fuzz/harness.h"

static char g_scene[256];

static const char k_base[] =
    "{\"name\": \"f\", \"dx\": 0.05, \"fps\": 24, \"frames\": 2, \"gravity\": [0, -9.8, 0],\n"
    " \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, \"domain_walls\": true,\n"
    " \"materials\": {\"soft\": {\"E\": 1e5, \"nu\": 0.3, \"density\": 1000},\n"
    "               \"sand\": {\"E\": 1e5, \"nu\": 0.3, \"density\": 1000,\n"
    "                        \"plasticity\": {\"type\": \"snow\", \"theta_c\": 0.01, \"theta_s\": 0.001}}},\n"
    " \"objects\": [{\"material\": \"soft\", \"ppc\": 8, \"velocity\": [0, -1, 0],\n"
    "   \"shape\": {\"type\": \"box\", \"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]}}],\n"
    " \"colliders\": [{\"name\": \"cap\", \"shape\": {\"type\": \"cylinder\", \"center\": [0.5, 0.8, 0.5],\n"
    "   \"radius\": 0.1, \"height\": 0.05}, \"motion\": [{\"until\": 1, \"angular_velocity_deg\": [0, 90, 0]},\n"
    "   {\"velocity\": [0, 0, 0]}]}],\n"
    " \"sources\": [{\"material\": \"sand\", \"ppc\": 8, \"velocity\": [0, -0.5, 0], \"until\": 1,\n"
    "   \"shape\": {\"type\": \"sphere\", \"center\": [0.2, 0.8, 0.2], \"radius\": 0.05}}]}\n";

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_setup();
    (void)poisson_tile_shared(1);
    const char *p = fuzz_write_input((const uint8_t *)k_base, sizeof k_base - 1, "_base.json");
    if (!p) abort();
    snprintf(g_scene, sizeof g_scene, "%s", p);
    return 0;
}

enum { MAX_SET = 16 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;
    char *text = malloc(size + 1);
    if (!text) return 0;
    if (size) memcpy(text, data, size);
    text[size] = '\0';
    SceneOverride ov[MAX_SET];
    int n = 0;
    for (char *line = text; line && n < MAX_SET;) {
        char *nl = strchr(line, '\n');
        if (nl) *nl = '\0';
        char *eq = strchr(line, '=');
        if (eq) { /* like main.c: key=value, the key non-empty */
            *eq = '\0';
            if (strcmp(line, "seed") == 0 && fuzz_new_tile_seed((const uint8_t *)eq + 1, strlen(eq + 1))) {
                line = nl ? nl + 1 : NULL; /* a new Poisson tile: seconds, see fuzz_scene.c */
                continue;
            }
            ov[n].key = line;
            ov[n].value = eq + 1;
            ++n;
        }
        line = nl ? nl + 1 : NULL;
    }
    Scene s;
    SceneLoadOptions opt = {.overrides = ov, .n_overrides = n, .max_particles = 20000};
    mpm_clear_error();
    int st = scene_load(g_scene, &opt, &s);
    fuzz_require_message(st, "scene_load with --set");
    if (st == MPM_OK) scene_free(&s);
    free(text);
    return 0;
}
