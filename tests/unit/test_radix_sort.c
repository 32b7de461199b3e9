/* floor: core */
/* The parallel particle sort (core/radix_sort.c, issue 21) gives exactly the
 * permutation of a qsort on (key, index), at 1 and at 2 threads: random
 * 64-bit keys, keys with many duplicates (a few distinct values, and
 * particles sharing cells), node_order_key of random base nodes with
 * negative coordinates, already sorted, reversed and all-equal input, and
 * the sizes 0, 1, 2, 3 and one not divisible by the thread count. */
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/node_order.h"
#include "core/radix_sort.h"
#include "tests/common/testutil.h"

typedef struct {
    uint64_t key;
    size_t idx;
} Item;

static int cmp_item(const void *a, const void *b)
{
    const Item *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->idx > y->idx) - (x->idx < y->idx);
}

static uint64_t next64(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    uint64_t z = *s;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

enum { RANDOM, FEW, CELLS, SORTED, REVERSED, EQUAL, N_KINDS };
static const char *const kind_name[N_KINDS] = {"random", "few distinct", "node keys", "sorted", "reversed", "equal"};

static void fill(int kind, size_t n, uint64_t *key, unsigned long long seed)
{
    for (size_t k = 0; k < n; ++k) {
        switch (kind) {
        case RANDOM: key[k] = next64(&seed); break;
        case FEW: key[k] = next64(&seed) % 5 * 0x0100010001000100ull; break; /* 5 values, bits in 4 digits */
        case CELLS: { /* base nodes in a 40^3 box around the origin: duplicates and negative coordinates */
            int c[3];
            for (int d = 0; d < 3; ++d) c[d] = (int)(next64(&seed) % 40) - 20;
            key[k] = node_order_key(c);
            break;
        }
        case SORTED: key[k] = 3 * (uint64_t)k / 2; break;
        case REVERSED: key[k] = ~(uint64_t)k; break;
        default: key[k] = 0xdeadbeefull;
        }
    }
}

int main(void)
{
    static const size_t sizes[] = {0, 1, 2, 3, 1000, 100003};
    int cases = 0;
    for (int kind = 0; kind < N_KINDS; ++kind)
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
            const size_t n = sizes[s];
            uint64_t *key = malloc(sizeof(uint64_t) * (n + 1));
            size_t *perm = malloc(sizeof(size_t) * (n + 1));
            Item *ref = malloc(sizeof(Item) * (n + 1));
            fill(kind, n, key, 1234 + n);
            for (size_t k = 0; k < n; ++k) ref[k] = (Item){key[k], k};
            qsort(ref, n, sizeof(Item), cmp_item);
            for (int threads = 1; threads <= 2; ++threads) {
                omp_set_num_threads(threads);
                memset(perm, 0xff, sizeof(size_t) * (n + 1));
                int st = radix_sort_u64(n, key, perm);
                CHECK(st == MPM_OK, "%s n=%zu: %s", kind_name[kind], n, mpm_last_error());
                size_t bad = n;
                for (size_t k = 0; k < n && bad == n; ++k)
                    if (perm[k] != ref[k].idx) bad = k;
                CHECK(bad == n, "%s n=%zu at %d threads: position %zu holds index %zu, qsort's %zu", kind_name[kind], n,
                      threads, bad, bad < n ? perm[bad] : 0, bad < n ? ref[bad].idx : 0);
                ++cases;
            }
            free(key), free(perm), free(ref);
        }
    printf("%d cases equal to qsort on (key, index)\n", cases);
    return test_summary("test_radix_sort");
}
