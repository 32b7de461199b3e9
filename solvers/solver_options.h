/* Free-form solver options (`--solver-opt key=value`, a preset's defaults,
 * the `:k=v,...` tail of a solver spec), shared by every part of a solver.
 *
 * Every lookup records the key it asked for with the value in effect (given
 * or default), so that after a solver is created
 *  - a given key nobody asked for is reported as unknown (a typo must not
 *    run silently with the default; cf. PETSc's -options_left), and
 *  - the effective options can be written beside the results (run.json). */
#ifndef MPM_SOLVER_OPTIONS_H
#define MPM_SOLVER_OPTIONS_H

/* Room for a library's long option names (PETSc's
 * pc_hypre_boomeramg_strong_threshold is 35 characters; adapters/petsc.c
 * passes its keys through) and for every option of a solver whose inverse
 * approximation takes a library's options one by one. */
#define SOLVER_MAX_OPTS 48
#define SOLVER_OPT_KEY 48 /* characters of a key, with its NUL */
typedef struct {
    int n;
    char key[SOLVER_MAX_OPTS][SOLVER_OPT_KEY];
    char value[SOLVER_MAX_OPTS][64];
    int n_asked;                           /* distinct keys looked up */
    char asked[SOLVER_MAX_OPTS][SOLVER_OPT_KEY];
    char asked_value[SOLVER_MAX_OPTS][64]; /* value in effect */
} SolverOptions;

/* Sets one "key=value" (a later value for the same key wins). `origin` names
 * where it came from in the error message ("--solver-opt", "preset pn-pcg"). */
int solver_opts_set(SolverOptions *o, const char *key_value, const char *origin);
/* Sets every item of a comma-separated "key=value,key=value" list ("" = none). */
int solver_opts_set_list(SolverOptions *o, const char *list, const char *origin);

/* Looks up an option; returns the default when absent, and MPM_EINPUT through
 * *status (left untouched on success) when present but not a finite number. */
double solver_opt_number(SolverOptions *o, const char *key, double def, int *status);
/* Same for an integer option: the value must be a number with no fractional
 * part within [lo, hi] (window=2.5 or window=1e10 are errors naming the key
 * and value, never a silent cast). */
int solver_opt_int(SolverOptions *o, const char *key, int def, int lo, int hi, int *status);
const char *solver_opt_string(SolverOptions *o, const char *key, const char *def);
/* MPM_EINPUT naming the first option no lookup asked for, and the options
 * `who` does take. */
int solver_opts_check_used(const SolverOptions *o, const char *who);

#endif
