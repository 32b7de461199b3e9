#include "core/transfer.h"

#include <string.h>

#include "core/block_traversal.h"
#include "core/mat3.h"

void transfer_p2g(Grid *g, const Stencils *st, const Particles *p)
{
    int n = g->n;
    double dx = g->dx;
    if (n == 0) return; /* no particles: no nodes (and possibly no arrays yet) */
    memset(g->mass, 0, sizeof(double) * (size_t)n);
    memset(g->v, 0, sizeof(double) * 3 * (size_t)n);
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const double *xp = p->x + 3 * (size_t)k, *vp = p->v + 3 * (size_t)k, *Cp = p->C + 9 * (size_t)k;
        const int *base = st->base + 3 * (size_t)k;
        const int *node = st->node + MPM_STENCIL * (size_t)k;
        double w[MPM_STENCIL];
        stencil_weights(st, (size_t)k, w, NULL);
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
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
        double inv = 1.0 / g->mass[i]; /* active nodes have positive mass by construction */
        g->v[3 * i] *= inv;
        g->v[3 * i + 1] *= inv;
        g->v[3 * i + 2] *= inv;
    }
}

/* v_i = (mv)_i / m_i (+ dt g with an explicit force). */
void transfer_normalise_grid_velocity(Grid *g, const ExplicitForce *force)
{
    double gdt[3] = {0, 0, 0};
    if (force)
        for (int d = 0; d < 3; ++d) gdt[d] = force->dt * force->gravity[d];
#pragma omp parallel for schedule(static)
    for (int i = 0; i < g->n; ++i) {
        double inv = 1.0 / g->mass[i]; /* active nodes have positive mass by construction */
        g->v[3 * i] = g->v[3 * i] * inv + gdt[0];
        g->v[3 * i + 1] = g->v[3 * i + 1] * inv + gdt[1];
        g->v[3 * i + 2] = g->v[3 * i + 2] * inv + gdt[2];
    }
}

/* Linear elasticity of the supplement's benchmark: K = V_p P F^T with
 * P = mu (F + F^T - 2 I) + lambda tr(F - I) I. */
void transfer_explicit_stress(const ExplicitForce *force, const Particles *p, size_t k, double K[9])
{
    const Material *m = &force->mats[p->mat[k]];
    const double *F = p->F + 9 * k;
    double P[9], Ft[9], tr = F[0] + F[4] + F[8] - 3.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) P[3 * a + b] = m->mu * (F[3 * a + b] + F[3 * b + a]) + (a == b ? m->lambda * tr - 2.0 * m->mu : 0.0);
    m3_transpose(F, Ft);
    m3_mul(P, Ft, K);
    for (int e = 0; e < 9; ++e) K[e] *= p->vol[k];
}

void transfer_p2g_apic_force(Grid *g, const Stencils *st, const Particles *p, const ExplicitForce *force)
{
    int n = g->n;
    double dx = g->dx;
    if (n == 0) return;
    memset(g->mass, 0, sizeof(double) * (size_t)n);
    memset(g->v, 0, sizeof(double) * 3 * (size_t)n);
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const double *xp = p->x + 3 * (size_t)k, *vp = p->v + 3 * (size_t)k, *Cp = p->C + 9 * (size_t)k;
        const int *base = st->base + 3 * (size_t)k;
        const int *node = st->node + MPM_STENCIL * (size_t)k;
        double w[MPM_STENCIL], dw[3 * MPM_STENCIL];
        stencil_weights(st, (size_t)k, w, dw);
        double mp = p->mass[k], K[9] = {0};
        if (force) {
            transfer_explicit_stress(force, p, (size_t)k, K);
            for (int e = 0; e < 9; ++e) K[e] *= -force->dt;
        }
        for (int s = 0; s < MPM_STENCIL; ++s) {
            int i = node[s];
            if (i < 0) continue;
            double r[3] = {(base[0] + s / 9) * dx - xp[0], (base[1] + (s / 3) % 3) * dx - xp[1],
                           (base[2] + s % 3) * dx - xp[2]};
            double u[3], f[3];
            m3_mulv(Cp, r, u);
            m3_mulv(K, dw + 3 * s, f);
            double wm = w[s] * mp;
            g->mass[i] += wm;
            g->v[3 * i] += wm * (vp[0] + u[0]) + f[0];
            g->v[3 * i + 1] += wm * (vp[1] + u[1]) + f[1];
            g->v[3 * i + 2] += wm * (vp[2] + u[2]) + f[2];
        }
    }
    transfer_normalise_grid_velocity(g, force);
}

