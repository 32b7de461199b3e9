/* Node-embedding transfers (HOT paper §4.1; reference §5.1; SPEC 6). The
 * coarse node set is found with an open-addressing hash on node_order_key
 * (which is injective on the coordinate range the grid uses), then sorted by
 * that key, so coarse ids do not depend on hash order or thread count. */
#include "solvers/mg/embedding.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/node_order.h"

#define EMPTY_KEY UINT64_MAX

int mg_embed_1d(MgEmbedding kind, int x, int X[3], double w[3])
{
    int X0 = floor_div_pow2(x, 1);
    int odd = x - 2 * X0; /* 0 or 1, also for negative x */
    if (odd) {
        X[0] = X0;
        X[1] = X0 + 1;
        w[0] = w[1] = 0.5;
        return 2;
    }
    if (kind == MG_EMBED_LINEAR) {
        X[0] = X0;
        w[0] = 1.0;
        return 1;
    }
    X[0] = X0 - 1;
    X[1] = X0;
    X[2] = X0 + 1;
    w[0] = 0.125;
    w[1] = 0.75;
    w[2] = 0.125;
    return 3;
}

static inline uint64_t hash_u64(uint64_t z)
{
    z ^= z >> 33;
    z *= 0xff51afd7ed558ccdull;
    z ^= z >> 33;
    z *= 0xc4ceb9fe1a85ec53ull;
    z ^= z >> 33;
    return z;
}

static int hash_alloc(MgTransfer *T, int64_t cap)
{
    uint64_t *k = malloc(sizeof(uint64_t) * (size_t)cap);
    int *v = malloc(sizeof(int) * (size_t)cap);
    if (!k || !v) {
        free(k);
        free(v);
        return mpm_error(MPM_EINTERNAL, "out of memory: multigrid coarse-node hash (%lld slots)", (long long)cap);
    }
    for (int64_t s = 0; s < cap; ++s) k[s] = EMPTY_KEY;
    free(T->h_key);
    free(T->h_val);
    T->h_key = k;
    T->h_val = v;
    T->h_cap = cap;
    return MPM_OK;
}

/* Returns the value stored for key, inserting `fresh` if absent. */
static inline int hash_get_or_insert(uint64_t *keys, int *vals, int64_t mask, uint64_t key, int fresh, int *inserted)
{
    int64_t s = (int64_t)(hash_u64(key) & (uint64_t)mask);
    for (;;) {
        if (keys[s] == key) {
            *inserted = 0;
            return vals[s];
        }
        if (keys[s] == EMPTY_KEY) {
            keys[s] = key;
            vals[s] = fresh;
            *inserted = 1;
            return fresh;
        }
        s = (s + 1) & mask;
    }
}

static int grow_int(int **p, size_t n)
{
    int *q = realloc(*p, sizeof(int) * (n ? n : 1));
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid transfer (%zu)", n);
    *p = q;
    return MPM_OK;
}
static int grow_i64(int64_t **p, size_t n)
{
    int64_t *q = realloc(*p, sizeof(int64_t) * (n ? n : 1));
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid transfer (%zu)", n);
    *p = q;
    return MPM_OK;
}
static int grow_dbl(double **p, size_t n)
{
    double *q = realloc(*p, sizeof(double) * (n ? n : 1));
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid transfer (%zu)", n);
    *p = q;
    return MPM_OK;
}

