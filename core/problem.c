#include "core/problem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/block_traversal.h"
#include "core/error.h"
#include "core/fcr.h"
#include "core/fcr4.h"
#include "core/gradient_cell.h"
#include "core/hessian_cell.h"
#include "core/mat3.h"
#include "core/reduce.h"

#define NEIGH 125

/* Offset index between stencil slots s and t of one particle: node (i + d),
 * d = (t/9 - s/9, (t/3)%3 - (s/3)%3, t%3 - s%3) in [-2,2]^3, has slot
 * 25 (d0 + 2) + 5 (d1 + 2) + (d2 + 2) of a row's 125. Generated at compile
 * time: constant data, nothing to build or synchronise at run time. */
#define PAIR_OFFSET(s, t) (25 * ((t) / 9 - (s) / 9 + 2) + 5 * ((t) / 3 % 3 - (s) / 3 % 3 + 2) + ((t) % 3 - (s) % 3 + 2))
#define PAIR_ROW3(s, t) PAIR_OFFSET(s, t), PAIR_OFFSET(s, (t) + 1), PAIR_OFFSET(s, (t) + 2)
#define PAIR_ROW9(s, t) PAIR_ROW3(s, t), PAIR_ROW3(s, (t) + 3), PAIR_ROW3(s, (t) + 6)
#define PAIR_ROW(s) {PAIR_ROW9(s, 0), PAIR_ROW9(s, 9), PAIR_ROW9(s, 18)}
#define PAIR_ROWS3(s) PAIR_ROW(s), PAIR_ROW((s) + 1), PAIR_ROW((s) + 2)
#define PAIR_ROWS9(s) PAIR_ROWS3(s), PAIR_ROWS3((s) + 3), PAIR_ROWS3((s) + 6)
static const unsigned char g_pair_offset[27][27] = {PAIR_ROWS9(0), PAIR_ROWS9(9), PAIR_ROWS9(18)};

static int grow(void **ptr, size_t bytes)
{
    void *q = realloc(*ptr, bytes);
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory (%zu bytes) in the step problem", bytes);
    *ptr = q;
    return MPM_OK;
}

static int ensure_capacity(StepProblem *pb, size_t np, int nn)
{
    int st = 0;
    if (np > pb->cap_particles) {
        size_t c = np + np / 4 + 256;
        st |= grow((void **)&pb->a, sizeof(double) * 81 * c);
        st |= grow((void **)&pb->mu, sizeof(double) * c);
        st |= grow((void **)&pb->lambda, sizeof(double) * c);
        st |= grow((void **)&pb->stiff, sizeof(double) * c);
        st |= grow((void **)&pb->F, sizeof(double) * 9 * c);
        st |= grow((void **)&pb->P, sizeof(double) * 9 * c);
        if (st) return MPM_EINTERNAL;
        pb->cap_particles = c;
    }
    if (nn > pb->cap_nodes) {
        size_t c = (size_t)nn + (size_t)nn / 4 + 256;
        st |= grow((void **)&pb->bc, c);
        st |= grow((void **)&pb->bc_P, sizeof(double) * 9 * c);
        st |= grow((void **)&pb->dv0, sizeof(double) * 3 * c);
        st |= grow((void **)&pb->kappa, sizeof(double) * c);
        st |= grow((void **)&pb->slot, sizeof(short) * NEIGH * c);
        st |= grow((void **)&pb->rowmask, sizeof(uint64_t) * 2 * c);
        st |= grow((void **)&pb->tmp, sizeof(double) * 3 * c);
        st |= grow((void **)&pb->halo, sizeof(double) * 3 * c);
        if (st) return MPM_EINTERNAL;
        pb->cap_nodes = (int)c;
    }
    return MPM_OK;
}

/* ---- a distributed run (pb->comm; docs/distributed.md) ---- */

/* The ghosts' partial sums of a node field (width values a node) added
 * into their owners. */
static void halo_sum(StepProblem *pb, double *v, int width)
{
    if (pb->comm && pb->comm->halo_sum(pb->comm->ctx, v, width)) pb->comm_failed = 1;
}

/* Zero at every ghost: an outgoing field is its owners'. */
static void zero_ghosts(const StepProblem *pb, double *v, int width)
{
    if (!pb->comm) return;
    for (int i = 0; i < pb->n_nodes; ++i)
        if (!pb->owned[i]) memset(v + (size_t)width * i, 0, sizeof(double) * (size_t)width);
}

/* An incoming node field with its ghosts set from their owners (v itself
 * on one process). */
static const double *with_ghosts(StepProblem *pb, const double *v)
{
    if (!pb->comm) return v;
    memcpy(pb->halo, v, sizeof(double) * 3 * (size_t)pb->n_nodes);
    if (pb->comm->halo_copy(pb->comm->ctx, pb->halo, 3)) pb->comm_failed = 1;
    return pb->halo;
}

/* A sum over the ranks (the value itself on one process). */
static double ranks_sum(StepProblem *pb, double v)
{
    if (pb->comm && pb->comm->sum(pb->comm->ctx, &v, 1)) pb->comm_failed = 1;
    return v;
}

static double ranks_max(StepProblem *pb, double v)
{
    if (pb->comm && pb->comm->max(pb->comm->ctx, &v, 1)) pb->comm_failed = 1;
    return v;
}

