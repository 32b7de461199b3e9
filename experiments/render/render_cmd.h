/* `mpmbench render`: a PNG picture of a scene, either its initial state
 * (frame 0, no simulation) or after simulating N frames with a solver.
 *
 *   mpmbench render --scene NAME|FILE [options]   (mpmbench render --help)
 *
 * Defaults: frame 0, solver pn-pcg, view front, colour by material, output
 * <scene name>.png in the working directory. With neither --width nor
 * --height the image follows the aspect of the framed box (longer side 800
 * pixels); with one of them the other follows the aspect; with both the box
 * is fitted into W x H.
 *
 * Simulation prints nothing but the progress line on a terminal (as `run`);
 * the command prints one line naming the written file.
 *
 * Colliders are drawn by sphere tracing collider_phi at the current time;
 * inactive ("removed") colliders are skipped, and so are the six domain
 * walls (half-spaces named wall_x_min ... wall_z_max), which would cover the
 * picture. Other half-spaces (a ground) are drawn where they fall into the
 * framed box.
 *
 * Framing: the particles' box, plus the surfaces of the drawn colliders
 * near the particles: bounded colliders' surfaces within one particle-box
 * extent of the particles' box, and for unbounded ones (a ground) only the
 * part of the surface nearest to the particles (within 10% of the extent
 * of the nearest distance), so a ground plane adds a strip below the
 * particles, not an infinite floor; then a 10% margin. A state without
 * particles (a scene filled by a source later) frames the bounded colliders
 * in the domain, or the domain when there are none.
 *
 * Returns MPM_OK, MPM_EINPUT (one-line message) for bad flags or input,
 * MPM_EINTERNAL otherwise. */
#ifndef MPM_RENDER_CMD_H
#define MPM_RENDER_CMD_H

#include "experiments/cli/cli.h"

/* The command (options and help: render_cmd.c). */
extern const Command render_command;

#endif
