/* floor: scene */
/* With the original meshes (never required; their folder in the environment
 * variable MPM_MESH_DIR, docs/scenes.md): sauce-mesh loads with them as its
 * asset folder and its turkey collider sits at +(3, 3, 3). Skipped (exit 77)
 * without them; tests/scene/test_scenes_mesh.sh runs the mesh variants. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/collider.h"
#include "core/error.h"
#include "core/scene/scene_load.h"
#include "tests/common/testutil.h"

int main(void)
{
    const char *dir = getenv("MPM_MESH_DIR");
    if (!dir || !dir[0]) return test_skip("test_mesh_assets", "MPM_MESH_DIR (the original meshes' folder) is not set");
    char probe[512];
    snprintf(probe, sizeof probe, "%s/turkey.obj", dir);
    if (access(probe, R_OK) != 0) return test_skip("test_mesh_assets", "MPM_MESH_DIR has no turkey.obj");
    Scene s;
    SceneLoadOptions opt = {.scale = 3.0, .asset_dir = dir};
    double t0 = omp_get_wtime();
    mpm_clear_error();
    int st = scene_load("sauce-mesh", &opt, &s);
    CHECK(st == 0, "sauce-mesh with --asset-dir: %s", mpm_last_error());
    if (st) return test_summary("test_mesh_assets");
    double inside[3] = {3, 3.4, 3}, outside[3] = {3, 3.9, 3};
    CHECK(collider_phi(&s.colliders[0], 0, inside, NULL) < 0 && collider_phi(&s.colliders[0], 0, outside, NULL) > 0,
          "turkey mesh collider placed at +(3, 3, 3)");
    printf("mesh assets: sauce-mesh loads with --asset-dir %s (%.2f s)\n", dir, omp_get_wtime() - t0);
    scene_free(&s);
    return test_summary("test_mesh_assets");
}
