/* Smooth 3D value noise for procedural material variation (the clumps of a
 * snowball, see core/scene/scene_load.h "variation"): random values in [-1, 1] at the
 * corners of a cubic lattice of spacing `length`, blended with the C^1
 * smoothstep weights 3t^2 - 2t^3 per axis. The result lies in [-1, 1], is
 * continuous, varies on the scale `length` and depends only on (seed, x):
 * the same clumps at every --scale. */
#ifndef MPM_NOISE_H
#define MPM_NOISE_H

#include <stdint.h>

double value_noise3(uint64_t seed, double length, const double x[3]);

#endif
