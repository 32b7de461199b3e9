#include "core/transfer_blocked.h"

#include <string.h>

#include "core/block_traversal.h"
#include "core/kernel.h"
#include "core/mat3.h"

#define ARENA 6 /* a 4-node block plus the stencil's reach of 2 */
#define ARENA_N (ARENA * ARENA * ARENA)

void transfer_p2g_blocked(Grid *g, const Stencils *st, const Particles *p, const ExplicitForce *force,
                          TransferKind kind)
{
    const int n = g->n, mls = kind == TRANSFER_MLS;
    const double dx = g->dx, inv_dx = 1.0 / dx, dinv = 4.0 / (dx * dx);
    if (n == 0) return;
    memset(g->mass, 0, sizeof(double) * (size_t)n);
    memset(g->v, 0, sizeof(double) * 3 * (size_t)n);
    MPM_FOR_EACH_COLORED_BLOCK(&st->pcolor, q, k0, k1) {
        if (k0 == k1) continue;
        /* mass and momentum, node-major: 4 doubles per arena node (7 KB) */
        double arena[ARENA_N][4];
        memset(arena, 0, sizeof arena);
        const int *b0 = st->base + 3 * (size_t)k0;
        const int o[3] = {b0[0] & ~3, b0[1] & ~3, b0[2] & ~3}; /* the block's first node */
        for (int k = k0; k < k1; ++k) {
            const double *xp = p->x + 3 * (size_t)k, *vp = p->v + 3 * (size_t)k, *Cp = p->C + 9 * (size_t)k;
            const int *base = st->base + 3 * (size_t)k;
            double N[3][3], dN[3][3];
            for (int d = 0; d < 3; ++d) bspline2_1d(xp[d], inv_dx, N[d], dN[d]);
            const double mp = p->mass[k];
            double A[9], K[9] = {0}, mv[3] = {mp * vp[0], mp * vp[1], mp * vp[2]};
            if (force) transfer_explicit_stress(force, p, (size_t)k, K);
            if (mls) /* Q_p = m_p C_p - dt V_p D_p^-1 P F^T (supplement 3.1) */
                for (int e = 0; e < 9; ++e) A[e] = mp * Cp[e] - (force ? force->dt * dinv * K[e] : 0.0);
            else
                for (int e = 0; e < 9; ++e) A[e] = Cp[e], K[e] *= force ? -force->dt : 0.0;
            const int l0 = ((base[0] - o[0]) * ARENA + (base[1] - o[1])) * ARENA + (base[2] - o[2]);
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    for (int cc = 0; cc < 3; ++cc) {
                        double *gi = arena[l0 + (a * ARENA + b) * ARENA + cc];
                        const double w = N[0][a] * N[1][b] * N[2][cc];
                        const double r[3] = {(base[0] + a) * dx - xp[0], (base[1] + b) * dx - xp[1],
                                             (base[2] + cc) * dx - xp[2]};
                        double u[3];
                        m3_mulv(A, r, u);
                        if (mls) {
                            gi[0] += w * mp;
                            for (int d = 0; d < 3; ++d) gi[1 + d] += w * (mv[d] + u[d]);
                        } else {
                            const double gw[3] = {dN[0][a] * N[1][b] * N[2][cc], N[0][a] * dN[1][b] * N[2][cc],
                                                  N[0][a] * N[1][b] * dN[2][cc]};
                            double f[3];
                            m3_mulv(K, gw, f);
                            const double wm = w * mp;
                            gi[0] += wm;
                            for (int d = 0; d < 3; ++d) gi[1 + d] += wm * (vp[d] + u[d]) + f[d];
                        }
                    }
        }
        /* one add per touched node; a node outside the active set (none
         * with mass) is skipped as the plain kernels skip node < 0 */
        for (int l = 0; l < ARENA_N; ++l) {
            if (arena[l][0] == 0.0) continue;
            const int cn[3] = {o[0] + l / (ARENA * ARENA), o[1] + (l / ARENA) % ARENA, o[2] + l % ARENA};
            const int i = grid_lookup(g, cn);
            if (i < 0) continue;
            g->mass[i] += arena[l][0];
            for (int d = 0; d < 3; ++d) g->v[3 * (size_t)i + d] += arena[l][1 + d];
        }
    }
    transfer_normalise_grid_velocity(g, force);
}
