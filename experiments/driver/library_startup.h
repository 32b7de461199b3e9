/* Library start-up before a run's first step, so that no step is charged
 * with it: the OpenMP thread team, and for the solvers that use them MPI +
 * hypre (MPI_Init, HYPRE_Init) and CHOLMOD, through the inverse
 * approximation's library_startup op (no type test: the implementation says
 * what it needs). Timed as the run's startup_s (run.json, cells.csv). */
#ifndef MPM_LIBRARY_STARTUP_H
#define MPM_LIBRARY_STARTUP_H

#include "solvers/solver.h"

/* Starts what `solver` needs (call after setting the thread count); adds the
 * seconds taken to library_startup_seconds(). */
int library_startup(const Solver *solver);
double library_startup_seconds(void);

#endif
