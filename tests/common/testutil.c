#include "tests/common/testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/scene/scene_load.h"

int g_test_failures = 0, g_test_checks = 0;

double rel_diff(double a, double b, double floor_)
{
    double m = fmax(fmax(fabs(a), fabs(b)), floor_);
    return fabs(a - b) / m;
}

double test_uniform(unsigned long long *state, double lo, double hi)
{
    unsigned long long z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return lo + (hi - lo) * (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

int test_summary(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, g_test_checks, g_test_failures);
    if (g_test_checks == 0) { /* a test that checked nothing proved nothing */
        fprintf(stderr, "%s: no checks ran\n", name);
        return 1;
    }
    return g_test_failures ? 1 : 0;
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
