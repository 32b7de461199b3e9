/* Whether the program was started by an MPI launcher (mpirun, mpiexec,
 * srun): its environment has the launcher's variables. A matrix run then
 * hands cells to ranks, and a `run` splits its scene over them; a matrix
 * cell's child process gets an environment without them
 * (experiments/matrix/matrix_child.c), so it runs alone. */
#ifndef MPM_MPI_LAUNCHER_H
#define MPM_MPI_LAUNCHER_H

/* The answer is the environment's at the first call, and main makes that
 * call before anything can start MPI: an MPI started without a launcher
 * (Open MPI's singleton, when a library such as PETSc initialises it) adds
 * the launcher's variables to the process's own environment. */
int under_mpi_launcher(void);

#endif
