/* Levels of the baseline geometric multigrid (SPEC 6 last item; HOT
 * reference §5.5, "LBFGS-GMG" / "PN-GMG-PCG"): the step Hessian
 * rediscretised from the particles on a grid of spacing h = 2^l dx.
 *
 * A level copies the fine particles' positions, F^n, volumes and masses,
 * sorts them by its own cells, builds its own sparse grid, P2G of mass, asks
 * the fine problem's Dirichlet function about its own nodes (per-level
 * Dirichlet lists rebuilt at every build; the reference accumulates them
 * across steps, a bug we do not reproduce), and assembles
 *   A_l = diag(m_I) + dt^2 sum_p V_p (F_p^nT grad w^l_Ip)^T A_p (F_p^nT grad w^l_Jp)
 * with the SAME per-particle tangent A_p as the fine level, BC-projected —
 * by the very code that assembles the fine Hessian (core/problem.c). */
#ifndef MPM_MG_GMG_LEVEL_H
#define MPM_MG_GMG_LEVEL_H

#include "core/problem.h"
#include "solvers/mg/embedding.h"

typedef struct {
    Particles parts;
    Grid grid;
    Stencils st;
    StepProblem pb;
} GmgLevel;

/* Builds the level at spacing h from the fine problem (whose tangent must be
 * current: problem_tangent was called) and assembles its BC-projected
 * Hessian into A. */
int gmg_level_build(GmgLevel *L, const StepProblem *fine, double h, Bsr *A);
void gmg_level_free(GmgLevel *L);

/* Linear-embedding transfer (mg/transfer.h conventions) from nodes with
 * coordinates fine_coord (sorted by node_order_key) onto the existing nodes
 * of grid `coarse`; embedding targets the coarse grid lacks are dropped. */
int gmg_transfer_onto(MgTransfer *T, const int *fine_coord, int n_fine, const Grid *coarse);

#endif
