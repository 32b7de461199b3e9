/* P2G through block-local grid arenas (MLS-MPM supplement section 3.2,
 * issue 21): the particles of one 4x4x4 node block scatter into a padded
 * local 6x6x6 grid that stays in L1, with weights computed from x on the
 * fly (no stencil arrays read), and the arena is then added to the global
 * grid once per node. Blocks of one colour touch disjoint nodes (the same
 * colouring as the plain kernels), so the adds need no atomics. */
#ifndef MPM_TRANSFER_BLOCKED_H
#define MPM_TRANSFER_BLOCKED_H

#include "core/transfer.h"

/* transfer_p2g_mls and transfer_p2g_apic_force (transfer.h) with block-local
 * arenas: the same grid mass and velocity up to round-off (the sums are
 * grouped per block). st needs only base, pcolor and the grid's active
 * nodes (grid_build); kind is TRANSFER_MLS or TRANSFER_APIC. */
void transfer_p2g_blocked(Grid *g, const Stencils *st, const Particles *p, const ExplicitForce *force,
                          TransferKind kind);

#endif
