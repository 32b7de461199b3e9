/* The runtime state of one simulation of a scene: the working particles,
 * the grid, the step problem and the clock. core/step.h advances it. */
#ifndef MPM_SIMULATION_H
#define MPM_SIMULATION_H

#include "core/dist/comm_ops.h"
#include "core/dist/decomposition.h"
#include "core/dist/dist_grid.h"
#include "core/grid.h"
#include "core/position_update.h"
#include "core/problem.h"
#include "core/scene_description.h"

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
    double dt_next;       /* > 0: the next step_begin takes this dt instead of sim_next_dt's, and
                             clears it (a run replaying a reference run's dt sequence, --dt-from) */
    double *vnew;
    int cap_nodes;
    /* Gast et al. 2015 section 6 options (scene fields, off by default) */
    int has_friction;     /* some slip collider has friction > 0 */
    double *grad;         /* friction: unconstrained gradient at dv* (cap_grad nodes) */
    int cap_grad;
    int volumes_done;     /* "particle_volume": "grid_density" applied (first step) */
    PositionUpdateStats pos_stats; /* last step's backward-Euler position update */
    /* one scene over MPI ranks (core/dist/dist_sim.h; comm NULL: one process) */
    const CommOps *comm;
    Decomposition decomp; /* the blocks each rank owns */
    DistGrid dist;        /* this rank's owned nodes and ghosts */
    double rebalance_above; /* > 0: a new cut when the busiest rank's particles pass this times the mean */
    int recuts;             /* new cuts made so far (dist_rebalance) */
    int uncut;              /* the split was made with no particle (all on rank 0): dist_rebalance cuts
                               after the first emission, whatever rebalance_above */
    double worst_imbalance; /* the largest busiest-over-mean particle count after a step's migration */
} Simulation;

int sim_init(Simulation *sim, const Scene *scene);
void sim_free(Simulation *sim);

/* dt rule of SPEC 2.1: cfl dx / vmax capped at max_dt, then hitting frame
 * boundaries exactly. vmax counts the colliders by the scene's cfl_rule. A
 * non-finite vmax, or a CFL dt below the scene's min_dt (which used to be
 * raised to the floor silently, breaking the CFL limit), is MPM_ENUMERIC. */
int sim_next_dt(const Simulation *sim, double *dt);

#endif
