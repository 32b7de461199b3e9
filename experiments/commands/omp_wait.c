/* The OpenMP wait default (omp_wait.h). */
#define _GNU_SOURCE
#include "experiments/commands/omp_wait.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Under a tool that runs the program inside itself (valgrind), /proc/self/exe
 * is the tool, and a re-execution would leave it: the tool's own preload
 * library is in LD_PRELOAD. */
static int under_a_runner(void)
{
    const char *pre = getenv("LD_PRELOAD");
    return pre && strstr(pre, "vgpreload") != NULL;
}

void omp_wait_default(char **argv)
{
    /* MPM_OMP_WAIT_SET marks the second start, so it cannot loop */
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT") || getenv("MPM_KEEP_OMP_WAIT") ||
        getenv("MPM_OMP_WAIT_SET") || under_a_runner())
        return;
    char self[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0) return; /* no /proc: OpenMP's own default */
    self[len] = '\0';
    if (setenv("GOMP_SPINCOUNT", MPM_DEFAULT_SPINCOUNT, 1) || setenv("MPM_OMP_WAIT_SET", "1", 1)) return;
    execv(self, argv);
    /* not re-executed: OpenMP's own default, which has not read the variables */
    unsetenv("GOMP_SPINCOUNT");
    unsetenv("MPM_OMP_WAIT_SET");
}
