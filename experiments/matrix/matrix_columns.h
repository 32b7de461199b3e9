/* The columns of DIR/cells.csv that describe a cell, in order (the
 * measurements follow: cell_measure_columns, matrix_measure.h), and the
 * names a named axis may not take because a results table has them: every
 * column of cells.csv, and check.csv's own. matrix_results.c writes the
 * header and rows from this table, matrix_check.c check.csv's first
 * columns, matrix_file.c refuses the reserved names and the JSON Schema
 * lists them. */
#ifndef MPM_MATRIX_COLUMNS_H
#define MPM_MATRIX_COLUMNS_H

typedef enum {
    MATRIX_COL_ID,
    MATRIX_COL_SCENE,
    MATRIX_COL_SOLVER,
    MATRIX_COL_EPS,
    MATRIX_COL_SCALE,
    MATRIX_COL_THREADS,           /* the run's own count when the matrix left it to OpenMP (per rank) */
    MATRIX_COL_RANKS,             /* the MPI ranks the scene was split over */
    MATRIX_COL_FRAMES_ASKED,      /* the run's own count when the matrix left it to the scene */
    MATRIX_COL_FIRST_TIMED_FRAME,
    MATRIX_COL_ERROR_REF,
    MATRIX_COL_NAMED_AXES,        /* not a column: one per named axis (its label), in file order */
    MATRIX_COL_REPEAT,
    MATRIX_COL_ROLE,              /* cell | reference */
    MATRIX_COL_REFERENCE,         /* the reference cell's id */
    MATRIX_COL_SAMPLE_FRAMES,     /* the frames a sampled cell timed (its reference wrote them), else empty */
    MATRIX_COL_SET,               /* the merged k=v;k=v */
    MATRIX_COL_SOLVER_OPTS,
    MATRIX_COLS
} MatrixColumn;

/* Which matrices have the column. */
typedef enum {
    MATRIX_COL_ALWAYS,
    MATRIX_COL_WITH_ERROR_REF,  /* error_ref is given somewhere */
    MATRIX_COL_WITH_REPEAT,     /* repeat > 1 */
    MATRIX_COL_WITH_REFERENCES, /* some cell has a reference run */
    MATRIX_COL_WITH_SAMPLES,    /* some reference run has sample_frames */
    MATRIX_COL_WITH_RANKS       /* ranks is given somewhere */
} MatrixColumnWhen;

typedef struct {
    const char *name;           /* NULL for MATRIX_COL_NAMED_AXES */
    MatrixColumnWhen when;
} MatrixColumnInfo;

extern const MatrixColumnInfo matrix_columns[MATRIX_COLS];

/* check.csv: cells.csv's columns up to this one, the named axes, then these. */
#define MATRIX_CHECK_LAST_SHARED MATRIX_COL_EPS
extern const char *const matrix_check_columns[]; /* NULL-terminated */

/* The column named name, -1 when none. */
int matrix_column_find(const char *name);

/* Is name a column of cells.csv or check.csv in some matrix, so a named axis
 * may not take it? */
int matrix_column_reserved(const char *name);

/* Calls fn with every reserved name, in the tables' order. */
void matrix_reserved_each(void (*fn)(const char *name, void *ctx), void *ctx);

#endif