int problem_prepare(StepProblem *pb, const Grid *g, const Stencils *st, const Particles *p,
                    const Material *mats, int n_mats, double dt, const double gravity[3])
{
    int status = ensure_capacity(pb, p->n, g->n);
    if (status) return status;
    pb->n_nodes = g->n;
    pb->n_particles = p->n;
    pb->dt = dt;
    pb->dx = g->dx;
    memcpy(pb->gravity, gravity, sizeof pb->gravity);
    pb->grid = g;
    pb->st = st;
    pb->parts = p;
    pb->mats = mats;
    pb->n_mats = n_mats;
    pb->pattern_ready = 0;
    pb->tangent_stored = 0;
    pb->n_dirichlet = 0;

    double maxstiff = 0.0;
#pragma omp parallel for schedule(static) reduction(max : maxstiff)
    for (size_t k = 0; k < p->n; ++k) {
        const Material *m = &mats[p->mat[k]];
        double h = 1.0;
        if (p->Jp && m->plasticity == PLASTICITY_SNOW && m->hardening > 0.0) h = exp(m->hardening * (1.0 - p->Jp[k]));
        pb->mu[k] = h * m->mu;
        pb->lambda[k] = h * m->lambda;
        pb->stiff[k] = fcr_rest_stiffness(pb->mu[k], pb->lambda[k]);
        if (pb->stiff[k] > maxstiff) maxstiff = pb->stiff[k];
        /* a_ip = F^nT grad w_ip */
        const double *Fn = p->F + 9 * k;
        double w[27], dw[81];
        stencil_weights(st, k, w, dw);
        double *a = pb->a + 81 * k;
        for (int s = 0; s < 27; ++s) {
            const double *gw = dw + 3 * s;
            for (int b = 0; b < 3; ++b) a[3 * s + b] = Fn[b] * gw[0] + Fn[3 + b] * gw[1] + Fn[6 + b] * gw[2];
        }
    }
    pb->max_stiffness = ranks_max(pb, maxstiff);
    pb->n_global = g->n;
    if (pb->comm) {
        int owned = 0;
        for (int i = 0; i < g->n; ++i) owned += pb->owned[i];
        pb->n_global = ranks_sum(pb, owned);
    }
    if (g->n == 0 && !pb->comm) return MPM_OK; /* no particles yet (a scene of sources only): nothing to set up */

    /* CN scale: kappa_i = 24 dx^2 dt abar_i, abar_i = sum_p w_ip m_p a_p / m_i
     * (SPEC 4, HOT §5.2). Scatter by particle-block colour. */
    double *num = pb->kappa;
    memset(num, 0, sizeof(double) * (size_t)g->n);
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const int *node = st->node + 27 * (size_t)k;
        double w[27];
        stencil_weights(st, (size_t)k, w, NULL);
        double s = p->mass[k] * pb->stiff[k];
        for (int t = 0; t < 27; ++t)
            if (node[t] >= 0) num[node[t]] += w[t] * s;
    }
    halo_sum(pb, num, 1); /* distributed: the owners' sums (a ghost's is its owner's, copied below) */
    double min_pos = INFINITY;
    for (int i = 0; i < g->n; ++i) {
        if (pb->comm && !pb->owned[i]) continue;
        double abar = num[i] / g->mass[i];
        num[i] = abar;
        if (abar > 0.0 && abar < min_pos) min_pos = abar;
    }
    min_pos = -ranks_max(pb, -min_pos);
    if (!isfinite(min_pos)) min_pos = 1.0; /* no elastic particle at all: plain residual */
    double scale = 24.0 * pb->dx * pb->dx * dt;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < g->n; ++i) {
        double abar = num[i] > 0.0 ? num[i] : min_pos; /* SPEC 4 guard */
        pb->kappa[i] = scale * abar;
    }
    if (pb->comm && pb->comm->halo_copy(pb->comm->ctx, pb->kappa, 1)) pb->comm_failed = 1;
    memset(pb->bc, BC_FREE, (size_t)g->n);
    /* initial guess of free nodes: dt g (HOT reference §1.3) */
#pragma omp parallel for schedule(static)
    for (int i = 0; i < g->n; ++i)
        for (int d = 0; d < 3; ++d) pb->dv0[3 * i + d] = dt * gravity[d];
    return MPM_OK;
}

void problem_set_dirichlet(StepProblem *pb, int i, const double v_target[3], const double normal[3])
{
    const double *vn = pb->grid->v + 3 * (size_t)i;
    double *P = pb->bc_P + 9 * (size_t)i;
    double *dv0 = pb->dv0 + 3 * (size_t)i;
    if (!normal) {
        pb->bc[i] = BC_STICKY;
        memset(P, 0, 9 * sizeof(double));
        for (int d = 0; d < 3; ++d) dv0[d] = v_target[d] - vn[d];
        return;
    }
    if (pb->bc[i] == BC_STICKY) return;
    double n[3] = {normal[0], normal[1], normal[2]};
    if (pb->bc[i] == BC_FREE) m3_identity(P);
    /* Gram-Schmidt against normals already removed: n <- P n. */
    double pn[3];
    m3_mulv(P, n, pn);
    double len = v3_norm(pn);
    pb->bc[i] = BC_SLIP;
    if (len < 1e-8) return; /* already constrained along n */
    for (int d = 0; d < 3; ++d) pn[d] /= len;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) P[3 * r + c] -= pn[r] * pn[c];
    /* the normal component of v^{n+1} becomes the collider's: dv.n = (v_target - v^n).n */
    double cur = v3_dot(dv0, pn), want = v3_dot(v_target, pn) - v3_dot(vn, pn);
    for (int d = 0; d < 3; ++d) dv0[d] += (want - cur) * pn[d];
}

void problem_initial_guess(const StepProblem *pb, double *dv)
{
    if (pb->n_nodes > 0) memcpy(dv, pb->dv0, sizeof(double) * 3 * (size_t)pb->n_nodes);
}

