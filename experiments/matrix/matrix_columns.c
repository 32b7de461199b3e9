/* The results tables' columns (matrix_columns.h). */
#include "experiments/matrix/matrix_columns.h"

#include <string.h>

#include "experiments/matrix/matrix_measure.h"

const MatrixColumnInfo matrix_columns[MATRIX_COLS] = {
    [MATRIX_COL_ID] = {"id", MATRIX_COL_ALWAYS},
    [MATRIX_COL_SCENE] = {"scene", MATRIX_COL_ALWAYS},
    [MATRIX_COL_SOLVER] = {"solver", MATRIX_COL_ALWAYS},
    [MATRIX_COL_EPS] = {"eps", MATRIX_COL_ALWAYS},
    [MATRIX_COL_SCALE] = {"scale", MATRIX_COL_ALWAYS},
    [MATRIX_COL_THREADS] = {"threads", MATRIX_COL_ALWAYS},
    [MATRIX_COL_RANKS] = {"ranks", MATRIX_COL_WITH_RANKS},
    [MATRIX_COL_FRAMES_ASKED] = {"frames_asked", MATRIX_COL_ALWAYS},
    [MATRIX_COL_FIRST_TIMED_FRAME] = {"first_timed_frame", MATRIX_COL_ALWAYS},
    [MATRIX_COL_ERROR_REF] = {"error_ref", MATRIX_COL_WITH_ERROR_REF},
    [MATRIX_COL_NAMED_AXES] = {NULL, MATRIX_COL_ALWAYS},
    [MATRIX_COL_REPEAT] = {"repeat", MATRIX_COL_WITH_REPEAT},
    [MATRIX_COL_ROLE] = {"role", MATRIX_COL_WITH_REFERENCES},
    [MATRIX_COL_REFERENCE] = {"reference", MATRIX_COL_WITH_REFERENCES},
    [MATRIX_COL_SAMPLE_FRAMES] = {"sample_frames", MATRIX_COL_WITH_SAMPLES},
    [MATRIX_COL_SET] = {"set", MATRIX_COL_ALWAYS},
    [MATRIX_COL_SOLVER_OPTS] = {"solver_opts", MATRIX_COL_ALWAYS},
};

const char *const matrix_check_columns[] = {"pass", "reasons", NULL};

int matrix_column_find(const char *name)
{
    for (int k = 0; k < MATRIX_COLS; ++k)
        if (matrix_columns[k].name && !strcmp(matrix_columns[k].name, name)) return k;
    return -1;
}

/* The measurement column i (cell_measure_columns is one comma-separated text) into out; 0 past the last. */
static int measure_column(int i, char *out, size_t n)
{
    const char *p = cell_measure_columns;
    for (; i > 0 && p; --i) p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL;
    if (!p || !*p) return 0;
    size_t len = strcspn(p, ",");
    if (len >= n) len = n - 1;
    memcpy(out, p, len);
    out[len] = '\0';
    return 1;
}

void matrix_reserved_each(void (*fn)(const char *name, void *ctx), void *ctx)
{
    for (int k = 0; k < MATRIX_COLS; ++k)
        if (matrix_columns[k].name) fn(matrix_columns[k].name, ctx);
    char col[64];
    for (int i = 0; measure_column(i, col, sizeof col); ++i) fn(col, ctx);
    for (int i = 0; matrix_check_columns[i]; ++i) fn(matrix_check_columns[i], ctx);
}

typedef struct {
    const char *name;
    int found;
} Lookup;

static void match(const char *name, void *ctx)
{
    Lookup *q = ctx;
    q->found |= !strcmp(name, q->name);
}

int matrix_column_reserved(const char *name)
{
    Lookup q = {name, 0};
    matrix_reserved_each(match, &q);
    return q.found;
}
