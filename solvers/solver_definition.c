/* A solver's resolved definition and its hash (solver_definition.h). */
#include "solvers/solver_definition.h"

#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

/* FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3). */
static uint64_t fnv1a64(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (; *s; ++s) h = (h ^ (unsigned char)*s) * 0x100000001b3ULL;
    return h;
}

int solver_definition(const Solver *s, char *text, size_t cap, char hash[SOLVER_DEFINITION_HASH_LEN])
{
    const SolverOptions *o = &s->opts;
    int order[SOLVER_MAX_OPTS]; /* the asked keys' rows, sorted by key (insertion: at most SOLVER_MAX_OPTS) */
    for (int i = 0; i < o->n_asked; ++i) {
        int j = i;
        for (; j > 0 && strcmp(o->asked[order[j - 1]], o->asked[i]) > 0; --j) order[j] = order[j - 1];
        order[j] = i;
    }
    size_t used = 0;
    int w = snprintf(text, cap, "outer=%s\ninverse=%s\n", s->outer->ops->name, s->inv->ops->name);
    for (int k = 0; w >= 0 && (size_t)w < cap - used && k < o->n_asked; ++k) {
        used += (size_t)w;
        w = snprintf(text + used, cap - used, "%s=%s\n", o->asked[order[k]], o->asked_value[order[k]]);
    }
    if (w < 0 || (size_t)w >= cap - used) return mpm_error(MPM_EINTERNAL, "solver definition longer than %zu bytes", cap);
    snprintf(hash, SOLVER_DEFINITION_HASH_LEN, "%016" PRIx64, fnv1a64(text));
    return MPM_OK;
}