static inline void project_node(const StepProblem *pb, int i, double *v)
{
    unsigned char b = pb->bc[i];
    if (b == BC_FREE) return;
    if (b == BC_STICKY) {
        v[0] = v[1] = v[2] = 0.0;
        return;
    }
    m3_mulv(pb->bc_P + 9 * (size_t)i, v, v);
}

void problem_project(const StepProblem *pb, double *v)
{
    if (pb->n_dirichlet == 0) return;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < pb->n_nodes; ++i) project_node(pb, i, v + 3 * (size_t)i);
}

/* The energy's sums go through reduce_sum (core/reduce.h): the same bits for
 * every thread count. */
typedef struct {
    StepProblem *pb;
    const double *dv;
} EnergyArgs;

/* dt (v_i + dv_i) of the stencil nodes, kept across the particles of a
 * cell (they share their 27 nodes): slot s holds node id[s]'s value. */
typedef struct {
    int id[27];
    double u[27][3];
} NodeCache;

/* F_p(dv) = F_p^n + dt sum_i (v_i + dv_i) a_ip^T (SPEC 3) into F, summed
 * over the stencil in slot order (in registers: F may alias nothing). */
static inline void gather_F(const StepProblem *pb, const double *dv, size_t k, NodeCache *nc, double *restrict Fout)
{
    const int *node = pb->st->node + 27 * k;
    const double *a = pb->a + 81 * k, *vn = pb->grid->v;
    double dt = pb->dt;
    double F[9];
    m3_copy(F, pb->parts->F + 9 * k);
    for (int s = 0; s < 27; ++s) {
        int i = node[s];
        if (i < 0) continue;
        double *u = nc->u[s];
        if (nc->id[s] != i) {
            nc->id[s] = i;
            u[0] = dt * (vn[3 * i] + dv[3 * i]);
            u[1] = dt * (vn[3 * i + 1] + dv[3 * i + 1]);
            u[2] = dt * (vn[3 * i + 2] + dv[3 * i + 2]);
        }
        const double *as = a + 3 * s;
        F[0] += u[0] * as[0]; F[1] += u[0] * as[1]; F[2] += u[0] * as[2];
        F[3] += u[1] * as[0]; F[4] += u[1] * as[1]; F[5] += u[1] * as[2];
        F[6] += u[2] * as[0]; F[7] += u[2] * as[1]; F[8] += u[2] * as[2];
    }
    m3_copy(Fout, F);
}

/* Elastic energy of particles [begin, end); stores F(dv) and P(F) per
 * particle. Four particles at a time share the SIMD lanes of the SVD
 * (core/fcr4.h); the sum keeps the particle order. */
static double elastic_range(const void *ctx, size_t begin, size_t end)
{
    const EnergyArgs *ea = ctx;
    StepProblem *pb = ea->pb;
    const Particles *p = pb->parts;
    double e = 0.0;
    NodeCache nc;
    for (int s = 0; s < 27; ++s) nc.id[s] = -1;
    size_t k = begin;
    for (; k + 4 <= end; k += 4) {
        for (int l = 0; l < 4; ++l) gather_F(pb, ea->dv, k + l, &nc, pb->F + 9 * (k + l));
        double psi[4];
        fcr_psi_P4(pb->F + 9 * k, pb->mu + k, pb->lambda + k, pb->P + 9 * k, psi, pb->stress_kernel);
        for (int l = 0; l < 4; ++l) e += p->vol[k + l] * psi[l];
    }
    for (; k < end; ++k) {
        gather_F(pb, ea->dv, k, &nc, pb->F + 9 * k);
        e += p->vol[k] * fcr_psi_P(pb->F + 9 * k, pb->mu[k], pb->lambda[k], pb->P + 9 * k);
    }
    return e;
}

/* Inertia and gravity terms of nodes [begin, end). */
static double inertial_range(const void *ctx, size_t begin, size_t end)
{
    const EnergyArgs *ea = ctx;
    const StepProblem *pb = ea->pb;
    const double *m = pb->grid->mass, *g = pb->gravity, *dv = ea->dv;
    double dt = pb->dt, e = 0.0;
    for (size_t i = begin; i < end; ++i) {
        const double *d = dv + 3 * i;
        e += m[i] * (0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - dt * (g[0] * d[0] + g[1] * d[1] + g[2] * d[2]));
    }
    return e;
}

double problem_energy(StepProblem *pb, const double *dv)
{
    EnergyArgs ea = {pb, with_ghosts(pb, dv)};
    pb->tangent_stored = 0; /* F changes */
    double elastic = reduce_sum(pb->parts->n, 64, elastic_range, &ea);
    double inertial = reduce_sum((size_t)pb->n_nodes, 1024, inertial_range, &ea);
    if (pb->comm) { /* both sums over the ranks, in one reduction */
        double both[2] = {elastic, inertial};
        if (pb->comm->sum(pb->comm->ctx, both, 2)) pb->comm_failed = 1;
        elastic = both[0], inertial = both[1];
    }
    pb->elastic_energy = elastic;
    return inertial + elastic;
}

