/* Experiment matrices: one JSON file describes a study (experiments/matrices/
 * NAME.json); `mpmbench matrix run FILE` runs every cell of it in a child
 * process and `mpmbench matrix report DIR` turns the results into tables and
 * plots. This file loads and validates the matrix file.
 *
 * ------------------------------------------------------------------------
 * Matrix file format. Unknown keys anywhere are errors. The keys of "defaults",
 * "scenes.NAME" and "axes" that are run settings, their types, ranges and
 * where each may stand come from the one table of run settings
 * (experiments/cli/run_settings.c; `mpmbench run --help` names the keys);
 * the list below describes them.
 * ------------------------------------------------------------------------
 * {
 *   "name": "stiffness",            required: 1-63 of [A-Za-z0-9_.-]; the
 *                                   default output is out/matrix-NAME
 *   "description": "...",           optional
 *   "defaults": {                   optional: a value for every `run` flag
 *     "scene": "bar3",              built-in name or path (relative paths:
 *                                   from the matrix file's directory)
 *     "solver": "hot",              preset name (mpmbench list solvers)
 *     "eps": 1e-7, "scale": 1.86,   > 0 (defaults 1e-7 and 1)
 *     "threads": 2,                 integer in [1, 1024] (default: OpenMP's)
 *     "frames": 5,                  integer >= 1 (default: the scene's)
 *     "first_timed_frame": 0,       integer >= 0, < frames: frames before it
 *                                   are simulated but not timed (a pusher that
 *                                   needs a few frames to reach its target)
 *     "set": {"materials.middle.E": 1e9},   --set overrides, path: value
 *     "solver_opts": {"levels": 5}, --solver-opt key: value
 *     "history": false,             --history (iters.csv, convergence plots)
 *     "armijo": false,              --armijo
 *     "particles": false,           --particles (PLY per frame; off by default
 *                                   so the timed window writes no particles)
 *     "asset_dir": "DIR",           --asset-dir; relative: from the matrix
 *                                   file's directory (`matrix run --asset-dir`
 *                                   overrides it, relative to the working dir)
 *     "error_ref": "auto",          --error-ref SOLVER[:eps] | auto[:eps]:
 *                                   per-step error against a reference solve
 *                                   (err_h, e_gap, err_v_max in steps.csv)
 *     "trajectory": false,          --trajectory (OUT/trajectory.bin)
 *     "max_outer": 10000,           --max-outer, integer >= 1
 *     "max_linear": 10000,          --max-linear, integer >= 1
 *     "max_step_seconds": 30,       --max-step-seconds, in (0, 1e9]
 *     "max_run_seconds": 600,       --max-run-seconds, in (0, 1e9]
 *     "on_failure": "stop"          --on-failure stop | continue
 *   },
 *   "axes": {                       optional: lists of values; the cells are
 *                                   their product. An axis replaces the
 *                                   defaults' value. No empty lists.
 *     "scene": ["bar3", ...], "solver": [...], "eps": [...], "scale": [...],
 *     "threads": [...], "error_ref": ["auto", "pn-pcg:1e-12"],
 *     "sets": {                     named axes of --set override sets, e.g.
 *       "stiffness": [{"materials.middle.E": 1e5}, {"materials.middle.E": 1e7}]
 *                                   a list (each set's label is its value when
 *                                   it has one key, else "k=v;k=v") or an
 *                                   object {"LABEL": {set}, ...}
 *     },
 *     "solver_opts": {"mg": [{"levels": 3}, {"levels": 5}]}
 *                                   named axes of --solver-opt sets, same form
 *   },                              Axis names: [a-z][a-z0-9_]*, unique, none
 *                                   of the built-in column names.
 *   "scenes": {                     optional per-scene settings (key: a value
 *     "boxes": {"scale": 2.52, "frames": 9, "first_timed_frame": 4,
 *               "set": {...}}       of the scene axis); precedence:
 *   },                              defaults < scenes.NAME < axes. Also
 *                                   allowed per scene: error_ref, the limits
 *                                   (max_*, on_failure) and "reference"
 *   "reference": {                  optional: a reference run per scene (the
 *     "solver": "pn-cholmod",       trajectory error's reference, SPEC 11):
 *     "eps": 1e-10,                 for every cell the runner derives a
 *     "solver_opts": {...}          reference cell, the cell's settings with
 *   },                              this solver (required), eps (default
 *                                   1e-10) and solver_opts (replacing the
 *                                   cell's), without error_ref, with
 *                                   --trajectory. It runs first, as a cell of
 *                                   its own (cells sharing the settings share
 *                                   it), and its directory is passed to the
 *                                   cell as --dt-from and --trajectory-ref;
 *                                   the cell is started only after its
 *                                   reference ended ok (also across resumes
 *                                   and MPI ranks) and is skipped, without a
 *                                   row, when it did not. scenes.NAME.reference
 *                                   replaces it for a scene (false: none).
 *                                   cells.csv then has the columns role
 *                                   (cell | reference) and reference (the
 *                                   reference cell's id)
 *   "include": [RULE, ...],         optional: keep only cells matching a rule
 *   "exclude": [RULE, ...],         optional: drop cells matching a rule
 *                                   RULE = {"scene": "bar3", "solver":
 *                                   ["hot", "pn-pcg"], "stiffness": "1e+05"}:
 *                                   a cell matches when, for every key (scene,
 *                                   solver, eps, scale, threads or a named
 *                                   axis, by label), its value is the one
 *                                   given or one of the list
 *   "baseline": "pn-pcg",           optional: a solver of the matrix; the
 *                                   report's speedups are against it
 *   "cell_timeout_s": 1800,         optional: wall-clock limit of one cell
 *                                   (> 0; default none); a cell over it is
 *                                   killed and gets status "timeout"
 *   "repeat": 3,                    optional, integer 1..100 (default 1): run
 *                                   every cell but the reference runs this
 *                                   many times, all cells once before any
 *                                   twice (so slow drifts of the machine
 *                                   spread over the cells); repetition k > 1
 *                                   is a cell of its own (its id from the
 *                                   settings and k; the first keeps the id a
 *                                   matrix without repeat gives), cells.csv
 *                                   gets a column "repeat" (1..N) and the
 *                                   report gives the median and min-max
 *   "report": {"mg_levels": false}  optional: also tabulate mg_levels.csv
 *                                   (HOT Fig. 8 sparsity)
 * }
 *
 * Values of sets and solver_opts are JSON numbers, strings, booleans (or, for
 * sets, arrays/objects): they are passed as the text of --set / --solver-opt.
 *
 * Errors: MPM_EINPUT with one line naming the file, the JSON path of the
 * field and the bad value, e.g.
 *   "stiffness.json: axes.eps[1]: expected a positive number, got "tight"". */
