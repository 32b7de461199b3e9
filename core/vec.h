/* Vector kernels over node-major 3-vectors (length 3n). OpenMP-parallel;
 * dot products sum fixed chunks in order (core/reduce.h), so results are
 * identical for every thread count. Zero lengths accept NULL pointers. */
#ifndef MPM_VEC_H
#define MPM_VEC_H

#include <stddef.h>

#include "core/dist/comm_ops.h"

double vec_dot(size_t len, const double *a, const double *b);
double vec_norm(size_t len, const double *a);

/* A distributed run (docs/distributed.md): from this call on, vec_dot and
 * vec_norm sum over comm's ranks, so every solver's reductions are the
 * whole scene's. Sound because every problem-sized vector of such a run
 * holds its rank's owned nodes and zeros at its ghosts (core/problem.h);
 * solvers whose vectors are not problem-sized (a multigrid's coarse
 * levels) have no distributed form yet and are refused before they run.
 * NULL (the default): this process only. A failed sum gives NaN, which the
 * solvers report as a breakdown. */
void vec_sum_over_ranks(const CommOps *comm);
/* y += alpha x */
void vec_axpy(size_t len, double alpha, const double *x, double *y);
/* y = x + beta y */
void vec_xpby(size_t len, const double *x, double beta, double *y);
void vec_copy(size_t len, const double *x, double *y);
void vec_zero(size_t len, double *x);
void vec_scale(size_t len, double alpha, double *x);
/* z_i = D_i r_i for 3x3 blocks D (9 per node), n nodes */
void vec_block_apply(size_t n_nodes, const double *D, const double *r, double *z);

#endif
