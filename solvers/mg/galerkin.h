/* Galerkin coarse operator A_c = R A P = P^T A P (HOT paper §4.1 eq. 6-8;
 * reference §5.1; SPEC 6), sparse and without padded slots.
 *
 * Row I of A_c is (row I of R A) P: first the fine-indexed row
 * sum_{i in R(I)} w_iI A_i is accumulated with a dense marker over fine
 * nodes, then multiplied by P with a dense marker over coarse nodes. Each
 * coarse row is computed once, in parallel over rows, with no atomics. Only
 * the upper triangle (J >= I) is computed; the lower one is its exact
 * transpose, so A_c is bitwise symmetric (A_c[J][I] == A_c[I][J]^T). Cost per
 * coarse row ~ |R(I)| |A row| + |RA row| |P row| block updates. */
#ifndef MPM_MG_GALERKIN_H
#define MPM_MG_GALERKIN_H

#include "core/bsr.h"
#include "solvers/mg/embedding.h"

/* Per-thread accumulators and output buffers, kept between calls so that
 * steady-state setups allocate nothing. */
typedef struct MgGalerkinWork MgGalerkinWork;

/* Ac = P^T A P; A is T->n_fine square, symmetric. Storage of Ac is reused;
 * its pattern_id is updated. *work is created on first use and reused (free
 * it with mg_galerkin_work_free); work == NULL uses a temporary one. */
int mg_galerkin(const Bsr *A, const MgTransfer *T, Bsr *Ac, MgGalerkinWork **work);
void mg_galerkin_work_free(MgGalerkinWork *w);

#endif
