/* MPI for the adapters whose libraries need it (hypre, Trilinos ML, PETSc):
 * one start-up for all of them.
 *
 * adapter_mpi_start() calls MPI_Init(NULL, NULL) the first time it runs in a
 * process that has not initialised MPI, and then registers, before any
 * library's own finaliser, the MPI_Finalize that ends the process's MPI: at
 * exit, handlers run in the reverse order of registration (C11 7.22.4.2), so
 * every library that an adapter starts after this call (HYPRE_Init,
 * PetscInitialize) and finalises in an atexit handler of its own is
 * finalised while MPI is still up. A program that initialised MPI itself
 * (the matrix runner under mpirun) keeps it: nothing is registered, and the
 * program finalises MPI. Idempotent; MPM_EINTERNAL (one line) when MPI was
 * already finalised or MPI_Init fails. */
#ifndef MPM_ADAPTER_MPI_STARTUP_H
#define MPM_ADAPTER_MPI_STARTUP_H

/* `who` names the adapter in an error ("petsc: MPI_Init failed"). */
int adapter_mpi_start(const char *who);

/* 1 while MPI is initialised and not yet finalised: an adapter's at-exit
 * handler finalises its library only then (after MPI_Finalize nothing may
 * call MPI, so a library left behind by a program that finalised MPI
 * itself is left as it is). */
int adapter_mpi_running(void);

#endif
