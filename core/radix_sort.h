/* Parallel stable sort of 64-bit keys (the per-step particle sort, issue 21). */
#ifndef MPM_RADIX_SORT_H
#define MPM_RADIX_SORT_H

#include <stddef.h>
#include <stdint.h>

/* perm[k] = the index of the k-th smallest key, ties in index order: the
 * permutation a qsort on (key, index) gives, so the result does not depend
 * on the thread count. LSD radix sort on 8-bit digits (digits on which all
 * keys agree are skipped), each pass a per-thread histogram, an exclusive
 * scan over (digit, thread) and a scatter of each thread's contiguous chunk
 * in order: stable and race-free. MPM_OK or MPM_EINTERNAL (out of memory). */
int radix_sort_u64(size_t n, const uint64_t *key, size_t *perm);

#endif
