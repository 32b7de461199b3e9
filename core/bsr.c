#include "core/bsr.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

int bsr_reserve(Bsr *A, int n, int64_t nnzb)
{
    if (n + 1 > A->cap_rows) {
        int64_t *rp = realloc(A->row_ptr, sizeof(int64_t) * (size_t)(n + 1));
        if (!rp) return mpm_error(MPM_EINTERNAL, "out of memory: block-CSR rows (%d)", n);
        A->row_ptr = rp;
        A->cap_rows = n + 1;
    }
    if (nnzb > A->cap_nnzb) {
        int64_t cap = nnzb + nnzb / 8 + 64; /* headroom so slow grid growth rarely reallocates */
        int *c = realloc(A->col, sizeof(int) * (size_t)cap);
        if (!c) return mpm_error(MPM_EINTERNAL, "out of memory: block-CSR columns (%lld)", (long long)cap);
        A->col = c;
        double *v = realloc(A->val, sizeof(double) * 9 * (size_t)cap);
        if (!v) return mpm_error(MPM_EINTERNAL, "out of memory: block-CSR values (%lld)", (long long)cap);
        A->val = v;
        A->cap_nnzb = cap;
    }
    A->n = n;
    return MPM_OK;
}

void bsr_update_pattern_id(Bsr *A)
{
    /* FNV-1a over the structure; equal patterns give equal ids. */
    uint64_t h = 1469598103934665603ull;
#define MIX(x)                       \
    do {                             \
        h ^= (uint64_t)(x);          \
        h *= 1099511628211ull;       \
    } while (0)
    MIX(A->n);
    for (int i = 0; i <= A->n; ++i) MIX(A->row_ptr[i]);
    for (int64_t k = 0; k < A->nnzb; ++k) MIX(A->col[k]);
#undef MIX
    A->pattern_id = h;
}

/* (A x)_i for block row i, on the doubles of A->val and on a single-precision
 * copy of them (core/bsr_row_product.inc, one body for both). */
#define BSR_VAL double
#define BSR_ROW_PRODUCT row_product_vals
#include "core/bsr_row_product.inc"
#undef BSR_VAL
#undef BSR_ROW_PRODUCT
#define BSR_VAL float
#define BSR_ROW_PRODUCT row_product_single
#include "core/bsr_row_product.inc"
#undef BSR_VAL
#undef BSR_ROW_PRODUCT

static inline void row_product(const Bsr *A, int i, const double *restrict x, double out[3])
{
    row_product_vals(A, A->val, i, x, out);
}

void bsr_spmv(const Bsr *A, const double *restrict x, double *restrict y)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < A->n; ++i) row_product(A, i, x, y + 3 * (size_t)i);
}

void bsr_spmv_sub(const Bsr *A, const double *restrict x, double *restrict r)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < A->n; ++i) {
        double s[3];
        row_product(A, i, x, s);
        r[3 * (size_t)i] -= s[0];
        r[3 * (size_t)i + 1] -= s[1];
        r[3 * (size_t)i + 2] -= s[2];
    }
}

void bsr_spmv_sub_single(const Bsr *A, const float *val, const double *restrict x, double *restrict r)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < A->n; ++i) {
        double s[3];
        row_product_single(A, val, i, x, s);
        r[3 * (size_t)i] -= s[0];
        r[3 * (size_t)i + 1] -= s[1];
        r[3 * (size_t)i + 2] -= s[2];
    }
}

int bsr_values_single(const Bsr *A, float **val, int64_t *cap)
{
    if (A->nnzb > *cap) {
        float *v = realloc(*val, sizeof(float) * 9 * (size_t)A->nnzb);
        if (!v) return mpm_error(MPM_EINTERNAL, "out of memory: single-precision block values (%lld)", (long long)A->nnzb);
        *val = v;
        *cap = A->nnzb;
    }
    float *restrict out = *val;
    const size_t len = 9 * (size_t)A->nnzb;
#pragma omp parallel for schedule(static)
    for (size_t e = 0; e < len; ++e) out[e] = (float)A->val[e];
    return MPM_OK;
}

int64_t bsr_find(const Bsr *A, int row, int col)
{
    int64_t lo = A->row_ptr[row], hi = A->row_ptr[row + 1] - 1;
    while (lo <= hi) {
        int64_t mid = lo + (hi - lo) / 2;
        int c = A->col[mid];
        if (c == col) return mid;
        if (c < col) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

void bsr_diagonal(const Bsr *A, double *diag)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < A->n; ++i) {
        int64_t k = bsr_find(A, i, i);
        if (k >= 0) memcpy(diag + 9 * (size_t)i, A->val + 9 * k, 9 * sizeof(double));
        else memset(diag + 9 * (size_t)i, 0, 9 * sizeof(double));
    }
}

size_t bsr_bytes(const Bsr *A)
{
    return sizeof(int64_t) * (size_t)(A->n + 1) + (sizeof(int) + 9 * sizeof(double)) * (size_t)A->nnzb;
}

int bsr_copy(Bsr *dst, const Bsr *src)
{
    int st = bsr_reserve(dst, src->n, src->nnzb);
    if (st) return st;
    dst->nnzb = src->nnzb;
    memcpy(dst->row_ptr, src->row_ptr, sizeof(int64_t) * (size_t)(src->n + 1));
    memcpy(dst->col, src->col, sizeof(int) * (size_t)src->nnzb);
    memcpy(dst->val, src->val, sizeof(double) * 9 * (size_t)src->nnzb);
    dst->pattern_id = src->pattern_id;
    return MPM_OK;
}

void bsr_free(Bsr *A)
{
    free(A->row_ptr);
    free(A->col);
    free(A->val);
    memset(A, 0, sizeof *A);
}
