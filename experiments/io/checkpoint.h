/* Checkpoints: the whole state of a simulation at the start of a frame, so a
 * run can continue from it bit for bit (`run --checkpoint-at FRAMES` writes,
 * `run --from FILE` reads; docs/outputs.md "Checkpoints").
 *
 * What the state is: the particles with every per-particle field (x, v, C,
 * F, mass, volume, material, plastic Jp when stored, identity), in their
 * current order, and the clock (t, the time into the frame, the frame, the
 * last dt, a pending replayed dt, whether the grid-density volumes were
 * estimated). Nothing else persists from step to step: the grid, the step
 * problem and the stencils are rebuilt by every step_begin, colliders and
 * sources are functions of t (core/collider.h, core/source.h), and no
 * random numbers are drawn while a scene runs. A solver that keeps a setup
 * across steps (reuse_across_steps=1) starts afresh after a restart.
 *
 * The file: a fixed header ("MPMBENCH-CHECKPOINT", format version, byte
 * order), the scene's fingerprint (whatever loads the scene: its file's
 * bytes, the scale and the overrides; the caller computes it), the clock, the
 * particle count, the arrays, and an FNV-1a hash of everything before it, so
 * a truncated or altered file is refused. Native byte order and doubles: a
 * checkpoint is read back on the machine kind that wrote it. */
#ifndef MPM_CHECKPOINT_H
#define MPM_CHECKPOINT_H

#include <stdint.h>

#include "core/simulation.h"

/* Writes sim's state. MPM_EINPUT naming the file when it cannot be written. */
int checkpoint_write(const char *path, const Simulation *sim, uint64_t scene_fingerprint);

/* Replaces the state of sim (initialised from the same scene by sim_init)
 * with the file's. A file that is not a checkpoint, is truncated or altered,
 * was written by another format version or byte order, or for another scene
 * (fingerprint) is MPM_EINPUT with one line naming the file and what is
 * wrong; sim is then unchanged. */
int checkpoint_read(const char *path, Simulation *sim, uint64_t scene_fingerprint);

/* The frame a checkpoint file starts at (for messages and checks before the
 * scene is loaded); MPM_EINPUT as checkpoint_read for a bad file. */
int checkpoint_frame(const char *path, int *frame);

/* FNV-1a 64 of bytes, continued from h (start with CHECKPOINT_FNV_BASIS):
 * for the scene fingerprint. */
#define CHECKPOINT_FNV_BASIS 0xcbf29ce484222325ULL
uint64_t checkpoint_hash(uint64_t h, const void *bytes, size_t n);

#endif
