#include <stdlib.h>
#include <string.h>

#include "core/dist/comm_ops.h"
#include "core/error.h"

static int serial_agree(void *ctx, int status, int *agreed)
{
    (void)ctx;
    *agreed = status;
    return MPM_OK;
}

static int serial_reduce(void *ctx, double *values, int n)
{
    (void)ctx, (void)values, (void)n;
    return MPM_OK;
}

static int serial_exchange(void *ctx, const int *send_counts, const uint64_t *send, int *recv_counts, uint64_t **recv)
{
    (void)ctx;
    recv_counts[0] = send_counts[0];
    *recv = malloc(sizeof(uint64_t) * (size_t)(send_counts[0] > 0 ? send_counts[0] : 1));
    if (!*recv) return mpm_error(MPM_EINTERNAL, "out of memory: exchange of %d items", send_counts[0]);
    if (send_counts[0]) memcpy(*recv, send, sizeof(uint64_t) * (size_t)send_counts[0]);
    return MPM_OK;
}

static int serial_halo_plan(void *ctx, const HaloPlan *plan, int n_nodes)
{
    (void)ctx, (void)n_nodes;
    if (plan->n_ghosts)
        return mpm_error(MPM_EINTERNAL, "serial communication: a halo plan with %d ghost nodes on one rank",
                         plan->n_ghosts);
    return MPM_OK;
}

static int serial_halo(void *ctx, double *node_values, int width)
{
    (void)ctx, (void)node_values, (void)width;
    return MPM_OK;
}

static void serial_close(void *ctx) { (void)ctx; }

const CommOps *comm_serial(void)
{
    static const CommOps ops = {.ctx = NULL,
                                .rank = 0,
                                .ranks = 1,
                                .agree = serial_agree,
                                .sum = serial_reduce,
                                .max = serial_reduce,
                                .exchange = serial_exchange,
                                .halo_plan = serial_halo_plan,
                                .halo_sum = serial_halo,
                                .halo_copy = serial_halo,
                                .close = serial_close};
    return &ops;
}
