/* One MPI start-up for the adapters (adapters/mpi_startup.h). */
#include "adapters/mpi_startup.h"

#include <mpi.h>
#include <stdlib.h>

#include "core/error.h"

static int g_started = 0; /* adapter_mpi_start succeeded once */

static void finalize_mpi(void)
{
    if (adapter_mpi_running()) MPI_Finalize();
}

int adapter_mpi_running(void)
{
    int inited = 0, finalized = 0;
    MPI_Initialized(&inited);
    MPI_Finalized(&finalized);
    return inited && !finalized;
}

int adapter_mpi_start(const char *who)
{
    if (g_started) return MPM_OK;
    int inited = 0, finalized = 0;
    MPI_Initialized(&inited);
    MPI_Finalized(&finalized);
    if (finalized) return mpm_error(MPM_EINTERNAL, "%s: MPI has already been finalised", who);
    if (!inited) {
        if (MPI_Init(NULL, NULL) != MPI_SUCCESS) return mpm_error(MPM_EINTERNAL, "%s: MPI_Init failed", who);
        /* first, so that it runs after every library finaliser registered later */
        atexit(finalize_mpi);
    }
    g_started = 1;
    return MPM_OK;
}
