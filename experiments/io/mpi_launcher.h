/* Whether the program was started by an MPI launcher (mpirun, mpiexec,
 * srun): its environment has the launcher's variables. A matrix run then
 * hands cells to ranks, and a `run` splits its scene over them; a matrix
 * cell's child process gets an environment without them
 * (experiments/matrix/matrix_child.c), so it runs alone. */
#ifndef MPM_MPI_LAUNCHER_H
#define MPM_MPI_LAUNCHER_H

int under_mpi_launcher(void);

#endif
