/* Particle <-> grid transfers with APIC and the RPIC blend (SPEC 2;
 * Jiang et al. 2015; HOT reference §1.2), MLS-MPM (SPEC 9; Hu et al. 2018
 * and its supplement), the PIC/FLIP blend of Stomakhin et al. 2013 / Gast
 * et al. 2015 section 6.1 step 5, and the particle volumes estimated from
 * the grid density (Gast et al. 2015 section 6.1 step 2). */
#ifndef MPM_TRANSFER_H
#define MPM_TRANSFER_H

#include "core/grid.h"
#include "core/material.h"
#include "core/particles.h"

/* P2G: m_i = sum_p w_ip m_p, (mv)_i = sum_p w_ip m_p (v_p + C_p (x_i - x_p)),
 * v_i = (mv)_i / m_i. Race-free by particle-block colouring. */
void transfer_p2g(Grid *g, const Stencils *st, const Particles *p);

/* The explicit particle force of the supplement's benchmark P2G (Hu et al.
 * 2018 supplement section 3, "Benchmark settings": linear elasticity,
 * P = mu (F + F^T - 2 I) + lambda tr(F - I) I, from each particle's
 * material mu and lambda), then v_i = (mv)_i / m_i + dt g. Only the
 * transfer benchmark uses it; the implicit step keeps the force in the
 * incremental potential and passes no force. */
typedef struct {
    double dt;
    const Material *mats;
    double gravity[3];
} ExplicitForce;

/* APIC P2G with an explicit force from the weight gradients (the
 * supplement's APIC reference kernel): (mv)_i += w_ip m_p (v_p + C_p (x_i - x_p))
 * - dt V_p P_p F_p^T grad w_ip. force NULL: transfer_p2g. */
void transfer_p2g_apic_force(Grid *g, const Stencils *st, const Particles *p, const ExplicitForce *force);

/* Fused MLS-MPM P2G (supplement section 3.1): one affine matrix per particle,
 *   Q_p = m_p C_p - dt V_p D_p^-1 P_p F_p^T,  D_p^-1 = 4/dx^2 I,
 *   (mv)_i += w_ip (m_p v_p + Q_p (x_i - x_p)),
 * so the inner loop over the 27 nodes has one 3x3 product. force NULL
 * (the implicit step): Q_p = m_p C_p, the APIC momentum of transfer_p2g
 * up to round-off. */
void transfer_p2g_mls(Grid *g, const Stencils *st, const Particles *p, const ExplicitForce *force);

/* The pieces the P2G kernels share (core/transfer_blocked.c uses them):
 * K = V_p P F^T of the supplement's linear elasticity, and v_i = (mv)_i / m_i
 * (+ dt g with an explicit force). */
void transfer_explicit_stress(const ExplicitForce *force, const Particles *p, size_t k, double K[9]);
void transfer_normalise_grid_velocity(Grid *g, const ExplicitForce *force);

/* Which particle velocity G2P stores. */
typedef enum {
    TRANSFER_APIC = 0,    /* APIC/RPIC: v_p = PIC velocity, C_p from B_p (apic_ratio) */
    TRANSFER_PIC_FLIP = 1, /* v_p = alpha v_FLIP + (1 - alpha) v_PIC, C_p = 0 */
    TRANSFER_MLS = 2       /* MLS-MPM: APIC velocities and C_p; the stencils' weight gradients are
                              the MLS substitute (stencils_use_mls_gradients), F <- (I + dt C'_p) F */
} TransferKind;

/* The scene file's name of each transfer ("transfer": "mls"), in the order
 * messages list them; NULL-terminated (the table: core/transfer_kind.c). */
extern const char *const transfer_names[];
/* The kind a name means: 1, or 0 when it names none. */
int transfer_kind_from_name(const char *name, TransferKind *kind);
/* The name of a kind ("pic_flip"). */
const char *transfer_kind_name(TransferKind kind);

typedef struct {
    TransferKind kind;
    double apic_ratio; /* TRANSFER_APIC: r in [0, 1] (1 APIC, 0 RPIC) */
    double flip_alpha; /* TRANSFER_PIC_FLIP: alpha in [0, 1] (0 = PIC, 1 = FLIP; Gast uses 0.95) */
    int advect;        /* 1: x_p += dt v_PIC (forward Euler); 0: positions untouched (the caller
                          moves them, e.g. position_update_backward_euler) */
} G2POptions;

/* G2P with weights at x_p^n, grid velocities vnew (3n), v^n = g->v
 * (MLS: as APIC, but F <- (I + dt C'_p) F with C'_p = 4/dx^2 B_p, the
 * supplement's eq. 6: no weight gradient is read):
 *   v_PIC = sum w v_i,  grad v_p = sum v_i grad w^T,  F_p <- (I + dt grad v_p) F_p,
 *   APIC:     v_p = v_PIC, B_p = sum w v_i (x_i - x_p)^T, C' = 4/dx^2 B_p,
 *             C_p = (r+1)/2 C' + (r-1)/2 C'^T,
 *   PIC/FLIP: v_p = alpha (v_p^n + sum w (v_i - v_i^n)) + (1 - alpha) v_PIC, C_p = 0
 *             (Stomakhin 2013 has no affine term, so P2G gets none; the F
 *             update is the same in both modes, Gast 6.1 step 4),
 *   advect:   x_p += dt v_PIC in both modes (Gast 6.3: positions move with
 *             the PIC velocity even where FLIP is stored). */
void transfer_g2p_opts(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                       const G2POptions *opt);

/* APIC/RPIC G2P with forward-Euler advection (transfer_g2p_opts with
 * kind APIC, advect 1). */
void transfer_g2p(const Grid *g, const Stencils *st, Particles *p, const double *vnew, double dt,
                  double apic_ratio);

/* Particle volumes from the grid density (Gast et al. 2015 section 6.1 step
 * 2, after Stomakhin et al. 2013): with the masses m_i of a P2G at the
 * particles' current positions, rho_i = m_i / dx^3, rho_p = sum_i w_ip rho_i
 * and V_p = m_p / rho_p. On a uniform lattice of ppc particles per cell this
 * gives V_p = dx^3 / ppc wherever the lattice covers the particle's whole
 * stencil neighbourhood; near a free surface rho_p is lower and V_p larger. */
void transfer_volumes_from_density(const Grid *g, const Stencils *st, Particles *p);

#endif
