/* Running a list of cell tasks: `jobs` child processes at a time on this
 * process and, under mpirun with K ranks, on every rank. Rank 0 hands out
 * the tasks one at a time in the given order to whichever rank has a free
 * slot (itself included, so -np 2 gives two workers), collects the results
 * and calls the callback for each; the other ranks only run what they are
 * given. Every loop polls its children and (rank 0) incoming messages with
 * a short sleep between rounds, so waiting costs no core and rank 0 keeps
 * serving MPI while its own child runs.
 *
 * A task may wait for another (`after`: a dependent cell for its reference
 * run): it is handed out, to this process or any rank, only after that one
 * finished with status ok, and is skipped (the `skipped` hook, no result)
 * when that one did not end ok or was itself skipped. A rank asking for work
 * while every remaining task waits is answered when one becomes ready.
 *
 * The cell directories must be on a file system every rank sees (each rank
 * measures the cells it ran and sends the numbers). */
#ifndef MPM_MATRIX_DISPATCH_H
#define MPM_MATRIX_DISPATCH_H

#include <stddef.h>

#include "experiments/matrix/matrix_measure.h"

typedef struct {
    int index;                 /* the caller's cell index */
    int first_timed_frame;
    int ranks;                 /* > 1: the cell runs under mpirun -np ranks */
    double timeout_s;          /* 0: none */
    int after;                 /* position in the task list of the task this one waits for; -1: none */
    int resumable;             /* a checkpoint reference: a stopped attempt goes on (matrix_resume.h) */
    char dir[1024];            /* the cell directory (wiped and recreated) */
    int argc;
    int args_len;
    char args[6144];           /* the run arguments, NUL-separated; must stay last */
} MatrixTask;

typedef struct {
    int index;
    int rank;                  /* where it ran */
    CellOutcome outcome;
    CellMeasure measure;
} MatrixResult;

typedef struct {
    /* rank 0: a task finished (in finishing order); a non-zero return stops the matrix */
    int (*done)(void *ctx, const MatrixResult *r);
    /* rank 0: called between polling rounds (terminal progress), running = cells in flight */
    void (*tick)(void *ctx, int running);
    /* rank 0: task t will not run because `dep` did not end ok (may be NULL) */
    void (*skipped)(void *ctx, const MatrixTask *t, const MatrixTask *dep);
    void *ctx;
} MatrixDispatchHooks;

/* Rank 0 (or a serial run, use_mpi 0): runs tasks[0..n-1]. Other ranks:
 * n = 0, they serve rank 0 until it has no task left. MPI must be
 * initialised when use_mpi is set; the caller finalises it. */
int matrix_dispatch(const MatrixTask *tasks, int n, int jobs, int use_mpi, const MatrixDispatchHooks *hooks);

#endif
