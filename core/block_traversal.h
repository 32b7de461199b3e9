/* The coloured traversal of particle blocks: the one loop nest of every
 * scatter from particles to nodes (P2G, the CN scale, the gradient, the
 * Hessian's pattern and assembly, H x, its diagonal, the grid's occupancy).
 *
 * Colours run one after another, the blocks of one colour in parallel and
 * the particles of a block in index order. A block's particles reach 6
 * nodes per axis and same-colour blocks start >= 8 apart (core/grid.h), so
 * no two threads write one node, and every node sums its terms in (colour,
 * particle) order whatever the thread count (docs/design.md "Threads and
 * determinism", SPEC 9.4).
 *
 * The block set is a value the caller passes, a NodeColoring whose block
 * ranges index particles (today a step's st->pcolor). A distributed run
 * passes a rank's owned-plus-ghost blocks as just another such set.
 *
 * The macros are `for` headers, so a kernel's body keeps its own lines
 * (for a debugger and for warnings) and compiles as if written out; `set`
 * is evaluated more than once. In a block's body `continue` skips to the
 * next block and so does `break` (an omp for cannot be left early). */
#ifndef MPM_BLOCK_TRAVERSAL_H
#define MPM_BLOCK_TRAVERSAL_H

#include <stddef.h>
#include <string.h>

#include "core/node_order.h"

#define MPM_TRAVERSAL_PRAGMA_(text) _Pragma(#text)

/* The blocks of one colour of `set` as the iterations of a worksharing
 * loop; the inner one-pass loop only declares q and its particle range
 * [k0, k1) for the body. */
#define MPM_TRAVERSAL_BLOCKS_OF_COLOR_(set, color, q, k0, k1)                                                      \
    for (int q##_at = (set)->color_start[color]; q##_at < (set)->color_start[(color) + 1]; ++q##_at)               \
        for (int q = (set)->color_blocks[q##_at], k0 = (set)->block_start[q], k1 = (set)->block_start[q + 1],      \
                 q##_once = 1;                                                                                     \
             q##_once; q##_once = 0)

/* Block q of `set` with its particles [k0, k1), each colour's blocks shared
 * by a new thread team (schedule(dynamic, 4): blocks hold very different
 * particle counts); the team's end is the barrier between colours. */
#define MPM_FOR_EACH_COLORED_BLOCK(set, q, k0, k1)                                                                 \
    for (int q##_color = 0; q##_color < MPM_NUM_COLORS; ++q##_color)                                               \
        MPM_TRAVERSAL_PRAGMA_(omp parallel for schedule(dynamic, 4))                                               \
        MPM_TRAVERSAL_BLOCKS_OF_COLOR_(set, q##_color, q, k0, k1)

/* The same inside an enclosing `omp parallel` whose threads keep their own
 * buffers across blocks: each colour is an `omp for` with the given chunk,
 * its implicit barrier the one between colours, so every thread of the
 * team must reach the loop. */
#define MPM_FOR_EACH_COLORED_BLOCK_IN_TEAM(set, chunk, q, k0, k1)                                                  \
    for (int q##_color = 0; q##_color < MPM_NUM_COLORS; ++q##_color)                                               \
        MPM_TRAVERSAL_PRAGMA_(omp for schedule(dynamic, chunk))                                                    \
        MPM_TRAVERSAL_BLOCKS_OF_COLOR_(set, q##_color, q, k0, k1)

/* Particle k of every block of `set`, in the traversal's order. */
#define MPM_FOR_EACH_COLORED_PARTICLE(set, k)                                                                      \
    MPM_FOR_EACH_COLORED_BLOCK(set, k##_block, k##_begin, k##_end)                                                 \
        for (int k = k##_begin; k < k##_end; ++k)

/* One past the last particle of the cell that starts at particle k: the run
 * of particles [k, end) < k1 with k's base node (base: 3 ints a particle).
 * Particles are sorted by base node (core/grid.c), so a cell's particles
 * are consecutive and share their 27 stencil nodes. */
static inline int particle_cell_end(const int *base, int k, int k1)
{
    const int *b = base + 3 * (size_t)k;
    int end = k + 1;
    while (end < k1 && memcmp(base + 3 * (size_t)end, b, 3 * sizeof(int)) == 0) ++end;
    return end;
}

/* The cells of the particle range [k0, k1), one per iteration as [k, kend),
 * in order: kernels that sum a cell's particles before one scatter. */
#define MPM_FOR_EACH_CELL(base, k0, k1, k, kend)                                                                   \
    for (int k = (k0), kend = particle_cell_end((base), (k0), (k1)); k < (k1);                                     \
         k = kend, kend = particle_cell_end((base), kend, (k1)))

#endif