int mg_transfer_build(MgTransfer *T, MgEmbedding kind, const int *fine_coord, int n_fine)
{
    int st;
    if (n_fine + 1 > T->cap_fine) {
        if ((st = grow_i64(&T->p_ptr, (size_t)n_fine + 1))) return st;
        T->cap_fine = n_fine + 1;
    }
    T->n_fine = n_fine;
    /* 1. row counts from the coordinate parities */
    T->p_ptr[0] = 0;
    for (int i = 0; i < n_fine; ++i) {
        int c = 1;
        for (int d = 0; d < 3; ++d) {
            int odd = fine_coord[3 * (size_t)i + d] & 1;
            c *= odd ? 2 : (kind == MG_EMBED_LINEAR ? 1 : 3);
        }
        T->p_ptr[i + 1] = T->p_ptr[i] + c;
    }
    int64_t ne = T->p_ptr[n_fine];
    if (ne > T->cap_entries) {
        if ((st = grow_int(&T->p_col, (size_t)ne)) || (st = grow_dbl(&T->p_w, (size_t)ne)) ||
            (st = grow_int(&T->r_col, (size_t)ne)) || (st = grow_dbl(&T->r_w, (size_t)ne)))
            return st;
        T->cap_entries = ne;
    }
    /* 2. coarse nodes in first-encounter order (serial, deterministic);
     *    p_col temporarily holds first-encounter indices */
    int64_t want = 64;
    while (want < 2 * (int64_t)n_fine) want <<= 1;
    if (T->h_cap < want) {
        if ((st = hash_alloc(T, want))) return st;
    } else {
        for (int64_t s = 0; s < T->h_cap; ++s) T->h_key[s] = EMPTY_KEY;
    }
    int m = 0, cap_tmp = n_fine / 2 + 64;
    int *tmp_coord = malloc(sizeof(int) * 3 * (size_t)cap_tmp);
    if (!tmp_coord) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid coarse nodes");
    for (int i = 0; i < n_fine; ++i) {
        const int *c = fine_coord + 3 * (size_t)i;
        int X[3][3], cnt[3];
        double w[3][3];
        for (int d = 0; d < 3; ++d) cnt[d] = mg_embed_1d(kind, c[d], X[d], w[d]);
        int64_t e = T->p_ptr[i];
        for (int a = 0; a < cnt[0]; ++a)
            for (int b = 0; b < cnt[1]; ++b)
                for (int g = 0; g < cnt[2]; ++g, ++e) {
                    int C[3] = {X[0][a], X[1][b], X[2][g]};
                    if (2 * (int64_t)(m + 1) > T->h_cap) { /* keep load <= 1/2: rehash */
                        uint64_t *ok = T->h_key;
                        int *ov = T->h_val;
                        int64_t ocap = T->h_cap;
                        T->h_key = NULL;
                        T->h_val = NULL;
                        if ((st = hash_alloc(T, 2 * ocap))) {
                            free(ok);
                            free(ov);
                            free(tmp_coord);
                            return st;
                        }
                        int dummy;
                        for (int64_t s = 0; s < ocap; ++s)
                            if (ok[s] != EMPTY_KEY)
                                hash_get_or_insert(T->h_key, T->h_val, T->h_cap - 1, ok[s], ov[s], &dummy);
                        free(ok);
                        free(ov);
                    }
                    int ins;
                    int id = hash_get_or_insert(T->h_key, T->h_val, T->h_cap - 1, node_order_key(C), m, &ins);
                    if (ins) {
                        if (m == cap_tmp) {
                            cap_tmp *= 2;
                            int *nt = realloc(tmp_coord, sizeof(int) * 3 * (size_t)cap_tmp);
                            if (!nt) {
                                free(tmp_coord);
                                return mpm_error(MPM_EINTERNAL, "out of memory: multigrid coarse nodes");
                            }
                            tmp_coord = nt;
                        }
                        memcpy(tmp_coord + 3 * (size_t)m, C, sizeof C);
                        ++m;
                    }
                    T->p_col[e] = id;
                    T->p_w[e] = w[0][a] * w[1][b] * w[2][g];
                }
    }
    /* 3. sort coarse nodes by node_order_key; rank_of[first-encounter] */
    int *perm = malloc(sizeof(int) * (size_t)(m > 0 ? m : 1));
    int *rank_of = malloc(sizeof(int) * (size_t)(m > 0 ? m : 1));
    if (!perm || !rank_of) {
        free(perm);
        free(rank_of);
        free(tmp_coord);
        return mpm_error(MPM_EINTERNAL, "out of memory: multigrid coarse nodes");
    }
    st = node_order_sort(tmp_coord, m, perm);
    if (!st && m + 1 > T->cap_coarse) {
        if (!(st = grow_int(&T->coarse_coord, 3 * (size_t)(m + 1))) && !(st = grow_i64(&T->r_ptr, (size_t)m + 1)))
            T->cap_coarse = m + 1;
    }
    if (st) {
        free(perm);
        free(rank_of);
        free(tmp_coord);
        return st;
    }
    T->n_coarse = m;
    for (int k = 0; k < m; ++k) {
        rank_of[perm[k]] = k;
        memcpy(T->coarse_coord + 3 * (size_t)k, tmp_coord + 3 * (size_t)perm[k], 3 * sizeof(int));
    }
    free(perm);
    free(tmp_coord);
    /* 4. P columns -> sorted ranks, rows sorted by column (<= 27 entries) */
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n_fine; ++i) {
        int64_t lo = T->p_ptr[i], hi = T->p_ptr[i + 1];
        for (int64_t e = lo; e < hi; ++e) T->p_col[e] = rank_of[T->p_col[e]];
        for (int64_t e = lo + 1; e < hi; ++e) {
            int c = T->p_col[e];
            double w = T->p_w[e];
            int64_t f = e;
            for (; f > lo && T->p_col[f - 1] > c; --f) {
                T->p_col[f] = T->p_col[f - 1];
                T->p_w[f] = T->p_w[f - 1];
            }
            T->p_col[f] = c;
            T->p_w[f] = w;
        }
    }
    free(rank_of);
    /* 5. R = P^T by counting sort (rows come out sorted by fine node) */
    memset(T->r_ptr, 0, sizeof(int64_t) * ((size_t)m + 1));
    for (int64_t e = 0; e < ne; ++e) T->r_ptr[T->p_col[e] + 1]++;
    for (int k = 0; k < m; ++k) T->r_ptr[k + 1] += T->r_ptr[k];
    int64_t *fill = malloc(sizeof(int64_t) * (size_t)(m > 0 ? m : 1));
    if (!fill) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid restriction");
    memcpy(fill, T->r_ptr, sizeof(int64_t) * (size_t)m);
    for (int i = 0; i < n_fine; ++i)
        for (int64_t e = T->p_ptr[i]; e < T->p_ptr[i + 1]; ++e) {
            int64_t f = fill[T->p_col[e]]++;
            T->r_col[f] = i;
            T->r_w[f] = T->p_w[e];
        }
    free(fill);
    return MPM_OK;
}

