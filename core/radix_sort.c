#include "core/radix_sort.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#define RADIX_BITS 8
#define RADIX (1 << RADIX_BITS)

int radix_sort_u64(size_t n, const uint64_t *key, size_t *perm)
{
    if (n == 0) return MPM_OK;
    const int T = omp_get_max_threads();
    uint64_t *k0 = malloc(sizeof(uint64_t) * n), *k1 = malloc(sizeof(uint64_t) * n);
    size_t *i1 = malloc(sizeof(size_t) * n), *hist = malloc(sizeof(size_t) * RADIX * (size_t)T);
    if (!k0 || !k1 || !i1 || !hist) {
        free(k0), free(k1), free(i1), free(hist);
        return mpm_error(MPM_EINTERNAL, "out of memory sorting %zu keys", n);
    }
    uint64_t vary = 0; /* the bits on which some key differs from the first */
#pragma omp parallel for schedule(static) reduction(| : vary)
    for (size_t k = 0; k < n; ++k) {
        k0[k] = key[k];
        perm[k] = k;
        vary |= key[k] ^ key[0];
    }
    uint64_t *ks = k0, *kd = k1;
    size_t *is = perm, *id = i1;
    for (int shift = 0; shift < 64; shift += RADIX_BITS) {
        if (!((vary >> shift) & (RADIX - 1))) continue; /* every key has the same digit: the pass is the identity */
#pragma omp parallel num_threads(T)
        {
            const int nt = omp_get_num_threads(), t = omp_get_thread_num();
            const size_t lo = n * (size_t)t / (size_t)nt, hi = n * (size_t)(t + 1) / (size_t)nt;
            size_t *h = hist + (size_t)RADIX * (size_t)t;
            memset(h, 0, sizeof(size_t) * RADIX);
            for (size_t k = lo; k < hi; ++k) ++h[(ks[k] >> shift) & (RADIX - 1)];
#pragma omp barrier
#pragma omp single
            { /* exclusive scan, digit-major then thread: thread t's keys of a digit follow thread t-1's */
                size_t sum = 0;
                for (int b = 0; b < RADIX; ++b)
                    for (int u = 0; u < nt; ++u) {
                        size_t c = hist[(size_t)RADIX * (size_t)u + (size_t)b];
                        hist[(size_t)RADIX * (size_t)u + (size_t)b] = sum;
                        sum += c;
                    }
            } /* implicit barrier */
            for (size_t k = lo; k < hi; ++k) {
                size_t o = h[(ks[k] >> shift) & (RADIX - 1)]++;
                kd[o] = ks[k];
                id[o] = is[k];
            }
        }
        uint64_t *tk = ks;
        ks = kd, kd = tk;
        size_t *ti = is;
        is = id, id = ti;
    }
    if (is != perm) memcpy(perm, is, sizeof(size_t) * n);
    free(k0), free(k1), free(i1), free(hist);
    return MPM_OK;
}
