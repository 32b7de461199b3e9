/* `mpmbench matrix run FILE`: loads and validates the matrix, skips the
 * cells DIR/cells.csv already has, runs the others (matrix_dispatch.h) and
 * appends one row per finished cell. Writes DIR/matrix.json (the matrix as
 * run, with its named axes, for the report) and appends this invocation's
 * provenance to DIR/provenance.json. Under mpirun (an MPI launcher's
 * environment) it initialises MPI and spreads the cells over the ranks; rank
 * 0 validates, prints and writes, the others only run cells.
 *
 * Output on stdout: one line per finished cell; on a terminal (stderr, CI
 * unset) also a progress line. MPM_OK when the matrix ran (whatever the
 * cells' statuses: they are in cells.csv), MPM_EINPUT for a bad matrix file
 * or flag; with --check, *failed gets the number of cells that failed their
 * check (matrix_check.h; one line on stderr says so), which the command
 * turns into exit status 3.
 *
 * A cell with a reference run (matrix_file.h "reference") is dispatched
 * only after its reference ended ok; when the reference did not, the cell
 * is skipped (no row: it stays to do) with one line saying why. --only
 * keeps the references of the cells it selects. */
#ifndef MPM_MATRIX_RUN_H
#define MPM_MATRIX_RUN_H

#define MATRIX_MAX_ONLY 64

typedef struct {
    const char *out_dir;              /* NULL: out/matrix-NAME */
    const char *only[MATRIX_MAX_ONLY]; /* globs on the cell id or "scene/solver" */
    int n_only;
    int dry_run;                      /* list the cells and what is done */
    int jobs;                         /* cells at a time per process (>= 1) */
    const char *asset_dir;            /* NULL: the matrix's */
    int threads;                      /* > 0: replaces defaults.threads (refused with a threads axis) */
    int check;                        /* --check: the stability verdict of every cell (matrix_check.h) */
    double checkpoint_every_s;        /* > 0: a checkpoint reference's resume checkpoints (matrix_resume.h) */
} MatrixRunOptions;

int matrix_run(const char *file, const MatrixRunOptions *o, int *failed);

#endif
