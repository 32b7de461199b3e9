/* Particle <-> grid transfers with APIC and the RPIC blend (SPEC 2;
 * Jiang et al. 2015; HOT reference §1.2). */
#ifndef MPM_TRANSFER_H
#define MPM_TRANSFER_H

#include "core/grid.h"
#include "core/particles.h"

/* P2G: m_i = sum_p w_ip m_p, (mv)_i = sum_p w_ip m_p (v_p + C_p (x_i - x_p)),
 * v_i = (mv)_i / m_i. Race-free by particle-block colouring. */
void transfer_p2g(Grid *g, const Stencils *st, const Particles *p);

/* G2P with weights at x_p^n, grid velocities vnew (3n):
 *   v_p = sum w v_i,  B_p = sum w v_i (x_i - x_p)^T,  C' = 4/dx^2 B_p,
 *   C_p = (r+1)/2 C' + (r-1)/2 C'^T   (r = apic_ratio; 1 APIC, 0 RPIC),
 *   grad v_p = sum v_i grad w^T,  x_p += dt v_p,  F_p <- (I + dt grad v_p) F_p. */
void transfer_g2p(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                  double apic_ratio);

#endif
