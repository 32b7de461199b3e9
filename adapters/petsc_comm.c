#include "adapters/petsc_comm.h"

#include <petscsf.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc.h"
#include "adapters/petsc_error.h"
#include "core/error.h"

#define MAX_WIDTH 16

typedef struct {
    MPI_Comm comm;
    int rank, ranks;
    int planned;              /* a halo plan was given */
    int n_ghosts, n_nodes;
    int *ghost_node;          /* local id of ghost j */
    PetscSFNode *owner;       /* ghost j's owner rank and its node's id there */
    /* Per width, an SF of single doubles (PETSc's reductions take MPI_SUM on
     * built-in types only): leaf j w + d is value d of ghost j, its root
     * value d of the owner's node. Made when a width is first used. */
    PetscSF sf[MAX_WIDTH + 1];
    double *leaf;             /* n_ghosts * width: the ghosts' values, contiguous for the SF */
    size_t cap_leaf;
    double *gathered;         /* sum: every rank's values */
    size_t cap_gathered;
    CommStats stats;
    long root_leaves;         /* other ranks' ghosts of this rank's nodes (-1: not counted yet for this plan) */
} PetscComm;

/* an operation's bytes and time into the counts: a sum sends the ghosts'
 * values, a copy the owned nodes' values to the ranks holding them as ghosts */
static int counted_halo(PetscComm *c, double t0, int width, int is_sum, int st)
{
    const double ghosts = 8.0 * c->n_ghosts * width, roots = 8.0 * (c->root_leaves > 0 ? c->root_leaves : 0) * width;
    c->stats.halo_ops++;
    c->stats.halo_bytes_sent += is_sum ? ghosts : roots;
    c->stats.halo_bytes_received += is_sum ? roots : ghosts;
    c->stats.halo_s += MPI_Wtime() - t0;
    return st;
}

static int counted_collective(PetscComm *c, double t0, int st)
{
    c->stats.collectives++;
    c->stats.collective_s += MPI_Wtime() - t0;
    return st;
}

static void comm_stats(void *ctx, CommStats *out) { *out = ((PetscComm *)ctx)->stats; }

static int mpi_status(int code, const char *what)
{
    if (code == MPI_SUCCESS) return MPM_OK;
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(code, text, &len);
    return mpm_error(MPM_EINTERNAL, "petsc communication: %s failed (%.*s)", what, len, text);
}

static int mpi_agree(void *ctx, int status, int *agreed)
{
    PetscComm *c = ctx;
    const double t0 = MPI_Wtime();
    return counted_collective(
        c, t0, mpi_status(MPI_Allreduce(&status, agreed, 1, MPI_INT, MPI_MAX, c->comm), "MPI_Allreduce"));
}

static int comm_sum_uncounted(PetscComm *c, double *values, int n)
{
    size_t need = (size_t)n * (size_t)c->ranks;
    if (need > c->cap_gathered) {
        double *g = realloc(c->gathered, sizeof(double) * need);
        if (!g) return mpm_error(MPM_EINTERNAL, "out of memory: a sum of %d values", n);
        c->gathered = g;
        c->cap_gathered = need;
    }
    int st = mpi_status(MPI_Allgather(values, n, MPI_DOUBLE, c->gathered, n, MPI_DOUBLE, c->comm), "MPI_Allgather");
    if (st) return st;
    for (int i = 0; i < n; ++i) { /* rank order: the same bits on every rank */
        double s = 0.0;
        for (int r = 0; r < c->ranks; ++r) s += c->gathered[(size_t)r * n + i];
        values[i] = s;
    }
    return MPM_OK;
}

static int comm_sum(void *ctx, double *values, int n)
{
    PetscComm *c = ctx;
    const double t0 = MPI_Wtime();
    return counted_collective(c, t0, comm_sum_uncounted(c, values, n));
}

static int comm_max(void *ctx, double *values, int n)
{
    PetscComm *c = ctx;
    const double t0 = MPI_Wtime();
    return counted_collective(
        c, t0, mpi_status(MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_MAX, c->comm), "MPI_Allreduce"));
}

