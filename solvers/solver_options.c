#include "solvers/solver_options.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

int solver_opts_set(SolverOptions *o, const char *kv, const char *origin)
{
    const char *eq = strchr(kv, '=');
    if (!eq || eq == kv || !eq[1]) return mpm_error(MPM_EINPUT, "%s '%s': expected key=value", origin, kv);
    size_t klen = (size_t)(eq - kv);
    if (klen >= sizeof o->key[0] || strlen(eq + 1) >= sizeof o->value[0])
        return mpm_error(MPM_EINPUT, "%s '%s': key or value too long", origin, kv);
    int slot = -1;
    for (int i = 0; i < o->n; ++i)
        if (strlen(o->key[i]) == klen && strncmp(o->key[i], kv, klen) == 0) slot = i;
    if (slot < 0) {
        if (o->n >= SOLVER_MAX_OPTS) return mpm_error(MPM_EINPUT, "%s '%s': too many solver options", origin, kv);
        slot = o->n++;
    }
    memcpy(o->key[slot], kv, klen);
    o->key[slot][klen] = '\0';
    snprintf(o->value[slot], sizeof o->value[slot], "%s", eq + 1);
    return MPM_OK;
}

int solver_opts_set_list(SolverOptions *o, const char *list, const char *origin)
{
    char buf[512];
    if (!list) return MPM_OK;
    if (strlen(list) >= sizeof buf) return mpm_error(MPM_EINPUT, "%s '%s': too long", origin, list);
    snprintf(buf, sizeof buf, "%s", list);
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int st = solver_opts_set(o, tok, origin);
        if (st) return st;
    }
    return MPM_OK;
}

static int asked_index(const SolverOptions *o, const char *key)
{
    for (int a = 0; a < o->n_asked; ++a)
        if (strcmp(o->asked[a], key) == 0) return a;
    return -1;
}

static int given_index(const SolverOptions *o, const char *key)
{
    for (int i = 0; i < o->n; ++i)
        if (strcmp(o->key[i], key) == 0) return i;
    return -1;
}

/* Index of key in o, -1 when absent; records key with the value in effect
 * (the given one, else def_text). */
static int lookup(SolverOptions *o, const char *key, const char *def_text)
{
    int i = given_index(o, key);
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
    if (end == o->value[i] || *end != '\0' || !isfinite(v)) {
        int st = mpm_error(MPM_EINPUT, "solver option %s=%s: expected a number", key, o->value[i]);
        if (!*status) *status = st;
        return def;
    }
    return v;
}

int solver_opt_int(SolverOptions *o, const char *key, int def, int lo, int hi, int *status)
{
    if (!o) return def;
    int st = MPM_OK;
    double v = solver_opt_number(o, key, def, &st);
    if (st) {
        if (!*status) *status = st;
        return def;
    }
    /* range first: a cast of 1e10 to int is undefined */
    if (!(v >= lo && v <= hi && v == floor(v))) {
        st = mpm_error(MPM_EINPUT, "solver option %s=%s: expected an integer in [%d, %d]", key,
                       o->value[given_index(o, key)], lo, hi);
        if (!*status) *status = st;
        return def;
    }
    return (int)v;
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
        return mpm_error(MPM_EINPUT, "solver option %s=%s: %s has no option '%s' (its options: %s)", o->key[i],
                         o->value[i], who, o->key[i], o->n_asked ? known : "none");
    }
    return MPM_OK;
}
