/* The one table of run settings: every setting of `mpmbench run`
 * (RunConfig), with its flag, its matrix-file key, its type and range, and
 * its help. It drives
 *   - the `run` command line (and the run settings `bench` and `render`
 *     take), experiments/cli/cli.c;
 *   - the matrix file's keys in "defaults", "scenes.NAME" and "axes", and a
 *     cell's settings and id, experiments/matrix/matrix_file.c and
 *     matrix_cells.c;
 *   - a cell's child process arguments (run_config_argv below);
 *   - every --help text.
 * Adding a run setting is adding its RunConfig field and one line here. */
#ifndef MPM_RUN_SETTINGS_H
#define MPM_RUN_SETTINGS_H

#include <stddef.h>

#include "experiments/cli/options.h"
#include "experiments/run/run.h"

#define RUN_SETTINGS_MAX 64                /* entries the table may have (a cell's given mask is 64 bits) */

extern const Option run_settings[];   /* ends with an entry whose flag is NULL */
extern const int run_settings_count;  /* without that end */

/* Index of the entry with this matrix key, -1 when none. */
int run_setting_index(const char *key);
/* The table's entry for a flag ("--eps") or a matrix key ("eps"), NULL when none. */
const Option *run_setting_by_flag(const char *flag);
const Option *run_setting_by_key(const char *key);

/* The `mpmbench run` arguments that give a RunConfig equal to cfg
 * (without the program; the first is "run"), NUL-separated in buf, in table
 * order; a setting is written when it differs from run_config_default's (or
 * is marked OPT_ARGV_ALWAYS). MPM_EINPUT when they do not fit in cap. */
int run_config_argv(const RunConfig *cfg, char *buf, size_t cap, int *argc);

/* Do a and b hold the same value of every setting of the table? On a
 * difference, which (its flag) in *first_diff. */
int run_config_equal(const RunConfig *a, const RunConfig *b, const char **first_diff);

#endif