static int exchange_uncounted(PetscComm *c, const int *send_counts, const uint64_t *send, int *recv_counts,
                              uint64_t **recv)
{
    const int R = c->ranks;
    *recv = NULL;
    int st = mpi_status(MPI_Alltoall((void *)send_counts, 1, MPI_INT, recv_counts, 1, MPI_INT, c->comm), "MPI_Alltoall");
    if (st) return st;
    int *sdispl = malloc(sizeof(int) * (size_t)R), *rdispl = malloc(sizeof(int) * (size_t)R);
    size_t total = 0;
    for (int r = 0; sdispl && rdispl && r < R; ++r) {
        sdispl[r] = r ? sdispl[r - 1] + send_counts[r - 1] : 0;
        rdispl[r] = (int)total;
        total += (size_t)recv_counts[r];
    }
    *recv = malloc(sizeof(uint64_t) * (total ? total : 1));
    /* every rank reaches the Alltoallv, also one out of memory: it then sends
     * nothing, and the caller's agreement stops every rank */
    int ok = sdispl && rdispl && *recv;
    if (!ok) {
        int *zeros = calloc((size_t)R, sizeof(int));
        free(sdispl), free(rdispl), free(*recv);
        *recv = NULL;
        if (!zeros) return mpm_error(MPM_EINTERNAL, "out of memory: an exchange of %zu items", total);
        uint64_t dummy = 0;
        MPI_Alltoallv(&dummy, zeros, zeros, MPI_UINT64_T, &dummy, zeros, zeros, MPI_UINT64_T, c->comm);
        free(zeros);
        return mpm_error(MPM_EINTERNAL, "out of memory: an exchange of %zu items", total);
    }
    st = mpi_status(MPI_Alltoallv((void *)send, (int *)send_counts, sdispl, MPI_UINT64_T, *recv, recv_counts, rdispl,
                                  MPI_UINT64_T, c->comm),
                    "MPI_Alltoallv");
    free(sdispl);
    free(rdispl);
    return st;
}

static int comm_exchange(void *ctx, const int *send_counts, const uint64_t *send, int *recv_counts, uint64_t **recv)
{
    PetscComm *c = ctx;
    const double t0 = MPI_Wtime();
    return counted_collective(c, t0, exchange_uncounted(c, send_counts, send, recv_counts, recv));
}

static void drop_sfs(PetscComm *c)
{
    for (int w = 0; w <= MAX_WIDTH; ++w)
        if (c->sf[w]) PetscSFDestroy(&c->sf[w]);
}

static int comm_halo_plan(void *ctx, const HaloPlan *plan, int n_nodes)
{
    PetscComm *c = ctx;
    drop_sfs(c);
    c->planned = 0;
    int n = plan->n_ghosts;
    int *ids = realloc(c->ghost_node, sizeof(int) * (size_t)(n ? n : 1));
    if (ids) c->ghost_node = ids;
    PetscSFNode *owner = ids ? realloc(c->owner, sizeof(PetscSFNode) * (size_t)(n ? n : 1)) : NULL;
    if (!owner) return mpm_error(MPM_EINTERNAL, "out of memory: a halo of %d ghost nodes", n);
    c->owner = owner;
    for (int j = 0; j < n; ++j) {
        ids[j] = plan->ghost_node[j];
        owner[j].rank = plan->owner_rank[j];
        owner[j].index = plan->owner_node[j];
    }
    c->n_ghosts = n;
    c->n_nodes = n_nodes;
    c->planned = 1;
    c->root_leaves = -1;
    return MPM_OK;
}

