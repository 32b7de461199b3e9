/* floor: core */
/* Minimal test helpers: CHECK records a failure with file/line and goes on;
 * a test's main returns test_summary(), non-zero if anything failed. */
#ifndef MPM_TESTUTIL_H
#define MPM_TESTUTIL_H

#include <stdio.h>

extern int g_test_failures, g_test_checks;

#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        ++g_test_checks;                                                   \
        if (!(cond)) {                                                     \
            ++g_test_failures;                                             \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                  \
            fputc('\n', stderr);                                           \
        }                                                                  \
    } while (0)

/* Relative difference |a-b| / max(|a|,|b|,floor). */
double rel_diff(double a, double b, double floor_);

/* Deterministic uniform in [lo, hi) (splitmix64 stream owned by the caller). */
double test_uniform(unsigned long long *state, double lo, double hi);

/* Prints the counts; non-zero if a check failed or if no check ran at all. */
int test_summary(const char *name);

/* The exit status of a test that cannot run here (a tool or file it needs is
 * missing): CTest reports it as "Skipped" (tests/CMakeLists.txt). */
#define TEST_SKIPPED 77
/* Prints "name: SKIPPED: why" and returns TEST_SKIPPED (return it from main). */
int test_skip(const char *name, const char *why);

#endif
