/* CSV tables read by column name (RFC 4180 quoting), so readers (the matrix
 * runner, --dt-from) keep working when a table gains columns. */
#ifndef MPM_CSV_TABLE_H
#define MPM_CSV_TABLE_H

#include <stddef.h>

typedef struct {
    int n_cols;
    char **header;
    int n_rows;
    char ***rows;     /* rows[r][c]; a short row is padded with "" */
    char *text;       /* storage of every field */
} CsvTable;

/* Reads a whole file. MPM_EINPUT if it cannot be read; an empty file gives
 * a table without columns. A last line without '\n' is a row too. */
int csv_read(const char *path, CsvTable *t);
int csv_parse(const char *data, size_t len, CsvTable *t);
void csv_free(CsvTable *t);
/* Column index of `name`, or -1. */
int csv_col(const CsvTable *t, const char *name);
/* The field, or "" when the column is -1. */
const char *csv_get(const CsvTable *t, int row, int col);

/* Appends `field` to out (at *len, capacity cap), quoted when it holds a
 * comma, quote or newline; returns -1 when it does not fit. */
int csv_put(char *out, size_t cap, size_t *len, const char *field);

#endif
