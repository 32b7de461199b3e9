/* Sparse background grid of active nodes and per-particle stencils.
 *
 * Nodes sit at integer coordinates i*dx. Active nodes are those that receive
 * a positive quadratic B-spline weight from some particle (so every active
 * node has positive mass). Nodes live in 4x4x4 blocks (an SPGrid-like layout:
 * a hash from block coordinates to a 64-bit occupancy mask); node ids follow
 * node_order_key (block, then position in the block), so neighbours are close
 * in memory and the block colouring of core/node_order.h applies directly.
 *
 * Particles are kept sorted by the block of their base node; `pcolor` groups
 * those particle blocks into 8 parity colours, so scatters (P2G, gradient,
 * Hessian assembly, matrix-free products) run in parallel without atomics:
 * a particle touches nodes base..base+2, and two same-colour particle blocks
 * are >= 8 nodes apart. */
#ifndef MPM_GRID_H
#define MPM_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "core/node_order.h"
#include "core/particles.h"

#define MPM_STENCIL 27

typedef struct {
    double dx;
    int n;              /* active nodes */
    int *coord;         /* 3n integer coordinates */
    double *mass;       /* n */
    double *v;          /* 3n grid velocity v^n after P2G */
    NodeColoring coloring; /* node blocks by colour (GS smoother, MG) */

    /* block table: open-addressing hash of block keys */
    int n_blocks, cap_blocks;
    uint64_t *block_key;   /* per block: packed block coordinates */
    uint64_t *block_mask;  /* per block: occupancy of its 64 nodes */
    int *block_first;      /* per block: id of its first node */
    int hash_cap;          /* power of two */
    int *hash_slot;        /* block index or -1 */
    int cap_nodes;
} Grid;

/* Per-particle stencil data, valid for the particle positions of one step. */
typedef struct {
    size_t n, cap;
    int *node;     /* 27 per particle: node id, -1 where the weight is exactly 0 */
    double *w;     /* 27 per particle */
    double *dw;    /* 81 per particle: weight gradients (27 x 3) */
    NodeColoring pcolor; /* particle blocks (particles sorted by base-node block) */
    int *base;     /* 3 per particle: base node */
    size_t *perm;  /* sort scratch */
    double *scratch;
} Stencils;

/* Sorts particles by base-node block, finds the active nodes, numbers them
 * and fills the stencils. Allocates only when sizes grow. */
int grid_build(Grid *g, Stencils *st, Particles *p, double dx);

/* Node id at integer coordinates, or -1 if not active. */
int grid_lookup(const Grid *g, const int c[3]);

void grid_free(Grid *g);
void stencils_free(Stencils *st);

#endif
