/* floor: core */
/* The coloured traversal of particle blocks (core/block_traversal.h) on
 * particles spread over many blocks of every colour, some blocks full and
 * some with a single particle, at negative and positive coordinates:
 * - every particle of the block set is visited exactly once, and no other;
 * - same-colour blocks never share a node of the stencil reach (base node
 *   + {0,1,2}^3);
 * - every node's visitors come in (colour, particle index) order, the order
 *   its sums are made in: the bits do not depend on the thread count;
 * - particles inside a block come in increasing order, and its cells
 *   (MPM_FOR_EACH_CELL) are its maximal runs of one base node;
 * - colours come one after another: no block of a colour begins before
 *   every block of the colours before it has ended;
 * - `continue` in a block's body skips just that block;
 * for the parallel-for and the in-team forms at 1, 2 and 3 threads, on the
 * step's block set and on a subset of it (the set is the caller's value). */
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/block_traversal.h"
#include "core/error.h"
#include "core/grid.h"
#include "tests/common/testutil.h"

typedef struct {
    int *visits;   /* per particle */
    long *ticket;  /* per particle: when it was visited (a global count) */
    long *enter, *leave; /* per block, where the body says so: when it began and ended (-1: not) */
    int n_blocks;
    long next;
} Visits;

static void visits_reset(Visits *v, size_t n)
{
    memset(v->visits, 0, sizeof(int) * n);
    for (size_t k = 0; k < n; ++k) v->ticket[k] = -1;
    for (int q = 0; q < v->n_blocks; ++q) v->enter[q] = v->leave[q] = -1;
    v->next = 0;
}

static long tick(Visits *v)
{
    long t;
#pragma omp atomic capture
    t = v->next++;
    return t;
}

static void visit(Visits *v, int k)
{
    v->ticket[k] = tick(v);
#pragma omp atomic update
    v->visits[k]++;
}

/* A block's body that takes some time (about 20 us), so that a thread
 * which went on to the next colour too early would overlap another's
 * block of this colour. */
static void block_enter(Visits *v, int q) { v->enter[q] = tick(v); }
static void block_leave(Visits *v, int q)
{
    double t0 = omp_get_wtime();
    while (omp_get_wtime() - t0 < 2e-5) {
    }
    v->leave[q] = tick(v);
}

/* One visit of the stencil reach of a particle. */
typedef struct {
    uint64_t node; /* packed node coordinates */
    long ticket;
    int color, block, k;
} Touch;

static uint64_t pack(const int c[3])
{
    uint64_t key = 0;
    for (int d = 0; d < 3; ++d) key = key << 21 | (uint64_t)(c[d] + (1 << 20));
    return key;
}

static int by_node_then_ticket(const void *a, const void *b)
{
    const Touch *x = a, *y = b;
    if (x->node != y->node) return x->node < y->node ? -1 : 1;
    return (x->ticket > y->ticket) - (x->ticket < y->ticket);
}

/* The checks of one traversal of `set`, whose visits are in v; in_set[k]:
 * particle k belongs to a block of the set. */
