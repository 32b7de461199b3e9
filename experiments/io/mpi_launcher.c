#include "experiments/io/mpi_launcher.h"

#include <stdlib.h>

int under_mpi_launcher(void)
{
    /* Open MPI, PMIx, MPICH/Hydra and Slurm's PMI */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"};
    for (int i = 0; i < 4; ++i)
        if (getenv(vars[i])) return 1;
    return 0;
}
