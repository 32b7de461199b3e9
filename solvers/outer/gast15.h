/* Pieces of the Gast et al. 2015 outer method (solvers/outer/gast15.c, "gast15")
 * that tests check on their own. */
#ifndef MPM_GAST15_H
#define MPM_GAST15_H

#include <stddef.h>

enum { GAST_DIR_NEWTON = 0, GAST_DIR_FLIPPED = 1, GAST_DIR_GRADIENT = 2 };

/* The downhill check of Gast et al. 2015 §3.1 on the Newton direction p
 * against the gradient g (3 n_nodes entries): p is suitable when
 *   p . g < -kappa ||p|| ||g||;
 * otherwise -p when that is suitable, otherwise the steepest descent
 * direction -g. p is replaced in place; returns GAST_DIR_NEWTON,
 * GAST_DIR_FLIPPED or GAST_DIR_GRADIENT.
 * With m (one lumped mass per node) instead of NULL, the norms are those of
 * the kinetic-energy metric of the velocity unknowns, ||p||_M and
 * ||g||_{M^-1}, and the steepest descent direction is -M^-1 g (the paper's
 * check in mass-scaled variables sqrt(m) dv; not in the paper). work: 3 n_nodes
 * doubles when m is given. */
int gast_downhill_direction(int n_nodes, const double *m, const double *g, double *p, double kappa, double *work);

/* Step 6 of Gast §3.1: scales p to length l when ||p|| > l; returns 1 when it did. */
int gast_clamp_step(size_t len, double *p, double l);

#endif
