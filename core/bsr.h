/* 3x3-block compressed sparse row matrix (SPEC 3 storage).
 *
 * Square, full symmetric storage (both triangles), column indices sorted
 * within each row, each block row-major. Only blocks that exist are stored:
 * no padded 125-slot rows. pattern_id changes whenever the sparsity pattern
 * changes, so factorisations and AMG know when to redo symbolic setup. */
#ifndef MPM_BSR_H
#define MPM_BSR_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    int n;             /* block rows (= block columns) */
    int64_t nnzb;      /* stored blocks */
    int64_t *row_ptr;  /* n + 1 */
    int *col;          /* nnzb, sorted within each row */
    double *val;       /* 9 * nnzb */
    uint64_t pattern_id;
    /* capacities: storage is reused across steps and only grows */
    int cap_rows;
    int64_t cap_nnzb;
} Bsr;

/* Ensures room for n rows and nnzb blocks; sets n (not nnzb). */
int bsr_reserve(Bsr *A, int n, int64_t nnzb);
/* Recomputes pattern_id as a hash of (n, row_ptr, col). */
void bsr_update_pattern_id(Bsr *A);
/* y = A x (row-parallel, OpenMP). */
void bsr_spmv(const Bsr *A, const double *x, double *y);
/* r -= A x (row-parallel). */
void bsr_spmv_sub(const Bsr *A, const double *x, double *r);
/* Single-precision copy of A's values (9 nnzb floats, *val grown to fit,
 * *cap its blocks): a bandwidth-halving operand for smoothers (SPEC 6.10). */
int bsr_values_single(const Bsr *A, float **val, int64_t *cap);
/* r -= A_s x with A_s the single-precision values `val` on A's pattern
 * (products and sums in double). */
void bsr_spmv_sub_single(const Bsr *A, const float *val, const double *x, double *r);
/* Index of block (row, col) or -1 (binary search in the sorted row). */
int64_t bsr_find(const Bsr *A, int row, int col);
/* Copies the diagonal blocks into diag (9n). Missing diagonal -> zero block. */
void bsr_diagonal(const Bsr *A, double *diag);
/* Bytes held by the matrix arrays as sized (not capacity). */
size_t bsr_bytes(const Bsr *A);
/* Deep copy (dst storage reused). */
int bsr_copy(Bsr *dst, const Bsr *src);
void bsr_free(Bsr *A);

#endif
