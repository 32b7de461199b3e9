/* `mpmbench matrix run FILE --check`: the stability verdict of each cell
 * (the stress suite, experiments/matrices/stress.json), decided from the
 * cell's files and its cells.csv row only. A cell passes when
 *   - it ended (status ok), or its run reported why it could not go on (a
 *     particle that left the domain or became non-finite: exit 1 with that
 *     message); a crash, a bad input, an internal error or the runner's
 *     wall-clock kill (status timeout) fails it;
 *   - every step either converged, re-checked from steps.csv (residual below
 *     eps, for the CN stopping rule; printed with 7 digits, so up to 1e-6
 *     relative), or reported capped, stalled, timeout or failed;
 *   - no NaN or Inf in a numeric field of steps.csv or frames.csv;
 *   - no line search accepted an energy increase (max_energy_rise <= 0);
 *   - it ran all its frames, or its last step says why not (failed or
 *     timeout: the failure policy or --max-run-seconds stopped it).
 * DIR/check.csv gets one row per cell: id, scene, solver, eps, the named
 * axes' labels, pass (1/0), reasons; --check prints the failing cells and
 * makes `matrix run` exit 3 when any failed. */
#ifndef MPM_MATRIX_CHECK_H
#define MPM_MATRIX_CHECK_H

#include <stddef.h>

#include "experiments/matrix/matrix_cells.h"
#include "experiments/io/csv_table.h"

typedef struct {
    int pass;
    char reasons[1024];  /* "; "-separated, "" when it passed */
    char notes[256];     /* what passed but is worth saying (a reported escape) */
} CellCheck;

/* The verdict of a finished cell: its directory, and its row (row index r of
 * the cells.csv table t). */
void matrix_check_cell(const MatrixCell *c, const char *dir, const CsvTable *t, int r, CellCheck *out);

/* Checks every cell of `cells` whose row DIR/cells.csv holds (the last row
 * of an id), writes DIR/check.csv, prints one line per failing cell and a
 * summary; *failed = the failing cells (a cell without a row fails: not
 * run). */
int matrix_check_all(const Matrix *m, const MatrixCells *cells, const char *dir, int *failed);

#endif
