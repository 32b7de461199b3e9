/* The OpenMP wait default (omp_wait.h). */
#define _GNU_SOURCE
#include "experiments/commands/omp_wait.h"

#include <stdlib.h>
#include <unistd.h>

void omp_wait_default(char **argv)
{
    /* MPM_OMP_WAIT_SET marks the second start, so it cannot loop */
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT") || getenv("MPM_KEEP_OMP_WAIT") ||
        getenv("MPM_OMP_WAIT_SET"))
        return;
    if (setenv("GOMP_SPINCOUNT", MPM_DEFAULT_SPINCOUNT, 1) || setenv("MPM_OMP_WAIT_SET", "1", 1)) return;
    execv("/proc/self/exe", argv);
    /* not re-executed (no /proc): OpenMP's own default, which has not read the variables */
    unsetenv("GOMP_SPINCOUNT");
    unsetenv("MPM_OMP_WAIT_SET");
}
