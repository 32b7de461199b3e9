/* The matrix file's own keys: the keys that are not run settings (those are
 * the run settings table's, experiments/cli/run_settings.c), each once, with
 * where it stands, its type and range and what it means. The loader
 * (matrix_file.c) checks a file's keys and ranges against this table and
 * the JSON Schema (matrix_schema.c) describes them from it. */
#ifndef MPM_MATRIX_KEYS_H
#define MPM_MATRIX_KEYS_H

#include "experiments/cli/options.h"

#define MATRIX_NAME_MAX 63          /* characters of a matrix's name */
#define MATRIX_NAME_RULE "1-" OPT_SPELLED(MATRIX_NAME_MAX) " of A-Z a-z 0-9 _ - ." /* a name, in words */
#define MATRIX_AXIS_NAME_MAX 63     /* characters of a named axis's name */
#define MATRIX_REFERENCE_EPS 1e-10  /* a reference run's eps when it gives none */

/* Where a key stands. */
typedef enum {
    MATRIX_AT_TOP,       /* the file's top level */
    MATRIX_AT_SETTINGS,  /* "defaults" and "scenes.NAME", after the run settings */
    MATRIX_AT_SCENE,     /* "scenes.NAME" only */
    MATRIX_AT_AXES,      /* "axes", after the run settings' axes */
    MATRIX_AT_REFERENCE, /* "reference" (and "scenes.NAME.reference") */
    MATRIX_AT_REPORT     /* "report" */
} MatrixKeyPlace;

typedef enum {
    MATRIX_KEY_NAME,     /* MATRIX_NAME_RULE */
    MATRIX_KEY_TEXT,     /* any string */
    MATRIX_KEY_INT,      /* an integer in [min, max] */
    MATRIX_KEY_POSITIVE, /* a finite number > 0 */
    MATRIX_KEY_BOOL,
    MATRIX_KEY_SETTING,  /* a value of the run setting `setting` (its type, range and check) */
    MATRIX_KEY_PART      /* a structure of its own, described by the schema's $defs entry `part` */
} MatrixKeyType;

typedef struct {
    MatrixKeyPlace place;
    const char *key;
    MatrixKeyType type;
    int required;
    double min, max;          /* MATRIX_KEY_INT */
    const char *setting;      /* MATRIX_KEY_SETTING: the run setting's key */
    const char *part;         /* MATRIX_KEY_PART */
    const char *description;
} MatrixKey;

extern const MatrixKey matrix_keys[];
extern const int matrix_keys_count;

/* The table's line of key at place, NULL when none. */
const MatrixKey *matrix_key(MatrixKeyPlace place, const char *key);

/* The keys at place, in table order, into keys (NULL-terminated; at most
 * cap - 1 of them); their number. */
int matrix_keys_at(MatrixKeyPlace place, const char **keys, int cap);

#endif
