#include "core/transfer.h"

#include <string.h>

#include "core/mat3.h"

void transfer_p2g(Grid *g, const Stencils *st, const Particles *p)
{
    int n = g->n;
    double dx = g->dx;
    if (n == 0) return; /* no particles: no nodes (and possibly no arrays yet) */
    memset(g->mass, 0, sizeof(double) * (size_t)n);
    memset(g->v, 0, sizeof(double) * 3 * (size_t)n);
    const NodeColoring *pc = &st->pcolor;
    for (int c = 0; c < MPM_NUM_COLORS; ++c) {
#pragma omp parallel for schedule(dynamic, 4)
        for (int qi = pc->color_start[c]; qi < pc->color_start[c + 1]; ++qi) {
            int q = pc->color_blocks[qi];
            for (int k = pc->block_start[q]; k < pc->block_start[q + 1]; ++k) {
                const double *xp = p->x + 3 * (size_t)k, *vp = p->v + 3 * (size_t)k, *Cp = p->C + 9 * (size_t)k;
                const int *base = st->base + 3 * (size_t)k;
                const int *node = st->node + MPM_STENCIL * (size_t)k;
                const double *w = st->w + MPM_STENCIL * (size_t)k;
                double mp = p->mass[k];
                for (int s = 0; s < MPM_STENCIL; ++s) {
                    int i = node[s];
                    if (i < 0) continue;
                    double r[3] = {(base[0] + s / 9) * dx - xp[0], (base[1] + (s / 3) % 3) * dx - xp[1],
                                   (base[2] + s % 3) * dx - xp[2]};
                    double u[3];
                    m3_mulv(Cp, r, u);
                    double wm = w[s] * mp;
                    g->mass[i] += wm;
                    g->v[3 * i] += wm * (vp[0] + u[0]);
                    g->v[3 * i + 1] += wm * (vp[1] + u[1]);
                    g->v[3 * i + 2] += wm * (vp[2] + u[2]);
                }
            }
        }
    }
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
        double inv = 1.0 / g->mass[i]; /* active nodes have positive mass by construction */
        g->v[3 * i] *= inv;
        g->v[3 * i + 1] *= inv;
        g->v[3 * i + 2] *= inv;
    }
}

void transfer_g2p_opts(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                       const G2POptions *opt)
{
    double dx = g->dx, dinv = 4.0 / (dx * dx);
    const int pic_flip = opt->kind == TRANSFER_PIC_FLIP, advect = opt->advect;
    double sym = 0.5 * (opt->apic_ratio + 1.0), skew = 0.5 * (opt->apic_ratio - 1.0);
    double alpha = opt->flip_alpha;
    const double *vold = g->v; /* v^n of the P2G, for the FLIP increment */
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < p->n; ++k) {
        double *xp = p->x + 3 * k;
        const int *base = st->base + 3 * k;
        const int *node = st->node + MPM_STENCIL * k;
        const double *w = st->w + MPM_STENCIL * k, *dw = st->dw + 3 * MPM_STENCIL * k;
        double v[3] = {0, 0, 0}, B[9] = {0}, G[9] = {0}, dvw[3] = {0, 0, 0};
        for (int s = 0; s < MPM_STENCIL; ++s) {
            int i = node[s];
            if (i < 0) continue;
            const double *vi = vnew + 3 * (size_t)i;
            double r[3] = {(base[0] + s / 9) * dx - xp[0], (base[1] + (s / 3) % 3) * dx - xp[1],
                           (base[2] + s % 3) * dx - xp[2]};
            for (int a = 0; a < 3; ++a) {
                v[a] += w[s] * vi[a];
                for (int b = 0; b < 3; ++b) {
                    B[3 * a + b] += w[s] * vi[a] * r[b];
                    G[3 * a + b] += vi[a] * dw[3 * s + b];
                }
            }
            if (pic_flip)
                for (int a = 0; a < 3; ++a) dvw[a] += w[s] * (vi[a] - vold[3 * (size_t)i + a]);
        }
        double *C = p->C + 9 * k;
        if (pic_flip) {
            /* Gast et al. 2015 section 6.1 step 5: v_FLIP = v_p^n + sum w (v^{n+1} - v^n) */
            double *vp = p->v + 3 * k;
            for (int a = 0; a < 3; ++a) vp[a] = alpha * (vp[a] + dvw[a]) + (1.0 - alpha) * v[a];
            memset(C, 0, 9 * sizeof(double));
        } else {
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) C[3 * a + b] = dinv * (sym * B[3 * a + b] + skew * B[3 * b + a]);
            memcpy(p->v + 3 * k, v, sizeof v);
        }
        if (advect)
            for (int d = 0; d < 3; ++d) xp[d] += dt * v[d];
        double Fn[9], L[9];
        m3_copy(Fn, p->F + 9 * k);
        for (int e = 0; e < 9; ++e) L[e] = dt * G[e];
        L[0] += 1.0;
        L[4] += 1.0;
        L[8] += 1.0;
        m3_mul(L, Fn, p->F + 9 * k);
    }
}

void transfer_g2p(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                  double apic_ratio)
{
    G2POptions opt = {.kind = TRANSFER_APIC, .apic_ratio = apic_ratio, .flip_alpha = 0.0, .advect = 1};
    transfer_g2p_opts(g, st, p, vnew, dt, &opt);
}

void transfer_volumes_from_density(const Grid *g, const Stencils *st, Particles *p)
{
    /* rho_p = sum_i w_ip m_i / dx^3, V_p = m_p / rho_p (Gast 6.1 step 2) */
    double cell = g->dx * g->dx * g->dx;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < p->n; ++k) {
        const int *node = st->node + MPM_STENCIL * k;
        const double *w = st->w + MPM_STENCIL * k;
        double wm = 0.0;
        for (int s = 0; s < MPM_STENCIL; ++s)
            if (node[s] >= 0) wm += w[s] * g->mass[node[s]];
        /* wm > 0: m_i >= w_ip m_p (the particle's own share), so wm >= m_p sum_i w_ip^2 */
        p->vol[k] = p->mass[k] * cell / wm;
    }
}
