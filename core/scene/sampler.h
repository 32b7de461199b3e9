/* Particle sampling inside a shape. Deterministic for a given seed (and
 * independent of the number of OpenMP threads).
 *
 * - "poisson": blue-noise (Poisson-disk) samples cut from a periodic tile,
 *   as the HOT reference does (docs/scenes.md §4, hot-scenes.md section 1.5). The tile
 *   is generated once per seed with Bridson's algorithm (Bridson, "Fast
 *   Poisson disk sampling in arbitrary dimensions", SIGGRAPH 2007 sketches)
 *   made periodic, with unit minimum distance; it is anchored at the world
 *   origin and scaled so that the realised density is exactly
 *   SAMPLER_DENSITY * ppc samples per dx^3 on average (0.868 * ppc, the
 *   density implied by the paper's particle counts). Because the tile is
 *   anchored at the world origin, two objects with the same ppc that touch
 *   (e.g. the segments of a bar) continue one blue-noise pattern across the
 *   interface. See sampler_poisson_min_distance for the resulting spacing.
 * - "random": N = round(SAMPLER_DENSITY * ppc * volume / dx^3) points
 *   uniform in the shape (rejection from its bounds); the reference's
 *   "FullyRandom".
 * - "lattice": ppc = k^3 points per grid cell [i dx, (i+1) dx]^3 on a
 *   cell-centred k x k x k sub-lattice, those inside the shape.
 * A point x is inside when shape_contains(x) (i.e. shape_sdf(x) <= 0).
 * The scene assigns each particle the rest volume shape_volume / N (as the
 * reference does for analytic shapes). */
#ifndef MPM_SAMPLER_H
#define MPM_SAMPLER_H

#include <stddef.h>
#include <stdint.h>

#include "core/scene/shape.h"

/* Realised samples per dx^3 per unit ppc of the "poisson" and "random"
 * samplers (HOT: 0.864-0.871 over eight scenes, docs/scenes.md §4, hot-scenes.md). */
#define SAMPLER_DENSITY 0.868

typedef enum { SAMPLING_POISSON = 0, SAMPLING_RANDOM = 1, SAMPLING_LATTICE = 2 } SamplingKind;

/* "poisson", "random", "lattice" -> kind; returns 0 if unknown. */
int sampling_kind_from_string(const char *s, SamplingKind *out);
const char *sampling_kind_name(SamplingKind k);

/* A periodic Poisson-disk tile with minimum distance 1 (periodic distance). */
typedef struct PoissonTile PoissonTile;
int poisson_tile_create(uint64_t seed, PoissonTile **out);
void poisson_tile_free(PoissonTile *t);
/* A process-wide tile for `seed`, generated on first use and kept until the
 * process exits (a memo of poisson_tile_create, so repeated scene loads do
 * not pay the ~0.5 s generation again). Thread-safe. Do not free it. NULL
 * when out of memory or when tiles for 8 other seeds are already cached
 * (then create one with poisson_tile_create). */
const PoissonTile *poisson_tile_shared(uint64_t seed);
size_t poisson_tile_count(const PoissonTile *t);
double poisson_tile_period(const PoissonTile *t);        /* edge length, in min distances */
const double *poisson_tile_points(const PoissonTile *t); /* 3 * count, in [0, period) */

/* Minimum distance between "poisson" samples for (dx, ppc), i.e. the tile
 * scale: cbrt(density_tile * dx^3 / (SAMPLER_DENSITY * ppc)). */
double sampler_poisson_min_distance(const PoissonTile *t, double dx, double ppc);

typedef struct {
    double *x;       /* 3n coordinates */
    size_t n, cap;
    double min_dist; /* guaranteed minimum spacing (poisson: tile scale, lattice: dx/k, random: 0) */
} SamplePoints;

/* Samples `shape` (must be bounded, finite volume). `tile` (nullable) is used
 * for "poisson"; when NULL the tile for `seed` is used (poisson_tile_shared). "random" draws from
 * `seed` too. ppc must be > 0; "lattice" needs ppc = k^3 for an integer k.
 * Appends to *out (zero-initialise it first). */
int sampler_sample(const Shape *shape, SamplingKind kind, double dx, double ppc, uint64_t seed,
                   const PoissonTile *tile, SamplePoints *out);

/* n points on the surface of `shape` (bounded), spread uniformly by area
 * to O((h curvature)^2): candidates uniform in the bounds within |phi| < h
 * of the surface, projected onto phi = 0 along the gradient (Newton steps
 * on phi, |phi| <= 1e-3 h at the end). Deterministic for a seed and any
 * thread count. Appends to *out (min_dist is left unchanged). The scene uses
 * it to stand in for the reference's mesh-vertex particles (scene_load.h,
 * "surface_particles"); h = dx / 4 there. */
int sampler_surface(const Shape *shape, size_t n, double h, uint64_t seed, SamplePoints *out);

void sample_points_free(SamplePoints *p);

#endif