void problem_gradient(StepProblem *pb, const double *dv_in, double *grad)
{
    const double *dv = with_ghosts(pb, dv_in);
    const Particles *p = pb->parts;
    const Stencils *st = pb->st;
    const double *m = pb->grid->mass;
    double dt = pb->dt;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < pb->n_nodes; ++i)
        for (int d = 0; d < 3; ++d) grad[3 * i + d] = m[i] * (dv[3 * i + d] - dt * pb->gravity[d]);
    MPM_FOR_EACH_COLORED_BLOCK(&st->pcolor, q, k0, kend) {
        /* the particles of one cell (same base node) share their stencil */
        MPM_FOR_EACH_CELL(st->base, k0, kend, k, k1) {
            /* the next cell's node ids, read only at its scatter (a
             * cell's particles between: no hardware stream covers them) */
            __builtin_prefetch(st->node + 27 * (size_t)k1);
            __builtin_prefetch(st->node + 27 * (size_t)k1 + 16);
            _Alignas(32) double f[GRADIENT_CELL_SIZE];
            gradient_cell(k1 - k, pb->P + 9 * (size_t)k, p->F + 9 * (size_t)k, st->f1d + 18 * (size_t)k,
                          p->vol + k, dt, f, pb->gradient_kernel);
            /* node ids: the first particle's; where its weight is 0, another's */
            const int *node = st->node + 27 * (size_t)k;
            for (int t = 0; t < 27; ++t) {
                int i = node[t];
                for (int kk = k + 1; i < 0 && kk < k1; ++kk) i = st->node[27 * (size_t)kk + t];
                if (i < 0) continue;
                const double *ft = f + 12 * (t / 3) + t % 3;
                grad[3 * i] += ft[0];
                grad[3 * i + 1] += ft[4];
                grad[3 * i + 2] += ft[8];
            }
        }
    }
    halo_sum(pb, grad, 3);
    zero_ghosts(pb, grad, 3);
    problem_project(pb, grad);
}

double *problem_tangent_storage(StepProblem *pb)
{
    size_t n = pb->parts->n;
    if (n > pb->cap_A) {
        size_t c = n + n / 4 + 256;
        if (grow((void **)&pb->A, sizeof(double) * 81 * c)) return NULL;
        pb->cap_A = c;
    }
    return pb->A;
}

/* The tangent of particles [k0, k1) into A (81 numbers each): four at a
 * time in the SIMD lanes of the SVD and of the rank-9 sum (core/fcr4.h;
 * the scalar fcr_dPdF's bits), the last (k1 - k0) mod 4 alone. */
static void tangent_range(const StepProblem *pb, int projected, size_t k0, size_t k1, double *A)
{
    size_t k = k0;
    for (; k + 4 <= k1; k += 4)
        fcr_dPdF4(pb->F + 9 * k, pb->mu + k, pb->lambda + k, projected, A + 81 * (k - k0), pb->stress_kernel);
    for (; k < k1; ++k) fcr_dPdF(pb->F + 9 * k, pb->mu[k], pb->lambda[k], projected, A + 81 * (k - k0));
}

int problem_tangent(StepProblem *pb, int projected)
{
    const size_t n = pb->parts->n;
    if (!problem_tangent_storage(pb)) return MPM_EINTERNAL;
#pragma omp parallel for schedule(static)
    for (size_t k0 = 0; k0 < n; k0 += 4) /* groups of four; the last may be shorter */
        tangent_range(pb, projected, k0, k0 + 4 < n ? k0 + 4 : n, pb->A + 81 * k0);
    pb->tangent_projected = projected;
    pb->tangent_stored = 1;
    return MPM_OK;
}

/* hessvec and diagonal after a fused assembly (or none): the tangent is
 * computed here; if that fails, y is NaN so the solve stops as a
 * numerical breakdown instead of reading a stale tangent. */
static int tangent_for_products(StepProblem *pb)
{
    return pb->tangent_stored ? MPM_OK : problem_tangent(pb, pb->tangent_projected);
}

/* B_s[a][3c+d] = sum_b A[(a,b),(c,d)] a_s(b): the particle tangent contracted
 * with one node's a-vector (3 x 9). */
static inline void contract_left(const double *A, const double as[3], double B[27])
{
    for (int al = 0; al < 3; ++al) {
        const double *r0 = A + 9 * (3 * al), *r1 = r0 + 9, *r2 = r1 + 9;
        double *Bo = B + 9 * al;
        for (int e = 0; e < 9; ++e) Bo[e] = r0[e] * as[0] + r1[e] * as[1] + r2[e] * as[2];
    }
}

/* K[a][c] = sum_d B[a][3c+d] a_t(d) */
static inline void contract_right(const double B[27], const double at[3], double s, double K[9])
{
    for (int al = 0; al < 3; ++al)
        for (int c = 0; c < 3; ++c) {
            const double *b = B + 9 * al + 3 * c;
            K[3 * al + c] = s * (b[0] * at[0] + b[1] * at[1] + b[2] * at[2]);
        }
}

/* The offsets (s, t) a particle touching every node of its stencil adds to
 * row s's neighbour mask, for each s. */
static void full_stencil_masks(uint64_t full[27][2])
{
    for (int s = 0; s < 27; ++s) {
        full[s][0] = full[s][1] = 0;
        for (int t = 0; t < 27; ++t) {
            int o = g_pair_offset[s][t];
            full[s][o >> 6] |= 1ull << (o & 63);
        }
    }
}

static inline int floor4(int v) { return v >= 0 ? v / 4 : -((3 - v) / 4); }

