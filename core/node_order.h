/* Node ordering and 8-colour block colouring shared by the grid, the
 * Gauss-Seidel smoother and the multigrid levels.
 *
 * Nodes are grouped in blocks of 4x4x4 (HOT reference §5.1, SPEC 6): node
 * (x,y,z) lies in block (floor(x/4), floor(y/4), floor(z/4)); its colour is
 * the parity of the block coordinates (8 colours). Two distinct blocks of one
 * colour are >= 5 nodes apart, beyond the +-2 stencil of quadratic B-splines,
 * so their nodes can be processed in parallel without races. */
#ifndef MPM_NODE_ORDER_H
#define MPM_NODE_ORDER_H

#include <stdint.h>

#define MPM_BLOCK_SHIFT 2 /* 4 nodes per block edge */
#define MPM_NUM_COLORS 8

static inline int floor_div_pow2(int v, int shift) { return v >= 0 ? v >> shift : -((-v + (1 << shift) - 1) >> shift); }

/* Sort key: block coordinates first, then the position inside the block. */
uint64_t node_order_key(const int c[3]);

/* Computes perm so that new node k = old node perm[k] sorts nodes by
 * node_order_key. coord holds 3n ints. */
int node_order_sort(const int *coord, int n, int *perm);

typedef struct {
    int n_blocks;
    int *block_start;     /* n_blocks + 1; nodes of block b are [block_start[b], block_start[b+1]) */
    int color_start[MPM_NUM_COLORS + 1]; /* blocks of colour c: color_blocks[color_start[c] .. color_start[c+1]) */
    int *color_blocks;    /* block indices grouped by colour, increasing within a colour */
    int cap_blocks;
} NodeColoring;

/* Builds the block ranges and colours of nodes already sorted by
 * node_order_key. Storage is reused across calls. */
int node_coloring_build(const int *coord, int n, NodeColoring *col);
void node_coloring_free(NodeColoring *col);

#endif
