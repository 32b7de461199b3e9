#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "solvers/inverse_approx.h"

static int asked_index(const SolverOptions *o, const char *key)
{
    for (int a = 0; a < o->n_asked; ++a)
        if (strcmp(o->asked[a], key) == 0) return a;
    return -1;
}

/* Index of key in o, -1 when absent; records key with the value in effect
 * (the given one, else def_text). */
static int lookup(SolverOptions *o, const char *key, const char *def_text)
{
    int i = 0;
    while (i < o->n && strcmp(o->key[i], key) != 0) ++i;
    if (i == o->n) i = -1;
    int a = o->n_asked;
    if (asked_index(o, key) < 0 && a < SOLVER_MAX_OPTS) {
        o->n_asked++;
        snprintf(o->asked[a], sizeof o->asked[0], "%s", key);
        snprintf(o->asked_value[a], sizeof o->asked_value[0], "%s", i >= 0 ? o->value[i] : def_text);
    }
    return i;
}

double solver_opt_number(SolverOptions *o, const char *key, double def, int *status)
{
    if (!o) return def;
    char def_text[64];
    snprintf(def_text, sizeof def_text, "%.15g", def);
    int i = lookup(o, key, def_text);
    if (i < 0) return def;
    char *end = NULL;
    double v = strtod(o->value[i], &end);
    if (end == o->value[i] || *end != '\0') {
        *status = mpm_error(MPM_EINPUT, "--solver-opt %s=%s: expected a number", key, o->value[i]);
        return def;
    }
    return v;
}

const char *solver_opt_string(SolverOptions *o, const char *key, const char *def)
{
    if (!o) return def;
    int i = lookup(o, key, def ? def : "");
    return i < 0 ? def : o->value[i];
}

int solver_opts_check_used(const SolverOptions *o, const char *who)
{
    for (int i = 0; i < o->n; ++i) {
        if (asked_index(o, o->key[i]) >= 0) continue;
        char known[512] = "";
        size_t len = 0;
        for (int k = 0; k < o->n_asked && len < sizeof known; ++k)
            len += (size_t)snprintf(known + len, sizeof known - len, "%s%s", k ? ", " : "", o->asked[k]);
        return mpm_error(MPM_EINPUT, "--solver-opt %s=%s: %s has no option '%s' (its options: %s)", o->key[i],
                         o->value[i], who, o->key[i], o->n_asked ? known : "none");
    }
    return MPM_OK;
}
