/* Backward-Euler particle positions (Gast et al. 2015 section 6.3; see
 * position_update.h). */
#include "core/position_update.h"

#include <math.h>
#include <string.h>

#include "core/kernel.h"
#include "core/mat3.h"

double grid_velocity_at(const Grid *g, const double *vnew, const double x[3], const int *hint_base,
                        const int *hint_node, double v[3], double G[9])
{
    double inv_dx = 1.0 / g->dx, N[3][3], dN[3][3];
    int base[3];
    for (int d = 0; d < 3; ++d) base[d] = bspline2_1d(x[d], inv_dx, N[d], dN[d]);
    int same = hint_base && hint_node && base[0] == hint_base[0] && base[1] == hint_base[1] &&
               base[2] == hint_base[2];
    /* S = sum w v, dS = sum v grad w^T, W = sum w, dW = sum grad w over active nodes */
    double W = 0.0, dW[3] = {0, 0, 0}, S[3] = {0, 0, 0}, dS[9] = {0};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int c = 0; c < 3; ++c) {
                int s = stencil_slot(a, b, c);
                int id = same ? hint_node[s] : -1;
                if (id < 0) { /* a hinted -1 only says the weight was 0 at the hint's position */
                    int cc[3] = {base[0] + a, base[1] + b, base[2] + c};
                    id = grid_lookup(g, cc);
                    if (id < 0) continue;
                }
                double w = N[0][a] * N[1][b] * N[2][c];
                double gw[3] = {dN[0][a] * N[1][b] * N[2][c], N[0][a] * dN[1][b] * N[2][c],
                                N[0][a] * N[1][b] * dN[2][c]};
                const double *vi = vnew + 3 * (size_t)id;
                W += w;
                for (int e = 0; e < 3; ++e) {
                    dW[e] += gw[e];
                    S[e] += w * vi[e];
                    for (int f = 0; f < 3; ++f) dS[3 * e + f] += vi[e] * gw[f];
                }
            }
    if (!(W > 0.0)) {
        memset(v, 0, 3 * sizeof(double));
        memset(G, 0, 9 * sizeof(double));
        return 0.0;
    }
    /* v = S / W, dv/dx = (dS - v dW^T) / W */
    for (int e = 0; e < 3; ++e) v[e] = S[e] / W;
    for (int e = 0; e < 3; ++e)
        for (int f = 0; f < 3; ++f) G[3 * e + f] = (dS[3 * e + f] - v[e] * dW[f]) / W;
    return W;
}

/* r = x - x0 - dt v(x); returns ||r|| and leaves grad v in G. */
static double residual(const Grid *g, const double *vnew, const double x[3], const double x0[3], double dt,
                       const int *hint_base, const int *hint_node, double r[3], double G[9])
{
    double v[3];
    grid_velocity_at(g, vnew, x, hint_base, hint_node, v, G);
    for (int d = 0; d < 3; ++d) r[d] = x[d] - x0[d] - dt * v[d];
    return v3_norm(r);
}

void position_update_backward_euler(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                                    PositionUpdateStats *stats)
{
    const double tol = POSITION_TOL_DX * g->dx;
    long iters = 0, halvings = 0;
    int max_iters = 0;
    long unconverged = 0;
    const long long n = (long long)p->n;
#pragma omp parallel for schedule(static) reduction(+ : iters, halvings, unconverged) reduction(max : max_iters)
    for (long long k = 0; k < n; ++k) {
        double *xp = p->x + 3 * k;
        const int *hb = st->base + 3 * k, *hn = st->node + MPM_STENCIL * k;
        double x0[3] = {xp[0], xp[1], xp[2]}, x[3] = {xp[0], xp[1], xp[2]};
        double r[3], G[9];
        /* Newton from x^n, where r = -dt v_PIC(x^n) */
        double E = residual(g, vnew, x, x0, dt, hb, hn, r, G);
        int it = 0;
        while (E > tol && it < POSITION_MAX_NEWTON) {
            double J[9], Jinv[9], step[3];
            for (int e = 0; e < 9; ++e) J[e] = -dt * G[e];
            J[0] += 1.0;
            J[4] += 1.0;
            J[8] += 1.0;
            if (m3_inverse(J, Jinv)) {
                m3_mulv(Jinv, r, step);
            } else { /* singular Jacobian: the fixed-point direction */
                memcpy(step, r, sizeof step);
            }
            /* halve the Newton step until ||r|| does not increase; after 14
             * halvings take the reduced step anyway (Gast 6.3) */
            double alpha = 1.0, xt[3], rt[3], Gt[9], Et;
            int h = 0;
            for (;;) {
                for (int d = 0; d < 3; ++d) xt[d] = x[d] - alpha * step[d];
                Et = residual(g, vnew, xt, x0, dt, hb, hn, rt, Gt);
                if (Et <= E || h == POSITION_MAX_HALVINGS) break;
                alpha *= 0.5;
                ++h;
            }
            halvings += h;
            memcpy(x, xt, sizeof x);
            memcpy(r, rt, sizeof r);
            memcpy(G, Gt, sizeof G);
            E = Et;
            ++it;
        }
        iters += it;
        if (it > max_iters) max_iters = it;
        if (E > tol) ++unconverged;
        memcpy(xp, x, sizeof x);
    }
    if (stats) {
        stats->newton_iters = iters;
        stats->max_newton_iters = max_iters;
        stats->halvings = halvings;
        stats->unconverged = (size_t)unconverged;
    }
}
