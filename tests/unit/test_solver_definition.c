/* floor: driver */
/* A solver's resolved definition (solvers/solver_definition.h):
 *  - the text is "outer=", "inverse=", then every consulted option with its
 *    value in effect, sorted by key, one a line;
 *  - the hash is FNV-1a 64 of that text (checked against the published
 *    test vector of the empty string and of "a", and recomputed here);
 *  - a preset and the composition it names with the same options give the
 *    same definition; a changed option value, a different inverse or outer
 *    method give a different hash. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "experiments/driver/registry.h"
#include "solvers/solver_definition.h"
#include "tests/common/testutil.h"

static uint64_t fnv(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (; *s; ++s) h = (h ^ (unsigned char)*s) * 0x100000001b3ULL;
    return h;
}

static int define(const char *spec, char *text, size_t cap, char *hash)
{
    Solver *s = NULL;
    int st = solver_from_spec(spec, NULL, 0, &s);
    if (!st) st = solver_definition(s, text, cap, hash);
    CHECK(st == MPM_OK, "%s: %s", spec, mpm_last_error());
    solver_destroy(s);
    return st;
}

int main(void)
{
    CHECK(fnv("") == 0xcbf29ce484222325ULL && fnv("a") == 0xaf63dc4c8601ec8cULL, "FNV-1a 64 test vectors");
    char t1[4096], t2[4096], h1[SOLVER_DEFINITION_HASH_LEN], h2[SOLVER_DEFINITION_HASH_LEN];
    if (define("pn-pcg", t1, sizeof t1, h1)) return test_summary("test_solver_definition");
    CHECK(!strncmp(t1, "outer=pn\ninverse=block-jacobi\n", 30), "starts with the parts: %s", t1);
    char expect[17];
    snprintf(expect, sizeof expect, "%016llx", (unsigned long long)fnv(t1));
    CHECK(!strcmp(h1, expect), "hash %s = FNV-1a of the text %s", h1, expect);
    /* options sorted, each once, the last line ends the text */
    const char *prev = NULL;
    int lines = 0;
    for (const char *l = strchr(strchr(t1, '\n') + 1, '\n') + 1; *l; l = strchr(l, '\n') + 1, ++lines) {
        CHECK(strchr(l, '=') && strchr(l, '\n'), "a key=value line: %.40s", l);
        if (prev) CHECK(strcmp(prev, l) < 0, "sorted: '%.20s' before '%.20s'", prev, l);
        prev = l;
    }
    CHECK(lines >= 5 && strstr(t1, "\nlinesearch=halving\n") && strstr(t1, "\nstop=cn\n"),
          "generic options with their defaults (%d lines): %s", lines, t1);
    /* the preset is its composition */
    define("pn:block-jacobi", t2, sizeof t2, h2);
    CHECK(!strcmp(t1, t2) && !strcmp(h1, h2), "pn-pcg = pn:block-jacobi: %s vs %s", h1, h2);
    /* any change shows */
    const char *other[] = {"pn-pcg:linesearch=armijo", "pn-pcg-scalar", "lbfgs:block-jacobi", "pn-pcg-mf"};
    for (int i = 0; i < 4; ++i) {
        define(other[i], t2, sizeof t2, h2);
        CHECK(strcmp(h1, h2) != 0, "%s differs from pn-pcg (%s)", other[i], h2);
    }
    /* too small a buffer is an error, not a truncated definition */
    Solver *s = NULL;
    if (solver_from_spec("hot", NULL, 0, &s) == MPM_OK) {
        mpm_clear_error();
        CHECK(solver_definition(s, t2, 40, h2) == MPM_EINTERNAL, "40 bytes refused");
        mpm_clear_error();
    }
    solver_destroy(s);
    return test_summary("test_solver_definition");
}
