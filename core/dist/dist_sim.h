/* A simulation split over MPI ranks (docs/distributed.md): each rank keeps
 * the particles of the blocks it owns and runs the step on its own grid
 * (owned nodes and ghosts), communicating through the table of
 * core/dist/comm_ops.h. With a distributed simulation, step_begin builds
 * the rank's grid with its halo (dist_grid.h), sums P2G's mass and
 * momentum into the owners, gives the ghosts their owners' velocities and
 * no mass, and hands the step problem the table and the owned nodes
 * (core/problem.h), so its energy, gradient, H x, diagonal and CN residual
 * are the whole scene's. */
#ifndef MPM_DIST_SIM_H
#define MPM_DIST_SIM_H

#include "core/dist/comm_ops.h"
#include "core/simulation.h"

/* Splits sim (initialised by sim_init on every rank from the same scene)
 * over comm's ranks: the decomposition of its particles, then only this
 * rank's particles kept. Collective. MPM_EINPUT for more ranks than
 * blocks. A scene with no particle before its
 * sources emit starts with every block on rank 0 (sim->uncut). */
int sim_distribute(Simulation *sim, const CommOps *comm);

/* After P2G on a rank's grid: mass and momentum summed into the owners,
 * the owners' velocities, copied to the ghosts, and the ghosts' mass set
 * to 0 (their inertia is the owner's). Collective. */
int dist_p2g_halo(Simulation *sim);

/* After G2P: every particle whose base node's block belongs to another
 * rank moves there (exchange); the staying ones keep their order, the
 * arrivals follow rank after rank. *sent (when not NULL) gets how many
 * left this rank. Collective. */
int dist_migrate(Simulation *sim, size_t *sent);
/* After dist_migrate: the imbalance, the busiest rank's particles over the
 * mean, into sim->worst_imbalance; past sim->rebalance_above (> 0) the
 * curve is cut again by the ranks' particle blocks (decomposition_cut, the
 * same cut on every rank) and the particles migrate to their new owners
 * (sim->recuts counts the cuts that changed; a cut equal to the old one,
 * which block granularity can give, or fewer particle blocks than ranks
 * leaves the old one). Collective. */
int dist_rebalance(Simulation *sim);

/* After every rank's sources emitted the same particles (indices n_before
 * onward; emission is a function of the time and the sources only): their
 * identities as one process numbers them (from total_before, the whole
 * scene's count before the emission) and only those this rank owns kept,
 * in emission order. */
int dist_keep_emitted(Simulation *sim, size_t n_before, double total_before);

/* Backward-Euler positions (position_update.h) after G2P over ranks, on
 * this rank's grid grown by the nodes one node around it that other ranks
 * have, with their v^{n+1} (core/dist/dist_position.c); sim->pos_stats
 * gets this rank's counts. Collective. */
int dist_backward_euler(Simulation *sim);

/* The default of rebalance_above: a rank 20 % over the mean slows every
 * step by as much, while a cut costs an exchange of the block counts and
 * one migration. */
#define DIST_REBALANCE_ABOVE_DEFAULT 1.2

#endif
