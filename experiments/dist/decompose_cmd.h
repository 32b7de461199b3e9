/* `mpmbench decompose`: what every rank of a split of a scene's grid over R
 * ranks would own and exchange, counted on one process (core/dist/): one
 * CSV row per rank and rank count, the input of scripts/halo_model.py and
 * of results/distributed's counted volumes (docs/distributed.md).
 *
 *   mpmbench decompose --scene NAME|FILE [--scale S] [--ranks 1,2,4,8,16]
 *                      [--from CHECKPOINT] [--out FILE.csv]
 *
 * The state counted is the scene's first step (its grid and stencils), or
 * the first step after a checkpoint of `run --checkpoint-at` (--from), so
 * a scene that fills up or spreads out is counted where it matters. */
#ifndef MPM_DECOMPOSE_CMD_H
#define MPM_DECOMPOSE_CMD_H

#include "experiments/cli/cli.h"

extern const Command decompose_command;

#endif