static int build_pattern(StepProblem *pb, Bsr *H)
{
    const Stencils *st = pb->st;
    const Grid *g = pb->grid;
    int n = pb->n_nodes;
    memset(pb->rowmask, 0, sizeof(uint64_t) * 2 * (size_t)n);
    uint64_t full[27][2];
    full_stencil_masks(full);
    MPM_FOR_EACH_COLORED_BLOCK(&st->pcolor, q, k0, kend) {
        /* one pass per cell, not per particle: the particles of a cell
         * (same base node, consecutive, the runs problem_assemble sums)
         * share their 27 nodes, and the pattern holds every pair of the
         * cell's node union, the blocks scatter_cell adds to (a node is
         * missing from a particle's stencil only where its weight is
         * exactly 0) */
        MPM_FOR_EACH_CELL(st->base, k0, kend, k, k1) {
            int node[27];
            memcpy(node, st->node + 27 * (size_t)k, sizeof node);
            for (int kk = k + 1; kk < k1; ++kk)
                for (int t = 0; t < 27; ++t)
                    if (node[t] < 0) node[t] = st->node[27 * (size_t)kk + t];
            int all = 1;
            for (int t = 0; t < 27; ++t) all &= node[t] >= 0;
            for (int s = 0; s < 27; ++s) {
                int i = node[s];
                if (i < 0) continue;
                uint64_t *rm = pb->rowmask + 2 * (size_t)i;
                if (all) {
                    rm[0] |= full[s][0];
                    rm[1] |= full[s][1];
                    continue;
                }
                for (int t = 0; t < 27; ++t) {
                    if (node[t] < 0) continue;
                    int o = g_pair_offset[s][t];
                    rm[o >> 6] |= 1ull << (o & 63);
                }
            }
        }
    }
    /* every row holds its diagonal block, which carries the mass and I - P:
     * over ranks an owned node only other ranks' particles reach has no
     * block of this rank's particles (on one process a no-op) */
    const int centre = 25 * 2 + 5 * 2 + 2;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) pb->rowmask[2 * (size_t)i + (centre >> 6)] |= 1ull << (centre & 63);
    /* row pointers */
    int status = bsr_reserve(H, n, 0);
    if (status) return status;
    H->row_ptr[0] = 0;
    for (int i = 0; i < n; ++i)
        H->row_ptr[i + 1] = H->row_ptr[i] + __builtin_popcountll(pb->rowmask[2 * i]) +
                            __builtin_popcountll(pb->rowmask[2 * i + 1]);
    if ((status = bsr_reserve(H, n, H->row_ptr[n]))) return status;
    H->nnzb = H->row_ptr[n];
    /* columns sorted by node id; slot table maps offsets to row positions.
     * Row i's neighbours (offsets -2..2 per axis) lie in at most 2x2x2 node
     * blocks: find those once, visit them by increasing block_first and
     * their window's nodes by increasing local index, which is increasing
     * node id (grid.h), so no per-neighbour hash lookup and no sort. */
#pragma omp parallel for schedule(dynamic, 64)
    for (int i = 0; i < n; ++i) {
        const int *ci = g->coord + 3 * (size_t)i;
        const uint64_t *rm = pb->rowmask + 2 * (size_t)i;
        short *slot = pb->slot + NEIGH * (size_t)i;
        for (int o = 0; o < NEIGH; ++o) slot[o] = -1;
        int lo[3], nb[3];
        for (int d = 0; d < 3; ++d) {
            lo[d] = floor4(ci[d] - 2);
            nb[d] = floor4(ci[d] + 2) - lo[d] + 1;
        }
        int blk[8], nblk = 0, B[8][3];
        for (int x = 0; x < nb[0]; ++x)
            for (int y = 0; y < nb[1]; ++y)
                for (int z = 0; z < nb[2]; ++z) {
                    int c[3] = {lo[0] + x, lo[1] + y, lo[2] + z}, b = grid_block(g, c);
                    if (b < 0) continue;
                    /* insertion by block_first (at most 8) */
                    int pos = nblk++;
                    while (pos > 0 && g->block_first[blk[pos - 1]] > g->block_first[b]) {
                        blk[pos] = blk[pos - 1];
                        memcpy(B[pos], B[pos - 1], sizeof B[pos]);
                        --pos;
                    }
                    blk[pos] = b;
                    memcpy(B[pos], c, sizeof c);
                }
        int64_t r0 = H->row_ptr[i];
        int m = 0;
        for (int q = 0; q < nblk; ++q) {
            const uint64_t mask = g->block_mask[blk[q]];
            const int first = g->block_first[blk[q]];
            int a0[3], a1[3]; /* the window's local coordinates in this block */
            for (int d = 0; d < 3; ++d) {
                a0[d] = ci[d] - 2 - 4 * B[q][d];
                a1[d] = ci[d] + 2 - 4 * B[q][d];
                if (a0[d] < 0) a0[d] = 0;
                if (a1[d] > 3) a1[d] = 3;
            }
            for (int x = a0[0]; x <= a1[0]; ++x)
                for (int y = a0[1]; y <= a1[1]; ++y)
                    for (int z = a0[2]; z <= a1[2]; ++z) {
                        int l = x << 4 | y << 2 | z;
                        if (!((mask >> l) & 1u)) continue;
                        int o = 25 * (4 * B[q][0] + x - ci[0] + 2) + 5 * (4 * B[q][1] + y - ci[1] + 2) +
                                (4 * B[q][2] + z - ci[2] + 2);
                        if (!((rm[o >> 6] >> (o & 63)) & 1u)) continue;
                        H->col[r0 + m] = first + __builtin_popcountll(mask & ((1ull << l) - 1));
                        slot[o] = (short)m++;
                    }
        }
    }
    bsr_update_pattern_id(H);
    pb->pattern_ready = 1;
    return MPM_OK;
}

/* Applies P_i (.) P_j to block B (row i, column j) in place. */
static inline void project_block(const StepProblem *pb, int i, int j, double *B)
{
    unsigned char bi = pb->bc[i], bj = pb->bc[j];
    if (bi == BC_STICKY || bj == BC_STICKY) {
        memset(B, 0, 9 * sizeof(double));
        return;
    }
    if (bi == BC_SLIP) m3_mul(pb->bc_P + 9 * (size_t)i, B, B);
    if (bj == BC_SLIP) m3_mul(B, pb->bc_P + 9 * (size_t)j, B);
}

