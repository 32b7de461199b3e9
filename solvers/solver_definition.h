/* What a solver runs, independent of how it was named: its outer method, its
 * inverse approximation and every option its parts consulted with the value
 * in effect (the preset's, the user's or the default), one "key=value" a
 * line, "outer" and "inverse" first, the options after them sorted by key:
 *
 *     outer=lbfgs
 *     inverse=mg
 *     embedding=linear
 *     ...
 *
 * Its 64-bit FNV-1a hash, as 16 hex digits, names the definition in run.json
 * (solver_definition_hash). A study is stale for a solver when the hash its
 * runs recorded differs from the hash of the same spec in the current build
 * (`mpmbench list definitions`; scripts/study_status.py recomputes it from an
 * old run.json's outer_method, inverse_approximation and solver_options). */
#ifndef MPM_SOLVER_DEFINITION_H
#define MPM_SOLVER_DEFINITION_H

#include <stddef.h>

#include "solvers/solver.h"

#define SOLVER_DEFINITION_HASH_LEN 17 /* 16 hex digits and the NUL */

/* The definition of s into text (cap bytes) and its hash; MPM_EINTERNAL
 * when text is too small. */
int solver_definition(const Solver *s, char *text, size_t cap, char hash[SOLVER_DEFINITION_HASH_LEN]);

#endif
