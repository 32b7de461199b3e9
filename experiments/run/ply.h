/* Particle snapshots as binary PLY (position, velocity, material id) for
 * ParaView. */
#ifndef MPM_PLY_H
#define MPM_PLY_H

#include "core/particles.h"

int ply_write_particles(const char *path, const Particles *p);

#endif