void mg_transfer_free(MgTransfer *T)
{
    free(T->p_ptr);
    free(T->p_col);
    free(T->p_w);
    free(T->r_ptr);
    free(T->r_col);
    free(T->r_w);
    free(T->coarse_coord);
    free(T->h_key);
    free(T->h_val);
    memset(T, 0, sizeof *T);
}

void mg_prolong(const MgTransfer *T, const double *restrict uc, double *restrict uf)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < T->n_fine; ++i) {
        double s0 = 0.0, s1 = 0.0, s2 = 0.0;
        for (int64_t e = T->p_ptr[i]; e < T->p_ptr[i + 1]; ++e) {
            const double *u = uc + 3 * (size_t)T->p_col[e];
            double w = T->p_w[e];
            s0 += w * u[0];
            s1 += w * u[1];
            s2 += w * u[2];
        }
        uf[3 * (size_t)i] = s0;
        uf[3 * (size_t)i + 1] = s1;
        uf[3 * (size_t)i + 2] = s2;
    }
}

void mg_restrict(const MgTransfer *T, const double *restrict rf, double *restrict rc)
{
#pragma omp parallel for schedule(static)
    for (int k = 0; k < T->n_coarse; ++k) {
        double s0 = 0.0, s1 = 0.0, s2 = 0.0;
        for (int64_t e = T->r_ptr[k]; e < T->r_ptr[k + 1]; ++e) {
            const double *r = rf + 3 * (size_t)T->r_col[e];
            double w = T->r_w[e];
            s0 += w * r[0];
            s1 += w * r[1];
            s2 += w * r[2];
        }
        rc[3 * (size_t)k] = s0;
        rc[3 * (size_t)k + 1] = s1;
        rc[3 * (size_t)k + 2] = s2;
    }
}