/* Adds I - P_i to a diagonal block (BC-projected Hessian). */
static inline void add_complement(const StepProblem *pb, int i, double *B)
{
    unsigned char b = pb->bc[i];
    if (b == BC_FREE) return;
    if (b == BC_STICKY) {
        B[0] += 1.0;
        B[4] += 1.0;
        B[8] += 1.0;
        return;
    }
    const double *P = pb->bc_P + 9 * (size_t)i;
    for (int e = 0; e < 9; ++e) B[e] += ((e % 4 == 0) ? 1.0 : 0.0) - P[e];
}

/* Adds a cell's stiffness (core/hessian_cell.h layout) into the upper
 * triangle of H by node id: the pair (s, t), t >= s, of nodes (i, j) adds
 * K_st to block (i, j) if i <= j, else K_st^T to block (j, i). Half the
 * blocks of a full scatter; finish_row mirrors them once at the end. The
 * destinations are found first and prefetched (the cell's blocks lie in 27
 * rows of a matrix far larger than the caches: the adds wait on memory, not
 * on arithmetic), then added. */
static void scatter_cell(const StepProblem *pb, Bsr *H, const int node[27], const double *K)
{
    int64_t dst[378];
    short src[378]; /* HESSIAN_CELL_LD-strided offset of the pair's first entry in K; < 0: transposed */
    int n = 0;
    for (int si = 0; si < 27; ++si) {
        int i = node[si];
        if (i < 0) continue;
        for (int ti = si; ti < 27; ++ti) {
            int j = node[ti];
            if (j < 0) continue;
            int swap = i > j, row = swap ? j : i;
            int o = swap ? g_pair_offset[ti][si] : g_pair_offset[si][ti];
            int64_t b = 9 * (H->row_ptr[row] + pb->slot[NEIGH * (size_t)row + o]);
            __builtin_prefetch(H->val + b, 1);
            __builtin_prefetch(H->val + b + 8, 1);
            dst[n] = b;
            int off = 9 * HESSIAN_CELL_LD * si + ti;
            src[n++] = (short)(swap ? -1 - off : off);
        }
    }
    for (int m = 0; m < n; ++m) {
        double *Hb = H->val + dst[m];
        if (src[m] >= 0) {
            const double *k = K + src[m];
            for (int e = 0; e < 9; ++e) Hb[e] += k[HESSIAN_CELL_LD * e];
        } else {
            const double *k = K + (-1 - src[m]);
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) Hb[3 * r + c] += k[HESSIAN_CELL_LD * (3 * c + r)];
        }
    }
}

/* Row i after the scatter: adds the mass to the diagonal block, applies
 * the BC projection P_i B P_j (+ I - P_i on the diagonal) to the blocks
 * (i, j >= i) and writes their transposes into the blocks (j, i): H is
 * symmetric, and (P_i B P_j)^T = P_j B^T P_i. Rows touch disjoint blocks. */
static void finish_row(const StepProblem *pb, Bsr *H, int i)
{
    const int *ci = pb->grid->coord + 3 * (size_t)i;
    for (int64_t k = H->row_ptr[i]; k < H->row_ptr[i + 1]; ++k) {
        int j = H->col[k];
        if (j < i) continue;
        double *B = H->val + 9 * k;
        if (j == i) {
            double m = pb->grid->mass[i];
            B[0] += m;
            B[4] += m;
            B[8] += m;
        }
        if (pb->bc[i] != BC_FREE || pb->bc[j] != BC_FREE) project_block(pb, i, j, B);
        if (j == i) {
            /* over ranks the owner alone adds I - P: the ghosts' rows are partial sums */
            if (!pb->comm || pb->owned[i]) add_complement(pb, i, B);
            continue;
        }
        /* offset of i seen from j (the slot table's index of -d) */
        const int *cj = pb->grid->coord + 3 * (size_t)j;
        int o = 25 * (ci[0] - cj[0] + 2) + 5 * (ci[1] - cj[1] + 2) + (ci[2] - cj[2] + 2);
        double *Bt = H->val + 9 * (H->row_ptr[j] + pb->slot[NEIGH * (size_t)j + o]);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) Bt[3 * c + r] = B[3 * r + c];
    }
}

/* The Hessian's blocks (i, j >= i) from the particles' tangents: pb->A
 * when fused is 0, otherwise computed particle block by particle block into
 * a per-thread buffer that stays in cache (the same values: fcr_dPdF's). */
