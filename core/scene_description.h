/* A loaded scene: plain data (materials, colliders, sources, the initial
 * particles, the time-stepping settings) that the runtime reads. Reading it
 * from a scene file, the file format and the overrides are
 * core/scene/scene_load.h. */
#ifndef MPM_SCENE_DESCRIPTION_H
#define MPM_SCENE_DESCRIPTION_H

#include <stddef.h>

#include "core/collider.h"
#include "core/material.h"
#include "core/particles.h"
#include "core/position_update.h"
#include "core/source.h"
#include "core/transfer.h"

typedef enum { CFL_RULE_PAPER = 0, CFL_RULE_REFERENCE = 1 } CflRule;

typedef struct Scene {
    char name[64];
    char description[512];
    char path[1024];
    double dx;                        /* already multiplied by scale */
    int frames;
    double fps, cfl, max_dt, min_dt;  /* cfl default 0.6, max_dt default 1/fps, min_dt 1e-6 */
    CflRule cfl_rule;                 /* collider speed rule of the CFL dt (SPEC 12) */
    double gravity[3];
    double apic_ratio;                /* RPIC/APIC blend r (1 = APIC, 0 = RPIC) */
    TransferKind transfer;            /* "transfer": APIC (default), MLS or PIC/FLIP */
    double flip_alpha;                /* "transfer".alpha (PIC/FLIP only) */
    PositionUpdateKind position_update; /* "position_update" */
    int volumes_from_density;         /* "particle_volume": "grid_density" */
    double domain_lo[3], domain_hi[3];
    int domain_walls;                 /* the six wall colliders were added */
    Material *materials;              /* declaration order */
    int n_materials;
    Collider *colliders;              /* scene colliders, source colliders, then the domain walls */
    int n_colliders;
    Source *sources;                  /* particle sources (core/source.h) */
    int n_sources;
    Particles particles;              /* initial state */
    int needs_plasticity;             /* some material is plastic */
    unsigned long long seed;
    int n_objects;
    size_t *object_offsets;           /* n_objects + 1: object k owns particles
                                         [object_offsets[k], object_offsets[k+1]) */
} Scene;

#endif
