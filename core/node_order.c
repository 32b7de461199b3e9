#include "core/node_order.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* 18 bits per block coordinate (offset so negatives sort correctly) and 2 bits
 * per in-block coordinate: 60 bits in all. */
#define BLOCK_BITS 18
#define BLOCK_OFFSET (1 << (BLOCK_BITS - 1))

uint64_t node_order_key(const int c[3])
{
    uint64_t key = 0;
    for (int d = 0; d < 3; ++d) {
        uint64_t b = (uint64_t)(floor_div_pow2(c[d], MPM_BLOCK_SHIFT) + BLOCK_OFFSET) & ((1u << BLOCK_BITS) - 1);
        key = (key << BLOCK_BITS) | b;
    }
    for (int d = 0; d < 3; ++d) key = (key << MPM_BLOCK_SHIFT) | (uint64_t)(c[d] & ((1 << MPM_BLOCK_SHIFT) - 1));
    return key;
}

typedef struct {
    uint64_t key;
    int idx;
} KeyIdx;

static int cmp_keyidx(const void *a, const void *b)
{
    const KeyIdx *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->idx > y->idx) - (x->idx < y->idx);
}

int node_order_sort(const int *coord, int n, int *perm)
{
    KeyIdx *ki = malloc(sizeof(KeyIdx) * (size_t)(n > 0 ? n : 1));
    if (!ki) return mpm_error(MPM_EINTERNAL, "out of memory sorting %d nodes", n);
    for (int i = 0; i < n; ++i) {
        ki[i].key = node_order_key(coord + 3 * (size_t)i);
        ki[i].idx = i;
    }
    qsort(ki, (size_t)n, sizeof(KeyIdx), cmp_keyidx);
    for (int i = 0; i < n; ++i) perm[i] = ki[i].idx;
    free(ki);
    return MPM_OK;
}

static int block_color(const int c[3])
{
    int col = 0;
    for (int d = 0; d < 3; ++d) col |= (floor_div_pow2(c[d], MPM_BLOCK_SHIFT) & 1) << d;
    return col;
}

static int same_block(const int a[3], const int b[3])
{
    for (int d = 0; d < 3; ++d)
        if (floor_div_pow2(a[d], MPM_BLOCK_SHIFT) != floor_div_pow2(b[d], MPM_BLOCK_SHIFT)) return 0;
    return 1;
}

int node_coloring_build(const int *coord, int n, NodeColoring *col)
{
    /* count blocks */
    int nb = 0;
    for (int i = 0; i < n; ++i)
        if (i == 0 || !same_block(coord + 3 * (size_t)i, coord + 3 * (size_t)(i - 1))) ++nb;
    if (nb + 1 > col->cap_blocks) {
        int cap = nb + 1 + nb / 4;
        int *bs = realloc(col->block_start, sizeof(int) * (size_t)cap);
        if (!bs) return mpm_error(MPM_EINTERNAL, "out of memory: node colouring");
        col->block_start = bs;
        int *cb = realloc(col->color_blocks, sizeof(int) * (size_t)cap);
        if (!cb) return mpm_error(MPM_EINTERNAL, "out of memory: node colouring");
        col->color_blocks = cb;
        col->cap_blocks = cap;
    }
    col->n_blocks = nb;
    int b = 0;
    int count[MPM_NUM_COLORS] = {0};
    for (int i = 0; i < n; ++i) {
        if (i == 0 || !same_block(coord + 3 * (size_t)i, coord + 3 * (size_t)(i - 1))) {
            col->block_start[b++] = i;
            count[block_color(coord + 3 * (size_t)i)]++;
        }
    }
    col->block_start[nb] = n;
    col->color_start[0] = 0;
    for (int c = 0; c < MPM_NUM_COLORS; ++c) col->color_start[c + 1] = col->color_start[c] + count[c];
    int fill[MPM_NUM_COLORS];
    memcpy(fill, col->color_start, sizeof fill);
    for (int k = 0; k < nb; ++k) {
        int c = block_color(coord + 3 * (size_t)col->block_start[k]);
        col->color_blocks[fill[c]++] = k;
    }
    return MPM_OK;
}

void node_coloring_free(NodeColoring *col)
{
    free(col->block_start);
    free(col->color_blocks);
    memset(col, 0, sizeof *col);
}
