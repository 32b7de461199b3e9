/* The communication operations of a distributed step (core/dist/comm_ops.h)
 * across MPI ranks: the halo through a PetscSF (ghost leaves, owner roots:
 * PetscSFReduce with MPI_SUM for the halo sum, PetscSFBcast for the halo
 * copy), the reductions and the exchange through MPI collectives on
 * PETSC_COMM_WORLD. A sum gathers every rank's values and adds them in rank
 * order, so every rank gets the same bits on every run. */
#ifndef MPM_PETSC_COMM_H
#define MPM_PETSC_COMM_H

#include "core/dist/comm_ops.h"

/* Starts PETSc (and MPI) when not yet started and fills *ops; ops->close
 * frees what it holds. MPM_EINTERNAL with PETSc's or MPI's message. */
int petsc_comm_open(CommOps *ops);

#endif
