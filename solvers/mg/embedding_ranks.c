/* Coarse levels over ranks (solvers/mg/embedding_ranks.h). Two exchanges a
 * level: ghost coarse nodes' coordinates to their owners, and the owners'
 * global numbers back, in the order asked. */
#include "solvers/mg/embedding_ranks.h"

#include <stdlib.h>
#include <string.h>

#include "core/dist/node_pack.h"
#include "core/error.h"
#include "core/node_order.h"

typedef struct {
    uint64_t key, packed;
} KeyedNode;

static int by_key(const void *a, const void *b)
{
    const uint64_t x = ((const KeyedNode *)a)->key, y = ((const KeyedNode *)b)->key;
    return (x > y) - (x < y);
}

/* index of `key` in the sorted owned list, or -1 */
static int find_key(const KeyedNode *list, int n, uint64_t key)
{
    int lo = 0, hi = n - 1;
    while (lo <= hi) {
        const int mid = lo + (hi - lo) / 2;
        if (list[mid].key == key) return mid;
        if (list[mid].key < key) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

static int grow(int **p, int *cap, int n)
{
    if (n <= *cap) return MPM_OK;
    int *q = realloc(*p, sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: coarse level over ranks (%d)", n);
    *p = q;
    *cap = n;
    return MPM_OK;
}

int mg_coarse_ranks(const CommOps *comm, const Decomposition *d, int level, const MgTransfer *T, MgCoarseRanks *out)
{
    const int R = comm->ranks, me = comm->rank, m = T->n_coarse;
    int *owner = malloc(sizeof(int) * (size_t)(m > 0 ? m : 1));
    int *slot = malloc(sizeof(int) * (size_t)(m > 0 ? m : 1));
    int *send_counts = calloc((size_t)R, sizeof(int)), *recv_counts = calloc((size_t)R, sizeof(int));
    int *back_counts = calloc((size_t)R, sizeof(int)), *start = calloc((size_t)R + 1, sizeof(int));
    double *counts = calloc((size_t)R, sizeof(double));
    uint64_t *send = NULL, *recv = NULL, *reply = NULL, *back = NULL;
    KeyedNode *list = NULL;
    int st = owner && slot && send_counts && recv_counts && back_counts && start && counts
                 ? MPM_OK
                 : mpm_error(MPM_EINTERNAL, "out of memory: coarse level over ranks (%d nodes)", m);
    if (!st && (level < 1 || level > 20)) st = mpm_error(MPM_EINTERNAL, "coarse level %d over ranks", level);
    if (!st) st = grow(&out->global, &out->cap_global, m);
    /* the owner of each coarse node: the rank owning its fine-grid position */
    int n_ask = 0;
    for (int k = 0; k < m && !st; ++k) {
        const int *c = T->coarse_coord + 3 * (size_t)k;
        int pos[3];
        for (int a = 0; a < 3; ++a) {
            if (c[a] >= NODE_PACK_OFFSET || c[a] < -NODE_PACK_OFFSET)
                st = mpm_error(MPM_EINTERNAL, "coarse node coordinate %d outside +-2^20", c[a]);
            pos[a] = c[a] * (1 << level);
        }
        owner[k] = st ? me : decomposition_node_owner(d, pos);
        if (owner[k] != me) send_counts[owner[k]]++, ++n_ask;
    }
    if (!st && !(send = malloc(sizeof(uint64_t) * (size_t)(n_ask > 0 ? n_ask : 1))))
        st = mpm_error(MPM_EINTERNAL, "out of memory: coarse level over ranks (%d ghosts)", n_ask);
    if (!st) {
        for (int r = 0; r < R; ++r) start[r + 1] = start[r] + send_counts[r];
        int *next = back_counts; /* scratch: the next free item per rank */
        for (int r = 0; r < R; ++r) next[r] = start[r];
        for (int k = 0; k < m; ++k) {
            slot[k] = -1;
            if (owner[k] == me) continue;
            slot[k] = next[owner[k]]++;
            send[slot[k]] = node_pack(T->coarse_coord + 3 * (size_t)k);
        }
    }
    if ((st = comm_agree(comm, st))) goto done;
    if (comm->exchange(comm->ctx, send_counts, send, recv_counts, &recv)) {
        st = comm_agree(comm, MPM_EINTERNAL);
        goto done;
    }
    /* the owned set: own coarse nodes, then those asked for, sorted and once each */
    int n_recv = 0, n_list = 0;
    for (int r = 0; r < R; ++r) n_recv += recv_counts[r];
    list = malloc(sizeof(KeyedNode) * (size_t)(m + n_recv > 0 ? m + n_recv : 1));
    reply = malloc(sizeof(uint64_t) * (size_t)(n_recv > 0 ? n_recv : 1));
    if (!list || !reply) st = mpm_error(MPM_EINTERNAL, "out of memory: coarse level over ranks (%d asked)", n_recv);
    for (int k = 0; k < m && !st; ++k)
        if (owner[k] == me) {
            list[n_list].packed = node_pack(T->coarse_coord + 3 * (size_t)k);
            list[n_list++].key = node_order_key(T->coarse_coord + 3 * (size_t)k);
        }
    for (int q = 0; q < n_recv && !st; ++q) {
        int c[3];
        node_unpack(recv[q], c);
        list[n_list].packed = recv[q];
        list[n_list++].key = node_order_key(c);
    }
    int n_owned = 0;
    if (!st) {
        qsort(list, (size_t)n_list, sizeof *list, by_key);
        for (int q = 0; q < n_list; ++q)
            if (q == 0 || list[q].key != list[q - 1].key) list[n_owned++] = list[q];
        st = grow(&out->owned_coord, &out->cap_owned, 3 * n_owned);
    }
    if ((st = comm_agree(comm, st))) goto done;
    /* numbers: this rank's owned nodes after every earlier rank's */
    counts[me] = n_owned;
    if (comm->sum(comm->ctx, counts, R)) {
        st = comm_agree(comm, MPM_EINTERNAL);
        goto done;
    }
    double first = 0, total = 0;
    for (int r = 0; r < R; ++r) first += r < me ? counts[r] : 0, total += counts[r];
    if (total > 0x7fffffff / 3) st = mpm_error(MPM_EINPUT, "coarse level %d: %.0f nodes overflow", level, total);
    out->n_owned = n_owned;
    out->first = (int)first;
    out->total = (int)total;
    for (int q = 0; q < n_owned && !st; ++q) node_unpack(list[q].packed, out->owned_coord + 3 * (size_t)q);
    for (int k = 0; k < m && !st; ++k)
        if (owner[k] == me) out->global[k] = out->first + find_key(list, n_owned, node_order_key(T->coarse_coord + 3 * (size_t)k));
    for (int q = 0; q < n_recv && !st; ++q) {
        int c[3];
        node_unpack(recv[q], c);
        reply[q] = (uint64_t)(out->first + find_key(list, n_owned, node_order_key(c)));
    }
    if ((st = comm_agree(comm, st))) goto done;
    /* the numbers back to the ranks that asked, in the order they asked */
    if (comm->exchange(comm->ctx, recv_counts, reply, back_counts, &back)) {
        st = comm_agree(comm, MPM_EINTERNAL);
        goto done;
    }
    for (int r = 0; r < R && !st; ++r)
        if (back_counts[r] != send_counts[r])
            st = mpm_error(MPM_EINTERNAL, "coarse level %d: rank %d answered %d of %d numbers", level, r,
                           back_counts[r], send_counts[r]);
    for (int k = 0; k < m && !st; ++k) {
        if (owner[k] != me) out->global[k] = (int)back[slot[k]];
        if (out->global[k] < 0 || out->global[k] >= out->total)
            st = mpm_error(MPM_EINTERNAL, "coarse level %d: node %d got number %d of %d", level, k, out->global[k],
                           out->total);
    }
    st = comm_agree(comm, st);
done:
    free(owner), free(slot), free(send_counts), free(recv_counts), free(back_counts), free(start), free(counts);
    free(send), free(recv), free(reply), free(back), free(list);
    return st;
}

void mg_coarse_ranks_free(MgCoarseRanks *c)
{
    free(c->owned_coord);
    free(c->global);
    memset(c, 0, sizeof *c);
}
