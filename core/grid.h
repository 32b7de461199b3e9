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
 * Hessian assembly, matrix-free products) run in parallel without atomics
 * (core/block_traversal.h): a particle touches nodes base..base+2, and two
 * same-colour particle blocks are >= 8 nodes apart. */
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
    int mls;       /* 1: f1d's D holds the MLS substitute (stencils_use_mls_gradients) */
    double *f1d;   /* 18 per particle: the weights w and their gradients dw as tensor products,
                    * N[d][k] (9) then D[d][k] (9), D = dN or the MLS factor: for slot
                    * s = 9a + 3b + c, w_s = N0a N1b N2c and dw_s = (D0a N1b N2c, N0a D1b N2c,
                    * N0a N1b D2c). Kernels read these 144 bytes instead of 864 of stored w
                    * and dw (stencil_weights) */
    NodeColoring pcolor; /* particle blocks (particles sorted by base-node block) */
    int *base;     /* 3 per particle: base node */
    size_t *perm;  /* sort scratch */
    double *scratch;
} Stencils;

/* The 27 weights w and, unless dw is NULL, the 81 weight gradients of
 * particle k (slot s = 9a + 3b + c; dw[3s + d]), rebuilt from its 1D
 * factors in the products' fixed order, so bit for bit the same values
 * every time and in every kernel. */
static inline void stencil_weights(const Stencils *st, size_t k, double w[27], double *dw)
{
    const double *N = st->f1d + 18 * k, *D = N + 9;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double nn = N[a] * N[3 + b], dn = D[a] * N[3 + b], nd = N[a] * D[3 + b];
            for (int c = 0; c < 3; ++c) {
                int s = 9 * a + 3 * b + c;
                w[s] = nn * N[6 + c];
                if (dw) {
                    dw[3 * s] = dn * N[6 + c];
                    dw[3 * s + 1] = nd * N[6 + c];
                    dw[3 * s + 2] = nn * D[6 + c];
                }
            }
        }
}

/* Sorts particles by base-node block, finds the active nodes, numbers them
 * and fills the stencils. Allocates only when sizes grow. */
int grid_build(Grid *g, Stencils *st, Particles *p, double dx);

/* grid_build, with the n_extra nodes at the integer coordinates `extra`
 * (3 ints each) active too, whether a particle reaches them or not: a
 * distributed run's rank holds the nodes it owns that only other ranks'
 * particles reach (core/dist/dist_grid.h). */
int grid_build_with_nodes(Grid *g, Stencils *st, Particles *p, double dx, const int *extra, int n_extra);

/* MLS-MPM (SPEC 9; Hu et al. 2018 supplement eq. 5-10): replaces each
 * weight gradient grad w_ip by w_ip D_p^-1 (x_i - x_p), D_p = dx^2/4 I for
 * the quadratic B-spline, so the force, the F update and the incremental
 * potential with its gradient, Hessian and H x (core/problem.c reads dw)
 * become MLS-MPM's. Per axis the substitute is still a tensor product:
 * component a is g_a(i_a) w_b(i_b) w_c(i_c), g_a(k) = 4/dx (k - f_a) N_a(k)
 * with f_a = x_a/dx - base_a (kernel.h mls_factor_1d). Sets st->mls; call
 * after grid_build (which restores the B-spline gradients). */
void stencils_use_mls_gradients(Stencils *st, const Particles *p, double dx);

/* Node id at integer coordinates, or -1 if not active. */
int grid_lookup(const Grid *g, const int c[3]);
/* Index of the 4x4x4 node block at block coordinates B (node coordinates
 * 4 B .. 4 B + 3), or -1 if it has no active node. Its node with local
 * index l = (x & 3) << 4 | (y & 3) << 2 | (z & 3) is active when bit l of
 * block_mask is set, and its id is block_first + the set bits below l:
 * ids increase with the block's block_first, then with l. */
int grid_block(const Grid *g, const int B[3]);

void grid_free(Grid *g);
void stencils_free(Stencils *st);

#endif
