/* floor: solvers */
/* Synthetic SPD 3x3-block test matrices on sparse 3D node sets, shared by
 * test_pcg, test_sgs and test_mg (header-only: tests/CMakeLists.txt builds
 * each test_*.c alone).
 *
 * Nodes: integer points of a ball (or a box) around a centre, sorted with
 * node_order_sort and coloured. Matrix ("elasticity-like" spring network):
 *   A = m I (per node) + sum over coupled pairs e = (i, j) of
 *       K_e (x) [[1, -1], [-1, 1]],
 *   K_e = k(d) (I + u u^T + 0.3 B B^T) with u the unit pair direction, B a
 *   random 3x3 matrix drawn from the pair, k(d) = stiff / |d|^2 (times
 *   core_ratio inside an optional stiff core).
 * Pairs couple when |dx|, |dy|, |dz| <= reach (reach 2: the 125-point
 * quadratic-B-spline stencil; reach 1: 27-point). Symmetric positive
 * definite by construction, rigid modes only weakly pinned by the mass.
 * Optional Dirichlet nodes (y below a level): their rows and columns are
 * zeroed and the diagonal block set to m I (the BC-projected Hessian), and a
 * projection zeroes their entries. */
#ifndef MPM_TEST_SYNTHETIC_H
#define MPM_TEST_SYNTHETIC_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/bsr.h"
#include "core/error.h"
#include "core/mat3.h"
#include "core/node_order.h"
#include "solvers/krylov/linear_op.h"

typedef struct {
    int n;
    int *coord;            /* 3n, sorted by node_order_key */
    NodeColoring col;
    Bsr A;
    double *diag;          /* 9n */
    unsigned char *fixed;  /* n: Dirichlet flag */
    int n_fixed;
    LinearOp op;
    Projection proj;
} SynthProblem;

typedef struct {
    int center[3];
    double radius;     /* ball radius in nodes; <= 0: use box */
    int box[3];        /* box extents when radius <= 0 */
    int reach;         /* 1 or 2 */
    double mass, stiff;
    int dirichlet;     /* 1: nodes with y < center_y - radius + 2 (or box bottom 2 layers) are fixed */
    double core_ratio; /* > 0: pairs with both nodes within radius/2 of the centre get stiff * core_ratio
                          (a stiff inclusion, as in mixed-material scenes) */
    unsigned long long seed;
} SynthParams;