#ifndef MPM_MATRIX_FILE_H
#define MPM_MATRIX_FILE_H

#include <jansson.h>

#include "experiments/cli/run_settings.h"
#include "experiments/matrix/matrix_keys.h"

#define MATRIX_MAX_KV 32       /* entries of one merged set / solver_opts */
#define MATRIX_MAX_AXES 16     /* named axes */

/* key=value text with where it came from (a JSON path, for error messages). */
typedef struct {
    char key[128];
    char value[256];
    char origin[256];
} MatrixKv;

typedef struct {
    MatrixKv kv[MATRIX_MAX_KV];
    int n;
} MatrixKvList;

typedef enum { MATRIX_SET = 0, MATRIX_SOLVER_OPTS = 1 } MatrixNamedKind;

typedef struct {
    char label[256];
    MatrixKvList kv;
} MatrixNamedValue;

typedef struct {
    char name[64];
    MatrixNamedKind kind;
    MatrixNamedValue *values;
    int n;
} MatrixNamedAxis;

/* The reference run of a scene ("reference"). */
typedef struct {
    int has;                  /* 0: none (absent, or false per scene) */
    const char *solver;       /* in the matrix's text pool */
    double eps;
    MatrixKvList solver_opts;
    MatrixKvList set;         /* --set overrides on top of the cell's (e.g. another transfer) */
    char origin[200];         /* where it was given, for messages */
    const char *solver_origin;
} MatrixReference;

/* The settings given in "defaults" or in "scenes.NAME". The run settings
 * (experiments/cli/run_settings.h) are in `run`, bit k of `given` saying
 * whether run_settings[k] was given and origin[k] where; texts live in the
 * matrix's text pool; the list settings are in set and solver_opts (with
 * where each entry came from). The rest are the matrix's own keys. */
typedef struct {
    RunConfig run;
    unsigned long long given;
    const char *origin[RUN_SETTINGS_MAX];
    MatrixKvList set, solver_opts;
    int has_first, first_timed_frame;
    int has_reference;
    MatrixReference reference;
} MatrixSettings;

typedef struct {
    char scene[1024];         /* as in the scene axis */
    MatrixSettings s;         /* only the keys allowed per scene */
} MatrixSceneSettings;

/* The values of an axis of a run setting ("axes.eps": [...]), with where each
 * was given. */
typedef struct {
    OptionValue *values;
    const char **origins;
    int n;                    /* 0: not an axis (the defaults' value) */
} MatrixAxis;

typedef struct {
    char file[1024];          /* as given */
    char base[256];           /* file name without directories, for messages */
    char dir[1024];           /* directory of the file */
    char name[MATRIX_NAME_MAX + 1];
    const char *description;  /* the file's text, whole (owned by root); "" when none */
    MatrixSettings defaults;
    MatrixAxis axis[RUN_SETTINGS_MAX]; /* axis[k]: of run_settings[k] (OPT_AXIS ones) */
    MatrixNamedAxis named[MATRIX_MAX_AXES];
    int n_named;
    MatrixSceneSettings *per_scene;
    int n_per_scene;
    json_t *include, *exclude;    /* arrays of validated rules, or NULL */
    char baseline[128];           /* "" = none */
    double cell_timeout_s;        /* 0 = none */
    int report_mg_levels;
    int repeat;                   /* runs of every timed cell (>= 1) */
    MatrixReference reference;    /* top-level "reference" */
    int has_references;           /* some scene has a reference run */
    int uses_error_ref;           /* error_ref given anywhere: a cells.csv column */
    json_t *root;                 /* the parsed file */
    char **pool;                  /* the texts the settings point to */
    int n_pool, cap_pool;
} Matrix;

/* Loads and validates the file (structure, types, names of scenes and
 * solvers); cells are checked further by matrix_validate_cells. On failure
 * *m is left freeable. */
int matrix_load(const char *path, Matrix *m);
void matrix_free(Matrix *m);

/* Index of the named axis, or -1. */
int matrix_named_index(const Matrix *m, const char *name);
/* Values of the axis of a run setting ("threads"), 0 when it is not an axis. */
int matrix_axis_length(const Matrix *m, const char *key);
/* A copy of text owned by the matrix (freed by matrix_free); NULL when out of memory. */
const char *matrix_keep(Matrix *m, const char *text);

/* Shortest text that reads back as the same double ("1e+05", "0.5"). */
void matrix_format_number(double v, char *out, size_t n);

/* The path scene_load is given for a scene value: built-in names unchanged,
 * relative paths prefixed by the matrix file's directory. */
void matrix_scene_path(const Matrix *m, const char *scene, char *out, size_t n);

#endif
