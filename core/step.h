/* The two halves of a timestep around the solve (SPEC 2; DESIGN data flow):
 *   step_begin: colliders at t^n, dt from CFL and frame boundaries, particle
 *               sort, sparse grid, P2G, Dirichlet nodes, the step problem;
 *   step_end:   v^{n+1} = v^n + dv, G2P (APIC/RPIC, F update, advection),
 *               plasticity (lagged), sources; particles that crossed a
 *               domain wall are held at its face; non-finite state or a
 *               particle outside a wall-less domain is MPM_ENUMERIC. */
#ifndef MPM_STEP_H
#define MPM_STEP_H

#include "core/grid.h"
#include "core/problem.h"
#include "core/scene.h"

typedef struct {
    const Scene *scene;
    Particles p;          /* working state (a copy of the scene's initial particles) */
    Grid grid;
    Stencils st;
    StepProblem pb;
    double t;             /* simulated time */
    double frame_dt;
    double t_in_frame;    /* time since the start of the current frame */
    int frame;            /* frames completed */
    double dt;            /* current step */
    double *vnew;
    int cap_nodes;
} Simulation;

int sim_init(Simulation *sim, const Scene *scene);
void sim_free(Simulation *sim);

/* dt rule of SPEC 2.1: cfl dx / vmax capped at max_dt, then hitting frame
 * boundaries exactly. vmax counts the colliders by the scene's cfl_rule. A
 * non-finite vmax, or a CFL dt below the scene's min_dt (which used to be
 * raised to the floor silently, breaking the CFL limit), is MPM_ENUMERIC. */
int sim_next_dt(const Simulation *sim, double *dt);

int step_begin(Simulation *sim);
/* dv is the solver's result over the step problem's nodes. */
int step_end(Simulation *sim, const double *dv);

#endif
