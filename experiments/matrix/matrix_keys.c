/* The matrix file's own keys (matrix_keys.h). Table order is the order of
 * the known keys an error message lists and of the schema's properties. */
#include "experiments/matrix/matrix_keys.h"

#include <string.h>

#include "experiments/cli/options.h"

const MatrixKey matrix_keys[] = {
    {MATRIX_AT_TOP, "name", MATRIX_KEY_NAME, 1, 0, 0, NULL, NULL,
     MATRIX_NAME_RULE "; the default output folder is out/matrix-NAME"},
    {MATRIX_AT_TOP, "description", MATRIX_KEY_TEXT, 0, 0, 0, NULL, NULL, "what the study is; the report quotes it"},
    {MATRIX_AT_TOP, "defaults", MATRIX_KEY_PART, 0, 0, 0, NULL, "defaults", "a value for every `run` setting"},
    {MATRIX_AT_TOP, "axes", MATRIX_KEY_PART, 0, 0, 0, NULL, "axes",
     "lists of values; the cells are their product; an axis replaces the defaults' value"},
    {MATRIX_AT_TOP, "scenes", MATRIX_KEY_PART, 0, 0, 0, NULL, "scenes",
     "per-scene settings, keyed by a value of the scene axis; precedence: defaults < scenes.NAME < axes"},
    {MATRIX_AT_TOP, "include", MATRIX_KEY_PART, 0, 0, 0, NULL, "rules", "keep only the cells matching some rule"},
    {MATRIX_AT_TOP, "exclude", MATRIX_KEY_PART, 0, 0, 0, NULL, "rules", "drop the cells matching some rule"},
    {MATRIX_AT_TOP, "baseline", MATRIX_KEY_SETTING, 0, 0, 0, "solver", NULL,
     "a solver of the matrix; the report's speedups are against it"},
    {MATRIX_AT_TOP, "cell_timeout_s", MATRIX_KEY_POSITIVE, 0, 0, 0, NULL, NULL,
     "wall-clock limit of one cell [s]; a cell over it is killed (status timeout)"},
    {MATRIX_AT_TOP, "report", MATRIX_KEY_PART, 0, 0, 0, NULL, "report", "what the report tabulates besides its tables"},
    {MATRIX_AT_TOP, "reference", MATRIX_KEY_PART, 0, 0, 0, NULL, "reference",
     "a reference run per cell (its trajectory error, SPEC 11)"},
    {MATRIX_AT_TOP, "repeat", MATRIX_KEY_INT, 0, 1, 100, NULL, NULL,
     "runs of every cell but the reference runs; the report gives the median and the min-max"},

    {MATRIX_AT_SETTINGS, "first_timed_frame", MATRIX_KEY_INT, 0, 0, OPT_INT_CAP, NULL, NULL,
     "frames before it are simulated but not timed; below frames"},
    {MATRIX_AT_SCENE, "reference", MATRIX_KEY_PART, 0, 0, 0, NULL, "reference_or_false",
     "the scene's reference run, replacing the top-level one (false: none)"},

    {MATRIX_AT_AXES, "sets", MATRIX_KEY_PART, 0, 0, 0, NULL, "named_set_axes", "named axes of --set override sets"},
    {MATRIX_AT_AXES, "solver_opts", MATRIX_KEY_PART, 0, 0, 0, NULL, "named_solver_opts_axes",
     "named axes of --solver-opt sets"},

    {MATRIX_AT_REFERENCE, "solver", MATRIX_KEY_SETTING, 1, 0, 0, "solver", NULL, "the reference run's solver"},
    {MATRIX_AT_REFERENCE, "eps", MATRIX_KEY_SETTING, 0, 0, 0, "eps", NULL, "its eps (default " OPT_SPELLED(MATRIX_REFERENCE_EPS) ")"},
    {MATRIX_AT_REFERENCE, "solver_opts", MATRIX_KEY_SETTING, 0, 0, 0, "solver_opts", NULL,
     "its solver options, replacing the cell's"},
    {MATRIX_AT_REFERENCE, "set", MATRIX_KEY_SETTING, 0, 0, 0, "set", NULL,
     "--set overrides replacing or extending the cell's"},
    {MATRIX_AT_REFERENCE, "sample_frames", MATRIX_KEY_TEXT, 0, 0, 0, NULL, NULL,
     "\"F,F,...\", increasing frame numbers: the reference run writes checkpoints at these frames instead of a "
     "trajectory, and every cell of its scene times each of these frames alone from them (run --sample-frames)"},

    {MATRIX_AT_REPORT, "mg_levels", MATRIX_KEY_BOOL, 0, 0, 0, NULL, NULL,
     "also tabulate mg_levels.csv, the multigrid levels (HOT Fig. 8)"},
};
const int matrix_keys_count = (int)(sizeof matrix_keys / sizeof matrix_keys[0]);

const MatrixKey *matrix_key(MatrixKeyPlace place, const char *key)
{
    for (int i = 0; i < matrix_keys_count; ++i)
        if (matrix_keys[i].place == place && !strcmp(matrix_keys[i].key, key)) return &matrix_keys[i];
    return NULL;
}

int matrix_keys_at(MatrixKeyPlace place, const char **keys, int cap)
{
    int n = 0;
    for (int i = 0; i < matrix_keys_count && n + 1 < cap; ++i)
        if (matrix_keys[i].place == place) keys[n++] = matrix_keys[i].key;
    keys[n] = NULL;
    return n;
}
