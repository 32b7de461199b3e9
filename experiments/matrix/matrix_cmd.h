/* `mpmbench matrix run|report`: the command line of the experiment-matrix
 * runner (experiments/matrix/matrix_run.h) and of its report
 * (scripts/matrix_report.py, run with /usr/bin/python3, whose Debian
 * matplotlib it needs; MPM_PYTHON and MPM_SCRIPT_DIR override both).
 *
 *   mpmbench matrix run FILE [--out DIR] [--only GLOB ...] [--dry-run]
 *                       [--jobs N] [--asset-dir DIR] [--check]
 *   mpmbench matrix report DIR
 *
 * --only GLOB (repeatable) keeps the cells whose id or "scene/solver"
 * matches; --jobs N runs N cells at a time per process (default 1: a cell
 * uses its own threads); --check decides pass or fail per cell
 * (experiments/matrix/matrix_check.h) and exits 1 when any failed. */
#ifndef MPM_MATRIX_CMD_H
#define MPM_MATRIX_CMD_H

/* argv[1] is "matrix". */
int matrix_command(int argc, char **argv);

#endif
