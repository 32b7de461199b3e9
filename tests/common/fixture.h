/* floor: core */
/* A small hand-built step problem for unit tests that need no scene file:
 * a jittered lattice of particles in a cube, random velocities, APIC C and
 * deformation gradients, one or two fixed-corotated materials. Core floor
 * (mpm_test_core); a scene's first step problem is in scene_fixture.h. */
#ifndef MPM_TEST_FIXTURE_H
#define MPM_TEST_FIXTURE_H

#include "core/grid.h"
#include "core/problem.h"
#include "core/step.h"

typedef struct {
    Particles p;
    Grid g;
    Stencils st;
    StepProblem pb;
    Material mats[2];
    double dt;
} Fixture;

typedef struct {
    int per_axis;        /* particles per axis */
    double dx;
    double spacing;      /* particle spacing (default dx/2) */
    double F_noise;      /* F = I + noise * U(-1,1) per entry */
    double v_noise;      /* velocity magnitude */
    double C_noise;
    int two_materials;
    int inverted_fraction_pct; /* percentage of particles with a reflected F */
    double dt;
    double gravity[3];
    unsigned long long seed;
    int mls;             /* 1: MLS-MPM gradients (stencils_use_mls_gradients) and the fused P2G */
    int snap_to_centre;  /* 1: one coordinate of each particle, at random, at its cell's centre: the
                          * far node's weight in that axis is exactly 0 (needs dx a power of 2) */
} FixtureOptions;

void fixture_default(FixtureOptions *o);
int fixture_build(Fixture *f, const FixtureOptions *o);
void fixture_free(Fixture *f);

#endif
