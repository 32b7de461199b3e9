/* One cell as a child process of the same binary (`/proc/self/exe run ...`),
 * so a crash, a bad input or the wall-clock limit of one cell becomes its
 * status and the matrix goes on.
 *
 * The child runs in its own process group (a timed-out cell is killed with
 * its whole group), gets SIGKILL when the runner dies (so a killed matrix
 * leaves no cell running behind it), writes stdout and stderr to
 * DIR/stdout.txt and DIR/stderr.txt, reads /dev/null, and inherits the
 * environment without the variables of an MPI launcher (OMPI_*, PMIX_*,
 * PMI_*, ...): under `mpirun` a child that initialises MPI (the hypre
 * adapter does) must be an MPI singleton of its own, not try to join the
 * runner's job. */
#ifndef MPM_MATRIX_CHILD_H
#define MPM_MATRIX_CHILD_H

#include <sys/types.h>

#include "experiments/matrix/matrix_measure.h"

typedef struct {
    pid_t pid;          /* 0: none running */
    double t_start;     /* monotonic seconds */
    double timeout_s;   /* 0: none */
    int timed_out;
    int ranks;          /* > 1: under mpirun */
    double busy0;       /* machine_busy_seconds() at the start */
    double load0;       /* machine_load1() at the start */
} CellChild;

/* Starts `mpmbench args[0] ... args[argc-1]` with its output files in dir
 * (which must exist); with ranks > 1 under `mpirun -np ranks` (the first
 * mpirun on PATH; Open MPI's variables let ranks outnumber cores and run
 * as root, bind no rank to a core, and OMP_NUM_THREADS is the cores over
 * the ranks). */
int cell_child_start(char *const *args, int argc, const char *dir, double timeout_s, int ranks, CellChild *c);
/* Never blocks: 0 while the child runs, 1 when it ended (reaped) with *out
 * set (with the machine's other CPU use meanwhile: others_cpu_s, load_start;
 * `busy` is for the caller, who knows the cell's threads). Past the timeout
 * it kills the child's process group first. */
int cell_child_poll(CellChild *c, CellOutcome *out);

/* Kills a running child's process group and reaps it (a study that ends on
 * an error leaves no cell behind); nothing when none runs. */
void cell_child_kill(CellChild *c);

/* Sleeps for `ms` milliseconds (the runners' polling interval). */
void matrix_sleep_ms(int ms);

/* Is `name=value` an MPI launcher's variable? (exposed for the tests) */
int matrix_is_launcher_env(const char *entry);

#endif