static inline unsigned long long synth_mix(unsigned long long z)
{
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static inline double synth_unit(unsigned long long *s)
{
    *s = synth_mix(*s);
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0; /* [-1, 1) */
}

static inline int synth_cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

static inline void synth_spmv(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }

static inline void synth_project(const void *ctx, double *v)
{
    const SynthProblem *p = ctx;
    for (int i = 0; i < p->n; ++i)
        if (p->fixed[i]) v[3 * i] = v[3 * i + 1] = v[3 * i + 2] = 0.0;
}

static inline void synth_free(SynthProblem *p)
{
    free(p->coord);
    node_coloring_free(&p->col);
    bsr_free(&p->A);
    free(p->diag);
    free(p->fixed);
    memset(p, 0, sizeof *p);
}

/* K_e for the pair of nodes a < b (ids in sorted order) with offset d. */
static inline void synth_pair_block(const SynthParams *sp, int a, int b, const int d[3], double K[9], double scale)
{
    double len2 = (double)(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double u[3] = {d[0] / sqrt(len2), d[1] / sqrt(len2), d[2] / sqrt(len2)};
    unsigned long long s = sp->seed ^ synth_mix(((unsigned long long)a << 32) ^ (unsigned long long)b);
    double B[9];
    for (int k = 0; k < 9; ++k) B[k] = synth_unit(&s);
    double BBt[9];
    m3_mul_bt(B, B, BBt);
    double k = scale * sp->stiff / len2;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) K[3 * r + c] = k * ((r == c ? 1.0 : 0.0) + u[r] * u[c] + 0.3 * BBt[3 * r + c]);
}

static inline int synth_build(SynthProblem *p, const SynthParams *sp)
{
    memset(p, 0, sizeof *p);
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
        if (sp->radius > 0) {
            lo[d] = sp->center[d] - (int)ceil(sp->radius);
            hi[d] = sp->center[d] + (int)ceil(sp->radius);
        } else {
            lo[d] = sp->center[d];
            hi[d] = sp->center[d] + sp->box[d] - 1;
        }
    }
    int ext[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
    size_t cells = (size_t)ext[0] * ext[1] * ext[2];
    int *grid = malloc(sizeof(int) * cells);
    int *tmp = malloc(sizeof(int) * 3 * cells);
    if (!grid || !tmp) return mpm_error(MPM_EINTERNAL, "synth: out of memory");
    int n = 0;
    for (int x = lo[0]; x <= hi[0]; ++x)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int z = lo[2]; z <= hi[2]; ++z) {
                if (sp->radius > 0) {
                    double dx = x - sp->center[0], dy = y - sp->center[1], dz = z - sp->center[2];
                    if (dx * dx + dy * dy + dz * dz > sp->radius * sp->radius) continue;
                }
                tmp[3 * n] = x;
                tmp[3 * n + 1] = y;
                tmp[3 * n + 2] = z;
                ++n;
            }
    int *perm = malloc(sizeof(int) * (size_t)n);
    p->coord = malloc(sizeof(int) * 3 * (size_t)n);
    p->diag = malloc(sizeof(double) * 9 * (size_t)n);
    p->fixed = calloc((size_t)n, 1);
    if (!perm || !p->coord || !p->diag || !p->fixed) return mpm_error(MPM_EINTERNAL, "synth: out of memory");
    int st = node_order_sort(tmp, n, perm);
    if (st) return st;
    for (int i = 0; i < n; ++i) memcpy(p->coord + 3 * i, tmp + 3 * perm[i], 3 * sizeof(int));
    free(perm);
    free(tmp);
    p->n = n;
    for (size_t c = 0; c < cells; ++c) grid[c] = -1;
#define SYNTH_CELL(x, y, z) (((size_t)((x)-lo[0]) * ext[1] + (size_t)((y)-lo[1])) * ext[2] + (size_t)((z)-lo[2]))
    for (int i = 0; i < n; ++i) grid[SYNTH_CELL(p->coord[3 * i], p->coord[3 * i + 1], p->coord[3 * i + 2])] = i;
    int ylim = sp->radius > 0 ? sp->center[1] - (int)ceil(sp->radius) + 2 : lo[1] + 2;
    for (int i = 0; i < n; ++i)
        if (sp->dirichlet && p->coord[3 * i + 1] < ylim) {
            p->fixed[i] = 1;
            ++p->n_fixed;
        }
    st = node_coloring_build(p->coord, n, &p->col);
    if (st) return st;

    int R = sp->reach, w = 2 * R + 1;
    st = bsr_reserve(&p->A, n, (int64_t)n * w * w * w);
    if (st) return st;
    /* rows: neighbours sorted by id */
    int *nb = malloc(sizeof(int) * (size_t)(w * w * w));
    int64_t nnz = 0;
    for (int i = 0; i < n; ++i) {
        p->A.row_ptr[i] = nnz;
        const int *ci = p->coord + 3 * i;
        int cnt = 0;
        for (int dx = -R; dx <= R; ++dx)
            for (int dy = -R; dy <= R; ++dy)
                for (int dz = -R; dz <= R; ++dz) {
                    int x = ci[0] + dx, y = ci[1] + dy, z = ci[2] + dz;
                    if (x < lo[0] || x > hi[0] || y < lo[1] || y > hi[1] || z < lo[2] || z > hi[2]) continue;
                    int j = grid[SYNTH_CELL(x, y, z)];
                    if (j >= 0) nb[cnt++] = j;
                }
        qsort(nb, (size_t)cnt, sizeof(int), synth_cmp_int);
        double Dsum[9] = {0};
        int64_t kdiag = -1;
        for (int a = 0; a < cnt; ++a) {
            int j = nb[a];
            double *blk = p->A.val + 9 * nnz;
            p->A.col[nnz] = j;
            if (j == i) {
                kdiag = nnz;
            } else {
                const int *cj = p->coord + 3 * j;
                int d[3] = {cj[0] - ci[0], cj[1] - ci[1], cj[2] - ci[2]};
                double K[9], scale = 1.0;
                if (sp->core_ratio > 0 && sp->radius > 0) {
                    double ri = 0.0, rj = 0.0;
                    for (int q = 0; q < 3; ++q) {
                        ri += (double)(ci[q] - sp->center[q]) * (ci[q] - sp->center[q]);
                        rj += (double)(cj[q] - sp->center[q]) * (cj[q] - sp->center[q]);
                    }
                    double rc2 = 0.25 * sp->radius * sp->radius;
                    if (ri <= rc2 && rj <= rc2) scale = sp->core_ratio;
                }
                if (i < j) synth_pair_block(sp, i, j, d, K, scale);
                else {
                    int dm[3] = {-d[0], -d[1], -d[2]};
                    synth_pair_block(sp, j, i, dm, K, scale);
                }
                for (int k = 0; k < 9; ++k) {
                    Dsum[k] += K[k];
                    blk[k] = (p->fixed[i] || p->fixed[j]) ? 0.0 : -K[k];
                }
            }
            ++nnz;
        }
        double *Db = p->A.val + 9 * kdiag;
        for (int k = 0; k < 9; ++k) Db[k] = p->fixed[i] ? 0.0 : Dsum[k];
        Db[0] += sp->mass;
        Db[4] += sp->mass;
        Db[8] += sp->mass;
    }
    p->A.row_ptr[n] = nnz;
    p->A.nnzb = nnz;
    bsr_update_pattern_id(&p->A);
    bsr_diagonal(&p->A, p->diag);
#undef SYNTH_CELL
    free(nb);
    free(grid);
    p->op.n_nodes = n;
    p->op.apply = synth_spmv;
    p->op.ctx = &p->A;
    p->proj.apply = synth_project;
    p->proj.ctx = p;
    return MPM_OK;
}

static inline void synth_random_vector(int n, unsigned long long seed, double *v)
{
    unsigned long long s = seed;
    for (int k = 0; k < 3 * n; ++k) v[k] = synth_unit(&s);
}

#endif
