#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "solvers/inverse_approx.h"

double solver_opt_number(const SolverOptions *o, const char *key, double def, int *status)
{
    if (!o) return def;
    for (int i = 0; i < o->n; ++i) {
        if (strcmp(o->key[i], key) != 0) continue;
        char *end = NULL;
        double v = strtod(o->value[i], &end);
        if (end == o->value[i] || *end != '\0') {
            *status = mpm_error(MPM_EINPUT, "--solver-opt %s=%s: expected a number", key, o->value[i]);
            return def;
        }
        return v;
    }
    return def;
}

const char *solver_opt_string(const SolverOptions *o, const char *key, const char *def)
{
    if (!o) return def;
    for (int i = 0; i < o->n; ++i)
        if (strcmp(o->key[i], key) == 0) return o->value[i];
    return def;
}
