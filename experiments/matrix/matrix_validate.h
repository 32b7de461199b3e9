/* Checking an experiment matrix's cells before any of them runs: what
 * cannot run is refused when the matrix is validated (exit 2, one line),
 * not at a cell's first Newton step. */
#ifndef MPM_MATRIX_VALIDATE_H
#define MPM_MATRIX_VALIDATE_H

#include "experiments/matrix/matrix_cells.h"

/* The cell's solver with its options through the creation path `mpmbench
 * run` uses: the one function that decides whether a solver can run (today
 * registry_find + registry_options + solver_create / solver_destroy, which
 * refuses unknown options and bad values; a solver-spec check that also
 * refuses incompatible OUTER:INVERSE compositions replaces its body). */
int matrix_check_solver(const char *solver, const MatrixKv *opts, int n_opts);

/* Checks every distinct solver + options of the cells through
 * matrix_check_solver, and, of the cells flagged in `load` (NULL: all), every
 * distinct (scene, scale, overrides, asset dir) by loading the scene once
 * (cells already done need no scene); the scene's own frame count then
 * bounds first_timed_frame. One-line MPM_EINPUT naming the matrix file,
 * where the offending setting came from and the problem. */
int matrix_validate_cells(const Matrix *m, const MatrixCells *c, const int *load);

#endif
