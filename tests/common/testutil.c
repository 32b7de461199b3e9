/* floor: core */
#include "tests/common/testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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

int test_skip(const char *name, const char *why)
{
    printf("%s: SKIPPED: %s\n", name, why);
    return TEST_SKIPPED;
}
