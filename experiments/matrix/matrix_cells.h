/* The cells of an experiment matrix: one point of the product of its axes
 * after the include/exclude rules, with its effective settings (defaults <
 * per-scene settings < axis values), a stable id and the `mpmbench run`
 * command line that computes it.
 *
 * Id: the first 12 hex digits of the 64-bit FNV-1a hash of the canonical
 * serialisation of the effective settings (JSON, sorted keys, no spaces,
 * reals with 17 significant digits; overrides and solver options as sorted
 * key: text objects). It depends on nothing else: not on the order of the
 * axes, on the other values of an axis, on axis labels or on the asset
 * directory (which locates files but does not change a setting). Cells with
 * the same canonical settings are one cell (the first keeps its labels). */
#ifndef MPM_MATRIX_CELLS_H
#define MPM_MATRIX_CELLS_H

#include "experiments/matrix/matrix_file.h"

typedef struct {
    char id[16];
    /* the run settings (experiments/cli/run_settings.h): defaults < per-scene
     * settings < axis values. Texts as in the matrix (the scene not yet a
     * path; particles_dir "particles" = the cell's particles/ folder), in the
     * matrix's pool; the lists are set and solver_opts below (run.n_set and
     * run.n_solver_opts stay 0). matrix_cell_config makes the RunConfig the
     * cell runs with. */
    RunConfig run;
    unsigned long long given;    /* bit k: run_settings[k] given in the file */
    const char *origin[RUN_SETTINGS_MAX]; /* where each given setting came from */
    int first_timed_frame;
    MatrixKv *set, *solver_opts; /* merged, sorted by key */
    int n_set, n_solver_opts;
    int value[MATRIX_MAX_AXES];  /* value index of each named axis */
    char *canonical;
    double timeout_s;            /* 0 = none */
    int is_reference;            /* a reference run other cells depend on */
    int ref;                     /* index of this cell's reference cell, -1 = none */
    char ref_id[16];             /* its id ("" = none) */
    const char *sample_frames;   /* its reference's sample_frames (matrix_file.h): the reference writes
                                    checkpoints at them, the cell times them (the matrix's pool; NULL: none) */
    int repeat;                  /* 1..matrix repeat: which run of the same settings */
} MatrixCell;

typedef struct {
    MatrixCell *cells;
    int n;
} MatrixCells;

/* Every cell of the matrix, in product order (scene slowest, then solver,
 * eps, scale, threads, error_ref, the named axes in file order), rules
 * applied, duplicates removed; the reference cells (matrix_file.h
 * "reference") first, in the order they are first needed, and with
 * "repeat": N > 1 the repetitions 2..N of every other cell after all of
 * them (repetition by repetition, in the same order). A dependent
 * cell's canonical settings include its reference's id. MPM_EINPUT when a
 * cell's settings are inconsistent (a first timed frame not before its
 * frames). */
int matrix_expand(const Matrix *m, MatrixCells *out);
void matrix_cells_free(MatrixCells *c);
/* Keeps the cells i with keep[i] != 0, in order (the reference indices
 * renumbered; a kept cell's reference must be kept). */
void matrix_cells_keep(MatrixCells *c, const int *keep);

/* "scene/solver" */
void matrix_cell_name(const MatrixCell *c, char *out, size_t n);
/* "eps=1e-07 scale=4.3 threads=2 frames=1 stiffness=1e+05 ..." */
void matrix_cell_describe(const Matrix *m, const MatrixCell *c, char *out, size_t n);

/* Texts a cell's RunConfig points to (matrix_cell_config). */
typedef struct {
    char scene[2048], particles[1100], reference[1100];
    char set[MATRIX_MAX_KV][400], solver_opts[MATRIX_MAX_KV][400];
} MatrixCellTexts;

/* The RunConfig that computes the cell into out_dir: c->run with the scene
 * as a path (matrix_scene_path), the particles into out_dir/particles, the
 * lists as key=value texts, --quiet, --out out_dir, and for a dependent cell
 * --dt-from and --trajectory-ref with its reference's directory (out_dir's
 * sibling named by the reference's id). Its texts live in *texts.
 * MPM_EINPUT when a path does not fit. */
int matrix_cell_config(const Matrix *m, const MatrixCell *c, const char *out_dir, RunConfig *cfg,
                       MatrixCellTexts *texts);

/* The `mpmbench run` arguments (without the program) that compute the cell
 * into out_dir: run_config_argv of matrix_cell_config, NUL-separated in buf;
 * *argc set. MPM_EINPUT if too long. */
int matrix_cell_argv(const Matrix *m, const MatrixCell *c, const char *out_dir, char *buf, size_t cap, int *argc);

#endif
