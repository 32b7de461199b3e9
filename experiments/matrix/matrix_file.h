/* Experiment matrices: one JSON file describes a study (experiments/matrices/
 * NAME.json); `mpmbench matrix run FILE` runs every cell of it in a child
 * process and `mpmbench matrix report DIR` turns the results into tables and
 * plots. This file loads and validates the matrix file.
 *
 * The format is docs/matrix-format.md's, and `mpmbench matrix schema` prints
 * it as a JSON Schema. Unknown keys anywhere are errors. The keys of
 * "defaults", "scenes.NAME", "axes" and "reference" that are run settings,
 * their types, ranges and where each may stand, come from the one table of
 * run settings (experiments/cli/run_settings.c); the file's own keys from
 * matrix_keys.c.
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
    char name[MATRIX_AXIS_NAME_MAX + 1];
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
    const char *sample_frames; /* "F,F,...": a checkpoint run for sampled cells (in the text pool); NULL: none */
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
    int has_samples;              /* some reference run has sample_frames */
    int uses_error_ref;           /* error_ref given anywhere: a cells.csv column */
    int uses_ranks;               /* ranks given anywhere: a cells.csv column */
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
