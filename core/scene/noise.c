#include "core/scene/noise.h"

#include <math.h>

#include "core/scene/rng.h"

/* Lattice value in [-1, 1] at integer corner (i, j, k). */
static double corner(uint64_t seed, int64_t i, int64_t j, int64_t k)
{
    uint64_t h = rng_mix(seed, (uint64_t)i);
    h = rng_mix(h, (uint64_t)j);
    h = rng_mix(h, (uint64_t)k);
    return (double)(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

double value_noise3(uint64_t seed, double length, const double x[3])
{
    int64_t c[3];
    double t[3];
    for (int d = 0; d < 3; ++d) {
        double s = x[d] / length, f = floor(s);
        c[d] = (int64_t)f;
        double u = s - f;
        t[d] = u * u * (3.0 - 2.0 * u);
    }
    double acc = 0.0;
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int e = 0; e < 2; ++e) {
                double w = (a ? t[0] : 1.0 - t[0]) * (b ? t[1] : 1.0 - t[1]) * (e ? t[2] : 1.0 - t[2]);
                acc += w * corner(seed, c[0] + a, c[1] + b, c[2] + e);
            }
    return acc;
}
