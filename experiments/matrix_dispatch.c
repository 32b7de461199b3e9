#include "experiments/matrix_dispatch.h"

#include <mpi.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "experiments/matrix_child.h"
#include "experiments/matrix_results.h"

enum { TAG_REQUEST = 1, TAG_TASK = 2, TAG_STOP = 3, TAG_RESULT = 4 };
enum { POLL_MS = 5, MAX_ARGS = 512 };

/* ---------------------------------------------------------------- local slots */

typedef struct {
    MatrixTask task;
    CellChild child;
    int busy;
} Slot;

/* DIR/cmd.txt: the command line, shell-quoted, to rerun the cell by hand. */
static void write_command(const MatrixTask *t, char *const *args)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/cmd.txt", t->dir);
    FILE *f = fopen(path, "w");
    if (!f) return;
    fputs("mpmbench", f);
    for (int i = 0; i < t->argc; ++i) {
        int plain = args[i][0] != '\0';
        for (const char *c = args[i]; *c && plain; ++c) plain = strchr("/._-=:+,", *c) || (*c >= '0' && *c <= '9') ||
                                                              (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z');
        if (plain) {
            fprintf(f, " %s", args[i]);
            continue;
        }
        fputs(" '", f);
        for (const char *c = args[i]; *c; ++c) {
            if (*c == '\'') fputs("'\\''", f);
            else fputc(*c, f);
        }
        fputc('\'', f);
    }
    fputc('\n', f);
    fclose(f);
}

static int slot_start(Slot *s, const MatrixTask *t)
{
    memcpy(&s->task, t, offsetof(MatrixTask, args) + (size_t)t->args_len);
    char *args[MAX_ARGS];
    if (t->argc > MAX_ARGS) return mpm_error(MPM_EINTERNAL, "cell %s: too many arguments", t->dir);
    size_t off = 0;
    for (int i = 0; i < t->argc; ++i) {
        args[i] = s->task.args + off;
        off += strlen(args[i]) + 1;
    }
    /* whatever is there is a cell that did not finish: redo it from scratch */
    int st = matrix_remove_tree(t->dir);
    if (!st) st = matrix_mkdir_p(t->dir);
    if (st) return st;
    write_command(&s->task, args);
    if ((st = cell_child_start(args, t->argc, t->dir, t->timeout_s, &s->child))) return st;
    s->busy = 1;
    return MPM_OK;
}

static int slot_poll(Slot *s, int rank, MatrixResult *r)
{
    CellOutcome o;
    if (!s->busy || !cell_child_poll(&s->child, &o)) return 0;
    memset(r, 0, sizeof *r);
    r->index = s->task.index;
    r->rank = rank;
    r->outcome = o;
    cell_measure(s->task.dir, s->task.first_timed_frame, &r->measure);
    s->busy = 0;
    return 1;
}

static int count_busy(const Slot *s, int n)
{
    int b = 0;
    for (int i = 0; i < n; ++i) b += s[i].busy;
    return b;
}

static Slot *free_slot(Slot *s, int n)
{
    for (int i = 0; i < n; ++i)
        if (!s[i].busy) return &s[i];
    return NULL;
}

/* ---------------------------------------------------------------- MPI outbox */

/* Non-blocking sends whose buffers live until MPI says they are done. */
typedef struct {
    MPI_Request req[64];
    void *buf[64];
    int n;
} Outbox;

static void outbox_progress(Outbox *o)
{
    for (int i = 0; i < o->n;) {
        int done = 0;
        MPI_Test(&o->req[i], &done, MPI_STATUS_IGNORE);
        if (!done) {
            ++i;
            continue;
        }
        free(o->buf[i]);
        o->req[i] = o->req[o->n - 1];
        o->buf[i] = o->buf[o->n - 1];
        o->n--;
    }
}

static int outbox_send(Outbox *o, const void *data, int bytes, int dest, int tag)
{
    while (o->n == 64) {
        outbox_progress(o);
        if (o->n == 64) matrix_sleep_ms(1);
    }
    void *b = malloc(bytes > 0 ? (size_t)bytes : 1);
    if (!b) return mpm_error(MPM_EINTERNAL, "out of memory (MPI message)");
    memcpy(b, data, (size_t)bytes);
    o->buf[o->n] = b;
    if (MPI_Isend(b, bytes, MPI_BYTE, dest, tag, MPI_COMM_WORLD, &o->req[o->n]) != MPI_SUCCESS) {
        free(b);
        return mpm_error(MPM_EINTERNAL, "MPI_Isend to rank %d failed", dest);
    }
    o->n++;
    return MPM_OK;
}

static void outbox_flush(Outbox *o)
{
    while (o->n) {
        outbox_progress(o);
        if (o->n) matrix_sleep_ms(1);
    }
}