static void check_traversal(const char *what, const Stencils *st, const NodeColoring *set, const Visits *v,
                            const char *in_set, int threads)
{
    const int np = (int)st->n;
    int *color = malloc(sizeof(int) * (size_t)set->n_blocks), *block = malloc(sizeof(int) * (size_t)np);
    for (int q = 0; q < set->n_blocks; ++q) color[q] = -1;
    for (int c = 0; c < MPM_NUM_COLORS; ++c)
        for (int qi = set->color_start[c]; qi < set->color_start[c + 1]; ++qi) color[set->color_blocks[qi]] = c;
    for (int q = 0; q < set->n_blocks; ++q)
        for (int k = set->block_start[q]; k < set->block_start[q + 1]; ++k) block[k] = q;

    int wrong_count = 0, out_of_set = 0, not_increasing = 0;
    for (int k = 0; k < np; ++k) {
        wrong_count += in_set[k] && v->visits[k] != 1;
        out_of_set += !in_set[k] && v->visits[k] != 0;
        if (in_set[k] && k > set->block_start[block[k]]) not_increasing += v->ticket[k] <= v->ticket[k - 1];
    }
    CHECK(wrong_count == 0, "%s, %d threads: %d particles of the set not visited exactly once", what, threads,
          wrong_count);
    CHECK(out_of_set == 0, "%s, %d threads: %d particles outside the set visited", what, threads, out_of_set);
    CHECK(not_increasing == 0, "%s, %d threads: %d particles visited before their block's previous one", what,
          threads, not_increasing);

    Touch *t = malloc(sizeof(Touch) * 27 * (size_t)np);
    size_t nt = 0;
    for (int k = 0; k < np; ++k) {
        if (!in_set[k]) continue;
        const int *b = st->base + 3 * (size_t)k;
        for (int s = 0; s < 27; ++s) {
            int c[3] = {b[0] + s / 9, b[1] + (s / 3) % 3, b[2] + s % 3};
            t[nt++] = (Touch){pack(c), v->ticket[k], color[block[k]], block[k], k};
        }
    }
    qsort(t, nt, sizeof *t, by_node_then_ticket);
    /* same node: a later visit is a later colour, or the same block's later
     * particle; a same-colour visit from another block is a shared node */
    int shared = 0, out_of_order = 0;
    for (size_t e = 1; e < nt; ++e) {
        if (t[e].node != t[e - 1].node) continue;
        if (t[e].color == t[e - 1].color && t[e].block != t[e - 1].block) ++shared;
        else if (t[e].color < t[e - 1].color || (t[e].color == t[e - 1].color && t[e].k <= t[e - 1].k))
            ++out_of_order;
    }
    CHECK(shared == 0, "%s, %d threads: %d node visits from two same-colour blocks", what, threads, shared);
    CHECK(out_of_order == 0, "%s, %d threads: %d node visits out of (colour, particle) order", what, threads,
          out_of_order);

    /* colours one after another: every block of a colour ends before any
     * block of a later colour begins (where the body recorded its blocks) */
    long last_leave[MPM_NUM_COLORS], first_enter[MPM_NUM_COLORS];
    for (int c = 0; c < MPM_NUM_COLORS; ++c) last_leave[c] = -1, first_enter[c] = -1;
    int recorded = 0;
    for (int q = 0; q < set->n_blocks; ++q) {
        if (color[q] < 0 || v->enter[q] < 0) continue;
        int c = color[q];
        ++recorded;
        if (v->leave[q] > last_leave[c]) last_leave[c] = v->leave[q];
        if (first_enter[c] < 0 || v->enter[q] < first_enter[c]) first_enter[c] = v->enter[q];
    }
    int overlaps = 0;
    for (int c = 0; c < MPM_NUM_COLORS; ++c)
        for (int later = c + 1; later < MPM_NUM_COLORS; ++later)
            overlaps += last_leave[c] >= 0 && first_enter[later] >= 0 && first_enter[later] <= last_leave[c];
    if (recorded)
        CHECK(overlaps == 0, "%s, %d threads: %d pairs of colours whose blocks overlap in time", what, threads,
              overlaps);
    free(t), free(color), free(block);
}

/* Particles over [-0.8, 1.2)^3, dx 0.1: a dense jittered lattice in one
 * corner and scattered particles elsewhere (blocks of one particle). */
static int build(Particles *p, Grid *g, Stencils *st)
{
    unsigned long long rs = 2024;
    const double v[3] = {0, 0, 0};
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j)
            for (int l = 0; l < 16; ++l) {
                double x[3] = {-0.8 + (i + 0.5 + 0.3 * test_uniform(&rs, -1, 1)) * 0.05,
                               -0.8 + (j + 0.5 + 0.3 * test_uniform(&rs, -1, 1)) * 0.05,
                               0.1 + (l + 0.5 + 0.3 * test_uniform(&rs, -1, 1)) * 0.05};
                int s = particles_push(p, x, v, 1.0, 1.0, 0);
                if (s) return s;
            }
    for (int e = 0; e < 400; ++e) {
        double x[3] = {test_uniform(&rs, -0.8, 1.2), test_uniform(&rs, -0.8, 1.2), test_uniform(&rs, -0.8, 1.2)};
        int s = particles_push(p, x, v, 1.0, 1.0, 0);
        if (s) return s;
    }
    return grid_build(g, st, p, 0.1);
}

/* Every other block of each colour of `all`, as a set of its own. */
static int subset(const NodeColoring *all, NodeColoring *sub)
{
    *sub = *all;
    sub->color_blocks = malloc(sizeof(int) * (size_t)(all->n_blocks > 0 ? all->n_blocks : 1));
    if (!sub->color_blocks) return MPM_EINTERNAL;
    int m = 0;
    for (int c = 0; c < MPM_NUM_COLORS; ++c) {
        sub->color_start[c] = m;
        for (int qi = all->color_start[c]; qi < all->color_start[c + 1]; qi += 2)
            sub->color_blocks[m++] = all->color_blocks[qi];
    }
    sub->color_start[MPM_NUM_COLORS] = m;
    return MPM_OK;
}

static void mark_set(const NodeColoring *set, int np, char *in_set)
{
    memset(in_set, 0, (size_t)np);
    for (int qi = 0; qi < set->color_start[MPM_NUM_COLORS]; ++qi) {
        int q = set->color_blocks[qi];
        for (int k = set->block_start[q]; k < set->block_start[q + 1]; ++k) in_set[k] = 1;
    }
}

