/* floor: scene */
/* libFuzzer harness: the OBJ mesh loader (core/scene/mesh.h) and queries on what
 * it accepts (inside test, signed distance, volume: they walk the
 * bounding-volume hierarchy the loader builds). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/mesh.h"
#include "tests/fuzz/harness.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_setup();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 1 << 16) return 0;
    const char *path = fuzz_write_input(data, size, ".obj");
    if (!path) return 0;
    Mesh *m = NULL;
    mpm_clear_error();
    int st = size && data[0] == '#' ? mesh_load_obj_lenient(path, 8, &m) : mesh_load_obj(path, &m);
    fuzz_require_message(st, "mesh_load_obj");
    if (st == MPM_OK) {
        double v = mesh_volume(m);
        if (!(v > 0) || !isfinite(v)) {
            fprintf(stderr, "accepted mesh with volume %g\n", v);
            abort();
        }
        static const double q[4][3] = {{0, 0, 0}, {0.5, 0.5, 0.5}, {1e3, -2, 7}, {0.1, 0.2, 0.3}};
        for (int k = 0; k < 4; ++k) {
            double d = mesh_signed_distance(m, q[k]);
            int in = mesh_contains(m, q[k]);
            if (isnan(d) || (in != 0 && in != 1)) {
                fprintf(stderr, "query %d: distance %g, inside %d\n", k, d, in);
                abort();
            }
        }
        mesh_free(m);
    }
    return 0;
}