void transfer_p2g_mls(Grid *g, const Stencils *st, const Particles *p, const ExplicitForce *force)
{
    int n = g->n;
    double dx = g->dx, dinv = 4.0 / (dx * dx);
    if (n == 0) return;
    memset(g->mass, 0, sizeof(double) * (size_t)n);
    memset(g->v, 0, sizeof(double) * 3 * (size_t)n);
    MPM_FOR_EACH_COLORED_PARTICLE(&st->pcolor, k) {
        const double *xp = p->x + 3 * (size_t)k, *vp = p->v + 3 * (size_t)k, *Cp = p->C + 9 * (size_t)k;
        const int *base = st->base + 3 * (size_t)k;
        const int *node = st->node + MPM_STENCIL * (size_t)k;
        double w[MPM_STENCIL];
        stencil_weights(st, (size_t)k, w, NULL);
        double mp = p->mass[k], Q[9], mv[3] = {mp * vp[0], mp * vp[1], mp * vp[2]};
        for (int e = 0; e < 9; ++e) Q[e] = mp * Cp[e];
        if (force) { /* Q_p = m_p C_p - dt V_p D_p^-1 P F^T (supplement 3.1) */
            double K[9];
            transfer_explicit_stress(force, p, (size_t)k, K);
            for (int e = 0; e < 9; ++e) Q[e] -= force->dt * dinv * K[e];
        }
        for (int s = 0; s < MPM_STENCIL; ++s) {
            int i = node[s];
            if (i < 0) continue;
            double r[3] = {(base[0] + s / 9) * dx - xp[0], (base[1] + (s / 3) % 3) * dx - xp[1],
                           (base[2] + s % 3) * dx - xp[2]};
            double u[3];
            m3_mulv(Q, r, u);
            g->mass[i] += w[s] * mp;
            g->v[3 * i] += w[s] * (mv[0] + u[0]);
            g->v[3 * i + 1] += w[s] * (mv[1] + u[1]);
            g->v[3 * i + 2] += w[s] * (mv[2] + u[2]);
        }
    }
    transfer_normalise_grid_velocity(g, force);
}

void transfer_g2p_opts(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                       const G2POptions *opt)
{
    double dx = g->dx, dinv = 4.0 / (dx * dx);
    const int pic_flip = opt->kind == TRANSFER_PIC_FLIP, mls = opt->kind == TRANSFER_MLS, advect = opt->advect;
    double sym = 0.5 * (opt->apic_ratio + 1.0), skew = 0.5 * (opt->apic_ratio - 1.0);
    double alpha = opt->flip_alpha;
    const double *vold = g->v; /* v^n of the P2G, for the FLIP increment */
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < p->n; ++k) {
        double *xp = p->x + 3 * k;
        const int *base = st->base + 3 * k;
        const int *node = st->node + MPM_STENCIL * k;
        /* the weights and gradients as stencil_weights builds them (the same
         * products, so the same bits), formed slot by slot in registers */
        const double *N = st->f1d + 18 * k, *D = N + 9;
        double v[3] = {0, 0, 0}, B[9] = {0}, G[9] = {0}, dvw[3] = {0, 0, 0};
        for (int oa = 0, s = 0; oa < 3; ++oa) {
            const double r0 = (base[0] + oa) * dx - xp[0];
            for (int ob = 0; ob < 3; ++ob) {
                const double r1 = (base[1] + ob) * dx - xp[1];
                const double nn = N[oa] * N[3 + ob], dn = D[oa] * N[3 + ob], nd = N[oa] * D[3 + ob];
                for (int oc = 0; oc < 3; ++oc, ++s) {
                    int i = node[s];
                    if (i < 0) continue;
                    const double *vi = vnew + 3 * (size_t)i;
                    const double r[3] = {r0, r1, (base[2] + oc) * dx - xp[2]};
                    const double ws = nn * N[6 + oc];
                    if (mls) /* no weight gradient: C'_p = 4/dx^2 B_p is the velocity gradient */
                        for (int a = 0; a < 3; ++a) {
                            double wv = ws * vi[a];
                            v[a] += wv;
                            for (int b = 0; b < 3; ++b) B[3 * a + b] += wv * r[b];
                        }
                    else {
                        const double dws[3] = {dn * N[6 + oc], nd * N[6 + oc], nn * D[6 + oc]};
                        for (int a = 0; a < 3; ++a) {
                            v[a] += ws * vi[a];
                            for (int b = 0; b < 3; ++b) {
                                B[3 * a + b] += ws * vi[a] * r[b];
                                G[3 * a + b] += vi[a] * dws[b];
                            }
                        }
                    }
                    if (pic_flip)
                        for (int a = 0; a < 3; ++a) dvw[a] += ws * (vi[a] - vold[3 * (size_t)i + a]);
                }
            }
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
        if (mls) /* supplement eq. 6: F <- (I + dt C'_p) F */
            for (int e = 0; e < 9; ++e) G[e] = dinv * B[e];
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
        double w[MPM_STENCIL];
        stencil_weights(st, k, w, NULL);
        double wm = 0.0;
        for (int s = 0; s < MPM_STENCIL; ++s)
            if (node[s] >= 0) wm += w[s] * g->mass[node[s]];
        /* wm > 0: m_i >= w_ip m_p (the particle's own share), so wm >= m_p sum_i w_ip^2 */
        p->vol[k] = p->mass[k] * cell / wm;
    }
}
