#include "core/dist/node_numbering.h"

#include <stdlib.h>

#include "core/error.h"

int dist_node_numbering(const CommOps *comm, const unsigned char *owned, int n, int *global, NodeNumbering *out)
{
    int n_owned = 0;
    for (int i = 0; i < n; ++i) n_owned += owned[i] != 0;
    /* each rank's count at its own slot; the sum gives every rank all counts */
    double *counts = calloc((size_t)comm->ranks, sizeof(double));
    double *number = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
    int st = counts && number ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: node numbering (%d nodes)", n);
    if ((st = comm_agree(comm, st))) {
        free(counts);
        free(number);
        return st;
    }
    counts[comm->rank] = n_owned;
    if (comm->sum(comm->ctx, counts, comm->ranks)) st = MPM_EINTERNAL;
    double first = 0, total = 0;
    for (int r = 0; r < comm->ranks && !st; ++r) {
        if (r < comm->rank) first += counts[r];
        total += counts[r];
    }
    /* every rank sees the same total, so all of them stop here or none */
    if (!st && total > 0x7fffffff) st = mpm_error(MPM_EINPUT, "node numbering: %.0f nodes overflow 32-bit numbers", total);
    if (!st) {
        out->n_owned = n_owned;
        out->first = (int)first;
        out->total = (int)total;
        int next = out->first;
        for (int i = 0; i < n; ++i) number[i] = owned[i] ? next++ : -1.0;
        /* the ghosts from their owners (numbers below 2^53 are exact doubles) */
        if (comm->halo_copy(comm->ctx, number, 1)) st = MPM_EINTERNAL;
        for (int i = 0; i < n && !st; ++i) {
            global[i] = (int)number[i];
            if (global[i] < 0 || global[i] >= out->total)
                st = mpm_error(MPM_EINTERNAL, "node numbering: local node %d got %d of %d", i, global[i], out->total);
        }
    }
    free(counts);
    free(number);
    return comm_agree(comm, st); /* a rank's bad number fails them all before the caller's next collective */
}