static int assemble_cells(StepProblem *pb, Bsr *H, int fused, int projected)
{
    const Stencils *st = pb->st;
    const Particles *p = pb->parts;
    const double dt2 = pb->dt * pb->dt;
    int oom = 0;
#pragma omp parallel
    {
        /* particles sharing a base node share all 27 stencil nodes: sum
         * them in a dense cell buffer, scatter once per cell */
        static _Thread_local _Alignas(32) double Kloc[HESSIAN_CELL_SIZE]; /* no allocation per call */
        double *Ablock = NULL;
        size_t cap = 0;
        int failed = 0;
        /* chunks of 2, not 4: a block's tangents and cell kernels outweigh other scatters' blocks */
        MPM_FOR_EACH_COLORED_BLOCK_IN_TEAM(&st->pcolor, 2, q, k0, kend) {
            const double *A0 = pb->A ? pb->A + 81 * (size_t)k0 : NULL;
            if (fused) {
                size_t need = (size_t)(kend - k0);
                if (need > cap) {
                    double *grown = realloc(Ablock, sizeof(double) * 81 * need);
                    if (!grown) {
                        failed = 1;
                        continue;
                    }
                    Ablock = grown;
                    cap = need;
                }
                tangent_range(pb, projected, (size_t)k0, (size_t)kend, Ablock);
                A0 = Ablock;
            }
            MPM_FOR_EACH_CELL(st->base, k0, kend, k, k1) {
                hessian_cell(k1 - k, A0 + 81 * (size_t)(k - k0), pb->a + 81 * (size_t)k, p->vol + k, dt2, Kloc,
                             pb->cell_kernel);
                /* node ids of the cell: union over its particles (a node
                 * is -1 only where every weight vanishes) */
                int node[27];
                memcpy(node, st->node + 27 * (size_t)k, sizeof node);
                for (int kk = k + 1; kk < k1; ++kk)
                    for (int t = 0; t < 27; ++t)
                        if (node[t] < 0) node[t] = st->node[27 * (size_t)kk + t];
                scatter_cell(pb, H, node, Kloc);
            }
        }
        free(Ablock);
        if (failed) {
#pragma omp atomic write
            oom = 1;
        }
    }
    if (oom) return mpm_error(MPM_EINTERNAL, "out of memory: tangents of a particle block in the assembly");
    return MPM_OK;
}

static int assemble(StepProblem *pb, Bsr *H, int fused, int projected)
{
    int status;
    if (!pb->pattern_ready || H->n != pb->n_nodes) {
        if ((status = build_pattern(pb, H))) return status;
    }
    /* zero the blocks (i, j >= i), the row's tail (sorted columns); finish_row writes the others */
#pragma omp parallel for schedule(static)
    for (int i = 0; i < pb->n_nodes; ++i) {
        int64_t kd = H->row_ptr[i];
        while (kd < H->row_ptr[i + 1] && H->col[kd] < i) ++kd;
        memset(H->val + 9 * kd, 0, sizeof(double) * 9 * (size_t)(H->row_ptr[i + 1] - kd));
    }
    if ((status = assemble_cells(pb, H, fused, projected))) return status;
#pragma omp parallel for schedule(dynamic, 64)
    for (int i = 0; i < pb->n_nodes; ++i) finish_row(pb, H, i);
    return MPM_OK;
}

int problem_assemble(StepProblem *pb, Bsr *H)
{
    if (!pb->tangent_stored)
        return mpm_error(MPM_EINTERNAL, "problem_assemble: no tangent stored (problem_tangent first)");
    return assemble(pb, H, 0, pb->tangent_projected);
}

int problem_assemble_fused(StepProblem *pb, int projected, Bsr *H)
{
    pb->tangent_stored = 0; /* pb->A is not updated */
    pb->tangent_projected = projected;
    return assemble(pb, H, 1, projected);
}

void problem_assembled_product(StepProblem *pb, const Bsr *H, const double *x_in, double *y)
{
    bsr_spmv(H, with_ghosts(pb, x_in), y);
    halo_sum(pb, y, 3); /* the ghosts' rows are partial sums: their owners add them */
    zero_ghosts(pb, y, 3);
}

/* A ghost's block is the identity: an inverse of it stays finite and leaves zeros zero. */
static void identity_at_ghosts(const StepProblem *pb, double *D)
{
    if (!pb->comm) return;
    for (int i = 0; i < pb->n_nodes; ++i)
        if (!pb->owned[i]) {
            double *Di = D + 9 * (size_t)i;
            memset(Di, 0, 9 * sizeof(double));
            Di[0] = Di[4] = Di[8] = 1.0;
        }
}

void problem_assembled_diagonal(StepProblem *pb, const Bsr *H, double *D)
{
    bsr_diagonal(H, D);
    /* projected blocks sum to the projected sum (P_i is every rank's), and
     * only the owner's row holds I - P */
    halo_sum(pb, D, 9);
    identity_at_ghosts(pb, D);
}

void problem_hessvec(StepProblem *pb, const double *x_in, double *y)
{
    const double *x = with_ghosts(pb, x_in);
    const Stencils *st = pb->st;
    const Particles *p = pb->parts;
    const double *m = pb->grid->mass;
    double dt2 = pb->dt * pb->dt;
    int n = pb->n_nodes;
    if (tangent_for_products(pb)) {
        for (size_t e = 0; e < 3 * (size_t)n; ++e) y[e] = NAN;
        return;
    }
    const double *xp = x;
    if (pb->n_dirichlet) {
        memcpy(pb->tmp, x, sizeof(double) * 3 * (size_t)n);
        problem_project(pb, pb->tmp);
        xp = pb->tmp;
    }
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) y[3 * i + d] = m[i] * xp[3 * i + d];
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const int *node = st->node + 27 * (size_t)k;
        const double *a = pb->a + 81 * (size_t)k, *A = pb->A + 81 * (size_t)k;
        /* dF = sum_j x_j a_j^T (SPEC 3 "G2P of x") */
        double G[9] = {0};
        for (int t = 0; t < 27; ++t) {
            int j = node[t];
            if (j < 0) continue;
            const double *xj = xp + 3 * (size_t)j, *at = a + 3 * t;
            for (int r = 0; r < 3; ++r)
                for (int cc = 0; cc < 3; ++cc) G[3 * r + cc] += xj[r] * at[cc];
        }
        double dP[9];
        for (int e = 0; e < 9; ++e) {
            const double *row = A + 9 * e;
            double s = 0.0;
            for (int f = 0; f < 9; ++f) s += row[f] * G[f];
            dP[e] = s;
        }
        double s = dt2 * p->vol[k];
        for (int t = 0; t < 27; ++t) {
            int i = node[t];
            if (i < 0) continue;
            double f[3];
            m3_mulv(dP, a + 3 * t, f);
            y[3 * i] += s * f[0];
            y[3 * i + 1] += s * f[1];
            y[3 * i + 2] += s * f[2];
        }
    }
    halo_sum(pb, y, 3); /* before the constraints: they act once, at the owner */
    if (pb->n_dirichlet) {
#pragma omp parallel for schedule(static)
        for (int i = 0; i < n; ++i) {
            if (pb->bc[i] == BC_FREE) continue;
            double *yi = y + 3 * (size_t)i;
            const double *xi = x + 3 * (size_t)i;
            project_node(pb, i, yi);
            if (pb->bc[i] == BC_STICKY) {
                yi[0] = xi[0];
                yi[1] = xi[1];
                yi[2] = xi[2];
            } else {
                double px[3];
                m3_mulv(pb->bc_P + 9 * (size_t)i, xi, px);
                for (int d = 0; d < 3; ++d) yi[d] += xi[d] - px[d];
            }
        }
    }
    zero_ghosts(pb, y, 3);
}

