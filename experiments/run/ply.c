#include "experiments/run/ply.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

int ply_write_particles(const char *path, const Particles *p)
{
    FILE *f = fopen(path, "wb");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot write particle file", path);
    fprintf(f,
            "ply\nformat binary_little_endian 1.0\ncomment mpmbench particles\nelement vertex %zu\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float vx\nproperty float vy\nproperty float vz\nproperty int material\nend_header\n",
            p->n);
    for (size_t k = 0; k < p->n; ++k) {
        float rec[6];
        for (int d = 0; d < 3; ++d) {
            rec[d] = (float)p->x[3 * k + d];
            rec[3 + d] = (float)p->v[3 * k + d];
        }
        int32_t m = p->mat[k];
        fwrite(rec, sizeof rec, 1, f);
        fwrite(&m, sizeof m, 1, f);
    }
    int bad = ferror(f); /* a short fwrite (disk full) shows here or at fclose */
    if (fclose(f) != 0 || bad) return mpm_error(MPM_EINPUT, "%s: write failed", path);
    return MPM_OK;
}
