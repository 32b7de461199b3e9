/* PETSc's errors as mpmbench statuses, for the PETSc adapter's files
 * (adapters/petsc.c, adapters/petsc_hierarchy.c).
 *
 * petsc_record_error is pushed as PETSc's error handler at start-up: it keeps
 * PETSc's first message of a failure on one line and prints nothing;
 * petsc_status turns a PETSc return code into one mpm_error line with it. */
#ifndef MPM_PETSC_ERROR_H
#define MPM_PETSC_ERROR_H

#include <petscsys.h>

PetscErrorCode petsc_record_error(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode code,
                                  PetscErrorType type, const char *message, void *ctx);

/* MPM_OK for code 0; else `status` (an MPM_E* code) with "petsc: WHAT failed
 * (PETSc error N: message)". */
int petsc_status(PetscErrorCode code, int status, const char *what);

#endif