/* The cells of every block: maximal runs of one base node, in order. */
static void check_cells(const Stencils *st)
{
    const NodeColoring *pc = &st->pcolor;
    int covered_wrong = 0, mixed = 0, not_maximal = 0, cells = 0, multi = 0;
    for (int q = 0; q < pc->n_blocks; ++q) {
        int k0 = pc->block_start[q], k1 = pc->block_start[q + 1], next = k0;
        MPM_FOR_EACH_CELL(st->base, k0, k1, k, kend) {
            const int *b = st->base + 3 * (size_t)k;
            covered_wrong += k != next || kend <= k || kend > k1;
            for (int kk = k + 1; kk < kend; ++kk) mixed += memcmp(st->base + 3 * (size_t)kk, b, 3 * sizeof(int)) != 0;
            if (kend < k1) not_maximal += memcmp(st->base + 3 * (size_t)kend, b, 3 * sizeof(int)) == 0;
            next = kend;
            ++cells;
            multi += kend - k > 1;
        }
        covered_wrong += next != k1;
    }
    printf("cells: %d (%d of several particles)\n", cells, multi);
    CHECK(covered_wrong == 0, "%d blocks whose cells do not tile their particle range in order", covered_wrong);
    CHECK(mixed == 0, "%d particles in a cell of another base node", mixed);
    CHECK(not_maximal == 0, "%d cells that stop before the end of their base node's run", not_maximal);
    CHECK(multi > 0 && multi < cells, "the particles make cells of one and of several particles (%d of %d)", multi,
          cells);
}

int main(void)
{
    Particles p = {0};
    Grid g = {0};
    Stencils st = {0};
    int status = build(&p, &g, &st);
    CHECK(status == MPM_OK, "build: %s", mpm_last_error());
    if (status) return test_summary("test_block_traversal");
    const int np = (int)p.n;
    const NodeColoring *pc = &st.pcolor;
    int singles = 0;
    for (int q = 0; q < pc->n_blocks; ++q) singles += pc->block_start[q + 1] - pc->block_start[q] == 1;
    int least = np;
    for (int c = 0; c < MPM_NUM_COLORS; ++c)
        if (pc->color_start[c + 1] - pc->color_start[c] < least) least = pc->color_start[c + 1] - pc->color_start[c];
    printf("%d particles, %d blocks (%d of one particle), at least %d blocks a colour\n", np, pc->n_blocks, singles,
           least);
    CHECK(least >= 8 && singles >= 8, "blocks of every colour, some with one particle");

    Visits v = {malloc(sizeof(int) * (size_t)np), malloc(sizeof(long) * (size_t)np),
                malloc(sizeof(long) * (size_t)pc->n_blocks), malloc(sizeof(long) * (size_t)pc->n_blocks), pc->n_blocks,
                0};
    char *in_set = malloc((size_t)np), *odd_out = malloc((size_t)np);
    NodeColoring sub;
    CHECK(subset(pc, &sub) == MPM_OK, "subset");
    for (int threads = 1; threads <= 3; ++threads) {
        omp_set_num_threads(threads);
        for (int which = 0; which < 2; ++which) {
            const NodeColoring *set = which ? &sub : pc;
            const char *name = which ? "every other block" : "all blocks";
            char what[96];
            mark_set(set, np, in_set);

            visits_reset(&v, (size_t)np);
            MPM_FOR_EACH_COLORED_PARTICLE(set, k) visit(&v, k);
            snprintf(what, sizeof what, "%s, particles", name);
            check_traversal(what, &st, set, &v, in_set, threads);

            visits_reset(&v, (size_t)np);
            MPM_FOR_EACH_COLORED_BLOCK(set, q, k0, k1) {
                block_enter(&v, q);
                MPM_FOR_EACH_CELL(st.base, k0, k1, k, kend) {
                    for (int kk = k; kk < kend; ++kk) visit(&v, kk);
                }
                block_leave(&v, q);
            }
            snprintf(what, sizeof what, "%s, blocks and cells", name);
            check_traversal(what, &st, set, &v, in_set, threads);

            visits_reset(&v, (size_t)np);
            int team = 0;
#pragma omp parallel
            {
#pragma omp single
                team = omp_get_num_threads();
                MPM_FOR_EACH_COLORED_BLOCK_IN_TEAM(set, 2, q, k0, k1) {
                    block_enter(&v, q);
                    for (int k = k0; k < k1; ++k) visit(&v, k);
                    block_leave(&v, q);
                }
            }
            snprintf(what, sizeof what, "%s, in a team of %d", name, team);
            check_traversal(what, &st, set, &v, in_set, threads);

            /* continue: blocks of odd index are skipped, the others whole */
            visits_reset(&v, (size_t)np);
            MPM_FOR_EACH_COLORED_BLOCK(set, q, k0, k1) {
                if (q % 2) continue;
                for (int k = k0; k < k1; ++k) visit(&v, k);
            }
            memcpy(odd_out, in_set, (size_t)np);
            for (int q = 1; q < set->n_blocks; q += 2)
                for (int k = set->block_start[q]; k < set->block_start[q + 1]; ++k) odd_out[k] = 0;
            snprintf(what, sizeof what, "%s, continue on odd blocks", name);
            check_traversal(what, &st, set, &v, odd_out, threads);
        }
    }
    check_cells(&st);
    free(sub.color_blocks);
    free(v.visits), free(v.ticket), free(v.enter), free(v.leave), free(in_set), free(odd_out);
    grid_free(&g);
    stencils_free(&st);
    particles_free(&p);
    return test_summary("test_block_traversal");
}
