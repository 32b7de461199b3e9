/* The registry of named solver presets: the only place that knows every
 * implementation (DESIGN floor 4). Adding a solver = one line here. */
#ifndef MPM_REGISTRY_H
#define MPM_REGISTRY_H

#include "solvers/solver.h"

int registry_count(void);
const SolverPreset *registry_get(int i);
/* NULL when unknown. */
const SolverPreset *registry_find(const char *name);
/* Parses "key=value,key=value" defaults of a preset, then user options on top
 * (user wins). Returns MPM_EINPUT on a malformed option. */
int registry_options(const SolverPreset *p, const char *const *user, int n_user, SolverOptions *out);

#endif
