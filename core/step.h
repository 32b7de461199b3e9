/* The two halves of a timestep around the solve (SPEC 2; docs/design.md, data flow):
 *   step_begin: colliders at t^n, dt from CFL and frame boundaries, particle
 *               sort, sparse grid (MLS: the stencils' gradients become
 *               the MLS substitute, SPEC 9), P2G (MLS: the fused form),
 *               Dirichlet nodes, the step problem;
 *   step_end:   v^{n+1} = v^n + dv, Coulomb friction at slip colliders,
 *               G2P (APIC/RPIC, MLS or PIC/FLIP, F update, forward-Euler
 *               advection or the backward-Euler position update),
 *               plasticity (lagged), sources; particles that crossed a
 *               domain wall are held at its face; non-finite state or a
 *               particle outside a wall-less domain is MPM_ENUMERIC.
 * The first step_begin also estimates particle volumes from the grid
 * density when the scene asks ("particle_volume": "grid_density"). */
#ifndef MPM_STEP_H
#define MPM_STEP_H

#include "core/simulation.h"

int step_begin(Simulation *sim);
/* dv is the solver's result over the step problem's nodes. */
int step_end(Simulation *sim, const double *dv);

#endif
