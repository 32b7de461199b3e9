/* DIR/cells.csv, the table of a matrix's finished cells: one row per cell,
 * appended only after the cell finished, in one write() followed by fsync,
 * so a run killed at any moment leaves whole rows (a row cut short by a
 * crash mid-write is dropped when the file is opened again). Its columns:
 * the cell's (the table of experiments/matrix/matrix_columns.c), then its
 * measurements (cell_measure_columns, experiments/matrix/matrix_measure.h);
 * docs/outputs.md says what each holds. */
#ifndef MPM_MATRIX_RESULTS_H
#define MPM_MATRIX_RESULTS_H

#include "experiments/matrix/matrix_cells.h"
#include "experiments/io/csv_table.h"
#include "experiments/matrix/matrix_columns.h"
#include "experiments/matrix/matrix_measure.h"

typedef struct {
    char path[1100];
    int fd;
    CsvTable rows;          /* the rows there when opened */
    const char **ids;       /* their ids, sorted */
    int n_ids;
} CellsFile;

/* Does the matrix's cells.csv have column k (matrix_columns.h)? */
int matrix_results_has(const Matrix *m, MatrixColumn k);
int matrix_results_header(const Matrix *m, char *out, size_t cap);
/* The text of column k (not MATRIX_COL_NAMED_AXES) in cell c's row; x: the
 * cell's measurements, NULL when it has none (the counts are then the asked ones). */
void matrix_results_field(const MatrixCell *c, const CellMeasure *x, MatrixColumn k, char *out, size_t cap);
int matrix_results_row(const Matrix *m, const MatrixCell *c, const CellOutcome *o, const CellMeasure *x, char *out,
                       size_t cap);

/* Value of `column` for the row of cell `id` when the file's header lacks
 * that column (an axis added to the matrix); returns 0 and leaves out
 * empty when it has none. */
typedef int (*CellsFillFn)(void *ctx, const char *id, const char *column, char *out, size_t cap);

/* Opens DIR/cells.csv to append rows under `header`: creates it, or reads
 * the rows there (a cut-short last line is dropped); a file with another
 * header (the matrix gained an axis) is rewritten with this one, its rows
 * mapped by column name and the new columns filled by `fill` (may be NULL).
 * With writable 0 (a dry run) it only reads the rows, if the file exists,
 * and changes nothing. */
int cells_file_open(const char *dir, const char *header, int writable, CellsFillFn fill, void *fill_ctx,
                    CellsFile *f);
int cells_file_has(const CellsFile *f, const char *id);
/* Expected seconds of a cell from the rows there: mean elapsed_s of the rows
 * with the same scene, solver and scale, else scene and solver, else solver;
 * -1 when none. */
double cells_file_estimate(const CellsFile *f, const char *scene, const char *solver, const char *scale);
/* One row (no newline): one write() of row + '\n', then fsync. */
int cells_file_append(CellsFile *f, const char *row);
void cells_file_close(CellsFile *f);

/* rm -rf of a cell directory (never follows symbolic links) */
int matrix_remove_tree(const char *path);

#endif
