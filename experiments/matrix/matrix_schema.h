/* The JSON Schema of matrix files (docs/matrix.schema.json), generated from
 * the tables that define the format: the run settings table
 * (experiments/cli/run_settings.c: every key of "defaults", "scenes.NAME",
 * "axes" and "reference" that is a run setting, with its type, range,
 * choices and help), the matrix file's own keys (matrix_keys.c) and the
 * results tables' columns, which a named axis may not be called
 * (matrix_columns.c). `mpmbench matrix schema` prints it; the committed
 * file must equal it byte for byte (tests/matrix/test_matrix_schema.sh). */
#ifndef MPM_MATRIX_SCHEMA_H
#define MPM_MATRIX_SCHEMA_H

#include <stdio.h>

/* Writes the schema to f: JSON, two-space indents, keys in table order, a
 * final newline. MPM_EINTERNAL when out of memory or f fails. */
int matrix_schema_write(FILE *f);

#endif
