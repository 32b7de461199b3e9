/* floor: scene */
/* libFuzzer harness: the scene loader (core/scene/scene_load.h), called directly on a
 * scene file. Every input must give MPM_OK or a one-line MPM_EINPUT /
 * MPM_EINTERNAL message; ASan/UBSan and the leak checker find the rest.
 * The particle budget is small so each input samples in milliseconds, and
 * the Poisson tile of the default seed is made once up front (the loader's
 * process-wide tile cache then stays warm across inputs); an input that
 * asks for another valid seed is skipped, since a new tile takes seconds
 * to generate under the sanitizers (invalid seeds are still loaded). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/sampler.h"
#include "core/scene/scene_load.h"
#include "tests/fuzz/harness.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_setup();
    (void)poisson_tile_shared(1);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 1 << 16) return 0;
    if (fuzz_new_tile_seed(data, size)) return 0;
    const char *path = fuzz_write_input(data, size, ".json");
    if (!path) return 0;
    Scene s;
    SceneLoadOptions opt = {.max_particles = 20000};
    mpm_clear_error();
    int st = scene_load(path, &opt, &s);
    fuzz_require_message(st, "scene_load");
    if (st == MPM_OK) {
        for (size_t k = 0; k < 3 * s.particles.n; ++k)
            if (!(s.particles.x[k] >= s.domain_lo[k % 3] && s.particles.x[k] <= s.domain_hi[k % 3])) {
                fprintf(stderr, "loaded particle %zu outside the domain\n", k / 3);
                abort();
            }
        scene_free(&s);
    }
    return 0;
}