/* The leaf buffer and the SF of `width` doubles a node. */
static int halo_ready(PetscComm *c, int width, PetscSF *sf)
{
    if (!c->planned) return mpm_error(MPM_EINTERNAL, "petsc communication: a halo operation before a halo plan");
    if (width < 1 || width > MAX_WIDTH)
        return mpm_error(MPM_EINTERNAL, "petsc communication: a node field of %d values (1 to %d)", width, MAX_WIDTH);
    size_t need = (size_t)c->n_ghosts * (size_t)width;
    if (need > c->cap_leaf) {
        double *l = realloc(c->leaf, sizeof(double) * need);
        if (!l) return mpm_error(MPM_EINTERNAL, "out of memory: a halo of %zu values", need);
        c->leaf = l;
        c->cap_leaf = need;
    }
    if (!c->sf[width]) {
        /* SF creation is collective: a rank out of memory still agrees first */
        PetscSFNode *remote = malloc(sizeof(PetscSFNode) * (need ? need : 1));
        int mine = remote ? MPM_OK : MPM_EINTERNAL, all = MPM_OK;
        int st = mpi_agree(c, mine, &all);
        if (st || all) {
            free(remote);
            return st ? st
                      : mpm_error(MPM_EINTERNAL, "%s: a halo of %zu values",
                                  mine ? "out of memory" : "another rank ran out of memory", need);
        }
        for (int j = 0; j < c->n_ghosts; ++j)
            for (int d = 0; d < width; ++d) {
                remote[(size_t)j * width + d].rank = c->owner[j].rank;
                remote[(size_t)j * width + d].index = c->owner[j].index * width + d;
            }
        st = petsc_status(PetscSFCreate(c->comm, &c->sf[width]), MPM_EINTERNAL, "PetscSFCreate");
        if (!st)
            st = petsc_status(PetscSFSetGraph(c->sf[width], (PetscInt)c->n_nodes * width, (PetscInt)need, NULL,
                                              PETSC_COPY_VALUES, remote, PETSC_COPY_VALUES),
                              MPM_EINTERNAL, "PetscSFSetGraph");
        if (!st) st = petsc_status(PetscSFSetUp(c->sf[width]), MPM_EINTERNAL, "PetscSFSetUp");
        free(remote);
        if (st) return st;
    }
    if (c->root_leaves < 0) { /* once per plan, collective as every halo operation */
        const PetscInt *degree = NULL;
        int st = petsc_status(PetscSFComputeDegreeBegin(c->sf[width], &degree), MPM_EINTERNAL, "PetscSFComputeDegree");
        if (!st) st = petsc_status(PetscSFComputeDegreeEnd(c->sf[width], &degree), MPM_EINTERNAL, "PetscSFComputeDegree");
        if (st) return st;
        long leaves = 0;
        for (PetscInt k = 0; k < (PetscInt)c->n_nodes * width; ++k) leaves += degree[k];
        c->root_leaves = leaves / width;
    }
    *sf = c->sf[width];
    return MPM_OK;
}

static int comm_halo_sum(void *ctx, double *values, int width)
{
    PetscComm *c = ctx;
    const double t0 = MPI_Wtime();
    PetscSF sf;
    int st = halo_ready(c, width, &sf);
    if (st) return st;
    for (int j = 0; j < c->n_ghosts; ++j)
        memcpy(c->leaf + (size_t)j * width, values + (size_t)c->ghost_node[j] * width, sizeof(double) * width);
    st = petsc_status(PetscSFReduceBegin(sf, MPI_DOUBLE, c->leaf, values, MPI_SUM), MPM_EINTERNAL, "PetscSFReduceBegin");
    if (!st) st = petsc_status(PetscSFReduceEnd(sf, MPI_DOUBLE, c->leaf, values, MPI_SUM), MPM_EINTERNAL, "PetscSFReduceEnd");
    return counted_halo(c, t0, width, 1, st);
}

static int comm_halo_copy(void *ctx, double *values, int width)
{
    PetscComm *c = ctx;
    const double t0 = MPI_Wtime();
    PetscSF sf;
    int st = halo_ready(c, width, &sf);
    if (st) return st;
    st = petsc_status(PetscSFBcastBegin(sf, MPI_DOUBLE, values, c->leaf, MPI_REPLACE), MPM_EINTERNAL, "PetscSFBcastBegin");
    if (!st) st = petsc_status(PetscSFBcastEnd(sf, MPI_DOUBLE, values, c->leaf, MPI_REPLACE), MPM_EINTERNAL, "PetscSFBcastEnd");
    for (int j = 0; !st && j < c->n_ghosts; ++j)
        memcpy(values + (size_t)c->ghost_node[j] * width, c->leaf + (size_t)j * width, sizeof(double) * width);
    return counted_halo(c, t0, width, 0, st);
}

static void comm_close(void *ctx)
{
    PetscComm *c = ctx;
    if (!c) return;
    drop_sfs(c);
    free(c->ghost_node);
    free(c->owner);
    free(c->leaf);
    free(c->gathered);
    free(c);
}

int petsc_comm_open(CommOps *ops)
{
    int st = petsc_library_startup();
    if (st) return st;
    PetscComm *c = calloc(1, sizeof *c);
    if (!c) return mpm_error(MPM_EINTERNAL, "out of memory: petsc communication");
    c->comm = PETSC_COMM_WORLD;
    MPI_Comm_rank(c->comm, &c->rank);
    MPI_Comm_size(c->comm, &c->ranks);
    *ops = (CommOps){.ctx = c,
                     .rank = c->rank,
                     .ranks = c->ranks,
                     .agree = mpi_agree,
                     .sum = comm_sum,
                     .max = comm_max,
                     .exchange = comm_exchange,
                     .halo_plan = comm_halo_plan,
                     .halo_sum = comm_halo_sum,
                     .halo_copy = comm_halo_copy,
                     .stats = comm_stats,
                     .close = comm_close};
    return MPM_OK;
}
