/* Particle position update by backward Euler in the grid velocity field
 * (Gast et al. 2015 section 6.3):
 *
 *     x_p^{n+1} = x_p^n + dt v(x_p^{n+1}),   v(x) = sum_i v_i^{n+1} N_i(x),
 *
 * solved per particle by Newton's method on r(x) = x - x_p^n - dt v(x),
 * Jacobian I - dt grad v(x), with step halving: the full Newton step is
 * halved until ||r|| no longer increases, at most 14 times, after which the
 * reduced step is taken anyway (the paper's rule). Inside a sticky collider
 * the grid velocity is the collider's (0 for a resting one), so a particle
 * that would end inside must already have been there: unlike forward Euler,
 * the update cannot carry particles into a resting sticky collider.
 *
 * v(x) uses PIC (the interpolated grid velocity), whatever the particles
 * store (Gast 6.3: FLIP/PIC is kept on the particles, PIC moves them).
 *
 * Our grid is sparse: only nodes in the stencil of some particle at x^n
 * exist (the paper's dense grid holds v = 0 at its massless nodes). A Newton
 * iterate may reach nodes that do not exist; their velocity is unknown
 * rather than zero, so v(x) is the B-spline interpolation renormalised over
 * the existing nodes, v(x) = sum_a w_a(x) v_a / sum_a w_a(x). Where the whole
 * stencil exists (sum w = 1, partition of unity) this is the paper's field
 * exactly; at a free surface it avoids slowing the leading particles down
 * toward the zero velocity of empty space. */
#ifndef MPM_POSITION_UPDATE_H
#define MPM_POSITION_UPDATE_H

#include <stddef.h>

#include "core/grid.h"
#include "core/particles.h"

typedef enum {
    POSITION_FORWARD_EULER = 0, /* x += dt v_PIC(x^n) inside G2P (default) */
    POSITION_BACKWARD_EULER = 1 /* this file */
} PositionUpdateKind;

#define POSITION_MAX_HALVINGS 14  /* Gast 6.3 */
#define POSITION_MAX_NEWTON 20
#define POSITION_TOL_DX 1e-10     /* stop when ||r|| <= 1e-10 dx */

typedef struct {
    long newton_iters;    /* total over particles */
    int max_newton_iters; /* largest per particle */
    long halvings;        /* total step halvings */
    size_t unconverged;   /* particles stopped by POSITION_MAX_NEWTON with ||r|| > tol */
} PositionUpdateStats;

/* Grid velocity field at an arbitrary point x: v(x) and its spatial
 * gradient G = dv/dx (row-major, G[3a+b] = dv_a/dx_b), with the quadratic
 * B-spline of SPEC 1 renormalised over the active nodes (see above).
 * Returns the weight sum W of the active nodes in x's stencil (1 where all
 * of them exist); W = 0 means no active node: v = 0, G = 0. `hint_base` and
 * `hint_node` (nullable) are a known stencil (a particle's base node and its
 * 27 node ids): when x has the same base node they replace the hash lookups. */
double grid_velocity_at(const Grid *g, const double *vnew, const double x[3], const int *hint_base,
                        const int *hint_node, double v[3], double G[9]);

/* Moves every particle by backward Euler in vnew (3 per active node of g,
 * the grid v^{n+1}); g and st are the grid and stencils of the step (particle
 * positions x^n). In parallel over particles (each independent). `stats`
 * nullable. */
void position_update_backward_euler(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                                    PositionUpdateStats *stats);

#endif
