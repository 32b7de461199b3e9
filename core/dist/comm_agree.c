#include "core/dist/comm_ops.h"
#include "core/error.h"

int comm_agree(const CommOps *comm, int status)
{
    int all = MPM_OK, st = comm->agree(comm->ctx, status, &all);
    if (st || status) return st ? st : status;
    return all ? mpm_error(all, "another rank failed (rank %d stops with it)", comm->rank) : MPM_OK;
}
