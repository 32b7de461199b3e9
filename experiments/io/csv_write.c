#include "experiments/io/csv_write.h"

#include <string.h>

void csv_write_text(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; ++s) {
        if (*s == '"') fputc('"', f);
        fputc(*s == '\n' || *s == '\r' ? ' ' : *s, f);
    }
    fputc('"', f);
}

void csv_write_name(FILE *f, const char *s)
{
    if (strpbrk(s, ",\"\n\r")) csv_write_text(f, s);
    else fputs(s, f);
}
