/* A matrix reference run that writes checkpoints (matrix-format.md,
 * `sample_frames`) simulates a whole animation, which at the paper's scale
 * can take longer than the machine is available in one go. Stopped midway
 * (the runner killed, the machine shut down), it goes on from its newest
 * checkpoint at the next `matrix run` instead of starting over: the earlier
 * attempt's files move to DIR/attempts/N/, the run continues with --from
 * (bit for bit, experiments/io/checkpoint.h), and when it ends its
 * steps.csv and frames.csv are joined from the attempts and its cost
 * (elapsed, CPU, the others' CPU) is the sum over them, as each attempt's
 * DIR/progress.txt last recorded it while it ran. */
#ifndef MPM_MATRIX_RESUME_H
#define MPM_MATRIX_RESUME_H

#include <stddef.h>

#include "experiments/matrix/matrix_child.h"
#include "experiments/matrix/matrix_measure.h"

/* Seconds between a resumable reference's resume checkpoints (run
 * --checkpoint-every-s) unless `matrix run --checkpoint-every-s` says
 * otherwise, and between its progress records. */
#define MATRIX_RESUME_EVERY_S 300.0
#define MATRIX_PROGRESS_EVERY_S 1.0

/* Before the resumable cell in dir starts: when dir holds an attempt that
 * can go on (its progress.txt, its run.json, a checkpoint past the frame it
 * started at, and frames.csv rows of every frame before that checkpoint),
 * moves that attempt's files to dir/attempts/N/ and sets *attempts = N and
 * from to the checkpoint to continue from; otherwise *attempts = 0 and the
 * caller starts the cell afresh. Errors only when files cannot be moved. */
int matrix_resume_prepare(const char *dir, char *from, size_t cap, int *attempts);

/* While the cell runs: dir/progress.txt with its elapsed and CPU seconds,
 * the others' CPU seconds meanwhile and its peak memory (rewritten whole). */
void matrix_resume_record(const char *dir, const CellChild *c);

/* After the cell ended: with attempts > 0, its steps.csv and frames.csv
 * joined from the attempts (each up to the frame the next one started at),
 * their costs added to *o, and dir/attempts.csv (attempt, first_frame,
 * elapsed_s, cpu_s, others_cpu_s: each attempt's, the last one's as the
 * runner measured it); the resume checkpoints and progress.txt removed (the
 * sampled frames' checkpoints stay). */
int matrix_resume_finish(const char *dir, int attempts, CellOutcome *o);

#endif
