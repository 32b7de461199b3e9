/* PETSc's errors as mpmbench statuses (adapters/petsc_error.h). */
#include "adapters/petsc_error.h"

#include <stdio.h>

#include "core/error.h"

static char g_message[400];

PetscErrorCode petsc_record_error(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode code,
                                  PetscErrorType type, const char *message, void *ctx)
{
    (void)comm, (void)line, (void)file, (void)ctx;
    if (type == PETSC_ERROR_INITIAL) {
        snprintf(g_message, sizeof g_message, "%s: %s", fun ? fun : "?", message ? message : "");
        for (char *c = g_message; *c; ++c)
            if (*c == '\n' || *c == '\r') *c = ' ';
    }
    return code;
}

int petsc_status(PetscErrorCode code, int status, const char *what)
{
    if (!code) return MPM_OK;
    int st = mpm_error(status, "petsc: %s failed (PETSc error %d: %s)", what, (int)code, g_message);
    g_message[0] = '\0';
    return st;
}
