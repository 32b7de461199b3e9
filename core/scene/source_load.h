/* Reading a particle source from its JSON object and sampling its rest
 * frame (core/source.h is the runtime object: emission).
 *
 * JSON form (an entry of the scene's "sources" array; unknown fields are
 * errors):
 *   {"name": "sand",                    optional, default "source<i>"
 *    "material": "sand",                required, a key of "materials"
 *    "shape": {...},                    required, bounded (HOT: a sphere)
 *    "ppc": 16,                         required, > 0: Poisson samples per dx^3
 *                                       (realised 0.868 ppc, sampler.h)
 *    "velocity": [0, -0.5, 0],          required, nonzero: outflow velocity
 *                                       [m/s] in the source's rest frame
 *    "from": 0,                         optional, default 0 [s]
 *    "until": 4.125,                    optional, default forever [s]
 *    "pivot": [..], "motion": [..], "oscillation": {..}
 *                                       optional: the source's rigid motion,
 *                                       exactly as for colliders (collider_load.h)
 *    "collider": true,                  optional, default true
 *    "particle_volume": "sampled"}      optional: "sampled" (default) or
 *                                       "nominal", see core/source.h (rest volume)
 * The rest-frame bounds of the shape are filled with tile samples here
 * (core/source.h, emission); the source's collider is read by
 * collider_parse_named from the same shape and motion. */
#ifndef MPM_SOURCE_LOAD_H
#define MPM_SOURCE_LOAD_H

#include <jansson.h>

#include "core/collider.h"
#include "core/material.h"
#include "core/scene/sampler.h"
#include "core/source.h"

/* Parses one source (`jpath` e.g. "sources.0" names it in messages).
 * `default_name` names an unnamed source. `tile` is the scene's Poisson
 * tile. When the source has a collider, *collider receives it (else it is
 * zeroed). On failure nothing is left to free. */
int source_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                 const Material *mats, int n_mats, const PoissonTile *tile, const char *default_name,
                 Source *out, Collider *collider);

#endif
