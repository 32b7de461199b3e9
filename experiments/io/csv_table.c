#include "experiments/io/csv_table.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* Grows a pointer array by one slot. */
static int push(void ***arr, int *n, int *cap, void *item)
{
    if (*n == *cap) {
        int c = *cap ? 2 * *cap : 16;
        void **a = realloc(*arr, sizeof *a * (size_t)c);
        if (!a) return -1;
        *arr = a;
        *cap = c;
    }
    (*arr)[(*n)++] = item;
    return 0;
}

int csv_parse(const char *data, size_t len, CsvTable *t)
{
    memset(t, 0, sizeof *t);
    /* fields are copied unquoted into text, each NUL-terminated; never longer than the input */
    t->text = malloc(len + 1);
    if (!t->text) return mpm_error(MPM_EINTERNAL, "out of memory (CSV)");
    char *w = t->text;
    char **fields = NULL;
    int nf = 0, capf = 0, cap_rows = 0;
    size_t i = 0;
    int st = MPM_OK;
    while (i < len && !st) {
        /* one record */
        nf = 0;
        for (;;) {
            char *start = w;
            if (i < len && data[i] == '"') {
                ++i;
                while (i < len) {
                    if (data[i] == '"') {
                        if (i + 1 < len && data[i + 1] == '"') {
                            *w++ = '"';
                            i += 2;
                            continue;
                        }
                        ++i;
                        break;
                    }
                    *w++ = data[i++];
                }
            }
            while (i < len && data[i] != ',' && data[i] != '\n') {
                if (data[i] != '\r') *w++ = data[i];
                ++i;
            }
            *w++ = '\0';
            if (push((void ***)&fields, &nf, &capf, start)) st = mpm_error(MPM_EINTERNAL, "out of memory (CSV)");
            if (st || i >= len || data[i] == '\n') break;
            ++i; /* comma */
        }
        if (i < len) ++i; /* newline */
        if (st) break;
        char **rec = malloc(sizeof *rec * (size_t)(nf > t->n_cols ? nf : t->n_cols ? t->n_cols : 1));
        if (!rec) {
            st = mpm_error(MPM_EINTERNAL, "out of memory (CSV)");
            break;
        }
        memcpy(rec, fields, sizeof *rec * (size_t)nf);
        if (!t->header) {
            t->header = rec;
            t->n_cols = nf;
            continue;
        }
        if (nf == 1 && !rec[0][0]) { /* blank line */
            free(rec);
            continue;
        }
        for (int k = nf; k < t->n_cols; ++k) rec[k] = w - 1; /* "" (the last NUL) */
        if (push((void ***)&t->rows, &t->n_rows, &cap_rows, rec)) {
            free(rec);
            st = mpm_error(MPM_EINTERNAL, "out of memory (CSV)");
        }
    }
    free(fields);
    if (st) csv_free(t);
    return st;
}

int csv_read(const char *path, CsvTable *t)
{
    memset(t, 0, sizeof *t);
    FILE *f = fopen(path, "rb");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot read", path);
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (cap - len < 65536) {
            size_t c = cap ? 2 * cap : 65536;
            char *b = realloc(buf, c);
            if (!b) {
                free(buf);
                fclose(f);
                return mpm_error(MPM_EINTERNAL, "out of memory reading %s", path);
            }
            buf = b;
            cap = c;
        }
        size_t r = fread(buf + len, 1, cap - len, f);
        len += r;
        if (r == 0) break;
    }
    fclose(f);
    int st = csv_parse(buf, len, t);
    free(buf);
    return st;
}

void csv_free(CsvTable *t)
{
    free(t->header);
    for (int r = 0; r < t->n_rows; ++r) free(t->rows[r]);
    free(t->rows);
    free(t->text);
    memset(t, 0, sizeof *t);
}

int csv_col(const CsvTable *t, const char *name)
{
    for (int c = 0; c < t->n_cols; ++c)
        if (!strcmp(t->header[c], name)) return c;
    return -1;
}

const char *csv_get(const CsvTable *t, int row, int col)
{
    if (col < 0 || col >= t->n_cols || row < 0 || row >= t->n_rows) return "";
    return t->rows[row][col];
}

int csv_put(char *out, size_t cap, size_t *len, const char *field)
{
    int quote = strpbrk(field, ",\"\n\r") != NULL;
    size_t need = strlen(field) + (quote ? 2 + strlen(field) : 0) + 1;
    if (*len + need >= cap) return -1;
    char *w = out + *len;
    if (quote) *w++ = '"';
    for (const char *c = field; *c; ++c) {
        if (quote && *c == '"') *w++ = '"';
        *w++ = *c;
    }
    if (quote) *w++ = '"';
    *w = '\0';
    *len = (size_t)(w - out);
    return 0;
}
