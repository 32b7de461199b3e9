/* Vector kernels over node-major 3-vectors (length 3n). OpenMP-parallel;
 * dot products sum fixed chunks in order (core/reduce.h), so results are
 * identical for every thread count. Zero lengths accept NULL pointers. */
#ifndef MPM_VEC_H
#define MPM_VEC_H

#include <stddef.h>

double vec_dot(size_t len, const double *a, const double *b);
double vec_norm(size_t len, const double *a);
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