void problem_diagonal(StepProblem *pb, double *D)
{
    const Stencils *st = pb->st;
    const Particles *p = pb->parts;
    const double *m = pb->grid->mass;
    double dt2 = pb->dt * pb->dt;
    int n = pb->n_nodes;
    if (tangent_for_products(pb)) {
        for (size_t e = 0; e < 9 * (size_t)n; ++e) D[e] = NAN;
        return;
    }
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
        double *Di = D + 9 * (size_t)i;
        memset(Di, 0, 9 * sizeof(double));
        Di[0] = Di[4] = Di[8] = m[i];
    }
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const int *node = st->node + 27 * (size_t)k;
        const double *a = pb->a + 81 * (size_t)k, *A = pb->A + 81 * (size_t)k;
        double s = dt2 * p->vol[k];
        for (int t = 0; t < 27; ++t) {
            int i = node[t];
            if (i < 0) continue;
            double B[27], K[9];
            contract_left(A, a + 3 * t, B);
            contract_right(B, a + 3 * t, s, K);
            double *Di = D + 9 * (size_t)i;
            for (int e = 0; e < 9; ++e) Di[e] += K[e];
        }
    }
    halo_sum(pb, D, 9); /* before the constraints: they act once, at the owner */
    if (pb->n_dirichlet) {
#pragma omp parallel for schedule(static)
        for (int i = 0; i < n; ++i) {
            if (pb->bc[i] == BC_FREE) continue;
            double *Di = D + 9 * (size_t)i;
            project_block(pb, i, i, Di);
            add_complement(pb, i, Di);
        }
    }
    identity_at_ghosts(pb, D);
}

void problem_mark_dirichlet(StepProblem *pb, DirichletFn fn, const void *ctx)
{
    pb->dirichlet_fn = fn;
    pb->dirichlet_ctx = ctx;
    if (fn) {
        const Grid *g = pb->grid;
        double dx = g->dx;
#pragma omp parallel for schedule(dynamic, 256)
        for (int i = 0; i < g->n; ++i) {
            double x[3] = {g->coord[3 * i] * dx, g->coord[3 * i + 1] * dx, g->coord[3 * i + 2] * dx};
            fn(ctx, pb, i, x);
        }
    }
    problem_finish_dirichlet(pb);
}

void problem_finish_dirichlet(StepProblem *pb)
{
    int count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (int i = 0; i < pb->n_nodes; ++i) count += pb->bc[i] != BC_FREE;
    pb->n_dirichlet = count;
}

typedef struct {
    const double *g, *kappa;
} CnArgs;

static double cn_range(const void *ctx, size_t begin, size_t end)
{
    const CnArgs *ca = ctx;
    const double *g = ca->g, *kappa = ca->kappa;
    double s = 0.0;
    for (size_t i = begin; i < end; ++i) {
        const double *gi = g + 3 * i;
        double k = kappa[i];
        s += (gi[0] * gi[0] + gi[1] * gi[1] + gi[2] * gi[2]) / (k * k);
    }
    return s;
}

double problem_cn_residual(const StepProblem *pb, const double *g)
{
    if (pb->n_nodes <= 0 && !pb->comm) return 0.0; /* a rank without nodes still takes part in the sum */
    CnArgs ca = {g, pb->kappa};
    double sum = reduce_sum((size_t)pb->n_nodes, 1024, cn_range, &ca);
    if (!pb->comm) return sqrt(sum / pb->n_nodes);
    /* ghosts hold zeros: the local sum is the owned nodes' share */
    StepProblem *mut = (StepProblem *)pb; /* the failure flag only */
    const double total = ranks_sum(mut, sum);
    return pb->n_global > 0 ? sqrt(total / pb->n_global) : 0.0; /* no node on any rank: as one process */
}

double problem_tau(const StepProblem *pb, double eps)
{
    double n = pb->comm ? pb->n_global : (double)pb->n_nodes;
    return eps * pb->dt * 24.0 * sqrt(n) * pb->dx * pb->dx * pb->max_stiffness;
}

void problem_free(StepProblem *pb)
{
    free(pb->a);
    free(pb->mu);
    free(pb->lambda);
    free(pb->stiff);
    free(pb->bc);
    free(pb->bc_P);
    free(pb->dv0);
    free(pb->kappa);
    free(pb->F);
    free(pb->P);
    free(pb->A);
    free(pb->slot);
    free(pb->rowmask);
    free(pb->tmp);
    free(pb->halo);
    memset(pb, 0, sizeof *pb);
}
