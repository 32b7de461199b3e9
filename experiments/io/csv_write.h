/* Text fields of the CSV files a run writes (RFC 4180). */
#ifndef MPM_CSV_WRITE_H
#define MPM_CSV_WRITE_H

#include <stdio.h>

/* Always quoted, inner quotes doubled, line breaks as spaces (free text:
 * a solve's reason). */
void csv_write_text(FILE *f, const char *s);
/* A name (scene, solver spec): as it is, or quoted like csv_write_text when
 * it holds a comma, quote or line break (a spec with several options). */
void csv_write_name(FILE *f, const char *s);

#endif