static int task_bytes(const MatrixTask *t) { return (int)(offsetof(MatrixTask, args) + (size_t)t->args_len); }

/* ---------------------------------------------------------------- rank 0 */

static int serve(const MatrixTask *tasks, int n, int jobs, int use_mpi, const MatrixDispatchHooks *h)
{
    int ranks = 1;
    if (use_mpi) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    Slot *slots = calloc((size_t)jobs, sizeof *slots);
    if (!slots) return mpm_error(MPM_EINTERNAL, "out of memory");
    Outbox out = {.n = 0};
    int next = 0, results = 0, stopped = 0, remote_running = 0, st = MPM_OK;
    while (!st && (results < n || stopped < ranks - 1)) {
        int busy_round = 0;
        MatrixResult r;
        for (int i = 0; i < jobs && !st; ++i)
            if (slot_poll(&slots[i], 0, &r)) {
                results++;
                busy_round = 1;
                st = h->done(h->ctx, &r);
            }
        Slot *s;
        while (!st && next < n && (s = free_slot(slots, jobs))) {
            st = slot_start(s, &tasks[next++]);
            busy_round = 1;
        }
        while (!st && use_mpi) {
            int flag = 0;
            MPI_Status ms;
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
            if (!flag) break;
            busy_round = 1;
            if (ms.MPI_TAG == TAG_REQUEST) {
                MPI_Recv(NULL, 0, MPI_BYTE, ms.MPI_SOURCE, TAG_REQUEST, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (next < n) {
                    st = outbox_send(&out, &tasks[next], task_bytes(&tasks[next]), ms.MPI_SOURCE, TAG_TASK);
                    next++;
                    remote_running++;
                } else {
                    st = outbox_send(&out, NULL, 0, ms.MPI_SOURCE, TAG_STOP);
                    stopped++;
                }
            } else if (ms.MPI_TAG == TAG_RESULT) {
                MPI_Recv(&r, (int)sizeof r, MPI_BYTE, ms.MPI_SOURCE, TAG_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                results++;
                remote_running--;
                st = h->done(h->ctx, &r);
            } else {
                st = mpm_error(MPM_EINTERNAL, "unexpected MPI message (tag %d) from rank %d", ms.MPI_TAG, ms.MPI_SOURCE);
            }
        }
        if (use_mpi) outbox_progress(&out);
        if (h->tick) h->tick(h->ctx, count_busy(slots, jobs) + remote_running);
        if (!busy_round) matrix_sleep_ms(POLL_MS);
    }
    if (use_mpi && !st) outbox_flush(&out);
    free(slots);
    return st;
}

/* ---------------------------------------------------------------- ranks > 0 */

static int work(int jobs)
{
    int rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    Slot *slots = calloc((size_t)jobs, sizeof *slots);
    MatrixTask *task = malloc(sizeof *task);
    if (!slots || !task) {
        free(slots);
        free(task);
        return mpm_error(MPM_EINTERNAL, "out of memory");
    }
    Outbox out = {.n = 0};
    int asked = 0, stop = 0, st = MPM_OK;
    while (!st && (!stop || count_busy(slots, jobs))) {
        int busy_round = 0;
        MatrixResult r;
        for (int i = 0; i < jobs && !st; ++i)
            if (slot_poll(&slots[i], rank, &r)) {
                busy_round = 1;
                st = outbox_send(&out, &r, (int)sizeof r, 0, TAG_RESULT);
            }
        if (!st && !stop && !asked && free_slot(slots, jobs)) {
            st = outbox_send(&out, NULL, 0, 0, TAG_REQUEST);
            asked = 1;
        }
        if (!st && asked) {
            int flag = 0;
            MPI_Status ms;
            MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
            if (flag) {
                busy_round = 1;
                asked = 0;
                if (ms.MPI_TAG == TAG_TASK) {
                    MPI_Recv(task, (int)sizeof *task, MPI_BYTE, 0, TAG_TASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                    st = slot_start(free_slot(slots, jobs), task);
                } else {
                    MPI_Recv(NULL, 0, MPI_BYTE, 0, ms.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                    stop = 1;
                }
            }
        }
        outbox_progress(&out);
        if (!busy_round) matrix_sleep_ms(POLL_MS);
    }
    if (!st) outbox_flush(&out);
    free(slots);
    free(task);
    return st;
}

int matrix_dispatch(const MatrixTask *tasks, int n, int jobs, int use_mpi, const MatrixDispatchHooks *hooks)
{
    if (jobs < 1) jobs = 1;
    int rank = 0;
    if (use_mpi) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank == 0 ? serve(tasks, n, jobs, use_mpi, hooks) : work(jobs);
}
