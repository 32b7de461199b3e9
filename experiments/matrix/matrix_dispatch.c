#include "experiments/matrix/matrix_dispatch.h"

#include <mpi.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "experiments/io/machine_load.h"
#include "core/event_log.h"
#include "experiments/matrix/matrix_child.h"
#include "experiments/matrix/matrix_resume.h"
#include "experiments/matrix/matrix_results.h"
#include "experiments/io/paths.h"

/* The protocol. A worker asks (REQUEST) when it has a free slot and gets a
 * TASK, or STOP once nothing is left: it then finishes its cells, sending
 * each RESULT, says BYE and waits for rank 0's FIN. A worker that fails
 * sends FAILED with its message instead of going on. Rank 0 on any error
 * (its own or a FAILED) sends ABORT to every rank it has no BYE from: they
 * kill their cells, say BYE and wait for FIN. Rank 0 answers every BYE with
 * a FIN once it has them all, so every message sent is received, and every
 * rank leaves the dispatch on every path: one rank's error ends the study
 * everywhere, without MPI_Abort. */
enum { TAG_REQUEST = 1, TAG_TASK = 2, TAG_STOP = 3, TAG_RESULT = 4, TAG_FAILED = 5, TAG_ABORT = 6, TAG_BYE = 7,
       TAG_FIN = 8 };
enum { FAILED_TEXT = 512 };
enum { POLL_MS = 5, MAX_ARGS = 512 };

/* ---------------------------------------------------------------- local slots */

typedef struct {
    MatrixTask task;
    CellChild child;
    int busy;
    int attempts;       /* a resumed cell's earlier attempts (matrix_resume.h) */
    double recorded;    /* event_clock() of its last progress record */
} Slot;

/* DIR/cmd.txt: the command line, shell-quoted, to rerun the cell by hand. */
static void write_command(const MatrixTask *t, char *const *args, int argc)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/cmd.txt", t->dir);
    FILE *f = fopen(path, "w");
    if (!f) return;
    if (t->ranks > 1) fprintf(f, "mpirun -np %d ", t->ranks);
    fputs("mpmbench", f);
    for (int i = 0; i < argc; ++i) {
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
    char *args[MAX_ARGS + 2], from[1200];
    if (t->argc > MAX_ARGS) return mpm_error(MPM_EINTERNAL, "cell %s: too many arguments", t->dir);
    size_t off = 0;
    int argc = t->argc;
    for (int i = 0; i < argc; ++i) {
        args[i] = s->task.args + off;
        off += strlen(args[i]) + 1;
    }
    /* whatever is there is a cell that did not finish: redo it from scratch,
     * unless it is a checkpoint reference that can go on from a checkpoint */
    s->attempts = 0;
    int st = t->resumable ? matrix_resume_prepare(t->dir, from, sizeof from, &s->attempts) : MPM_OK;
    if (!st && !s->attempts) {
        st = matrix_remove_tree(t->dir);
        if (!st) st = paths_mkdir_p(t->dir);
    }
    if (st) return st;
    if (s->attempts) {
        args[argc++] = "--from";
        args[argc++] = from;
        printf("[resuming] %s from %s (attempt %d)\n", t->dir, from, s->attempts + 1);
        fflush(stdout);
    }
    write_command(&s->task, args, argc);
    if ((st = cell_child_start(args, argc, t->dir, t->timeout_s, t->ranks, &s->child))) return st;
    s->busy = 1;
    s->recorded = -1e30;
    return MPM_OK;
}

static int slot_poll(Slot *s, int rank, MatrixResult *r)
{
    CellOutcome o;
    if (!s->busy) return 0;
    if (s->task.resumable && event_clock() - s->recorded >= MATRIX_PROGRESS_EVERY_S) {
        matrix_resume_record(s->task.dir, &s->child); /* what a stop would otherwise lose of its cost */
        s->recorded = event_clock();
    }
    if (!cell_child_poll(&s->child, &o)) return 0;
    memset(r, 0, sizeof *r);
    r->index = s->task.index;
    r->rank = rank;
    r->outcome = o;
    /* a resumed cell: its rows and its cost from every attempt */
    if (s->task.resumable && matrix_resume_finish(s->task.dir, s->attempts, &r->outcome)) {
        fprintf(stderr, "mpmbench: %s\n", mpm_last_error());
        r->outcome.status = CELL_FAILED;
    }
    cell_measure(s->task.dir, s->task.first_timed_frame, &r->measure);
    if (r->outcome.status == CELL_OK && r->measure.cut_short) r->outcome.status = CELL_TIME_LIMIT;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    /* a cell over ranks on this machine uses every rank's threads */
    const int threads = r->measure.threads_run * (s->task.ranks > 1 ? s->task.ranks : 1);
    r->outcome.busy = machine_was_busy(r->outcome.others_cpu_s, r->outcome.elapsed_s, threads, (int)cores);
    s->busy = 0;
    return 1;
}

static int count_busy(const Slot *s, int n)
{
    int b = 0;
    for (int i = 0; i < n; ++i) b += s[i].busy;
    return b;
}

static void kill_all(Slot *s, int n)
{
    for (int i = 0; i < n; ++i)
        if (s[i].busy) {
            cell_child_kill(&s[i].child);
            s[i].busy = 0;
        }
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
    if (bytes > 0) memcpy(b, data, (size_t)bytes); /* a zero-length message may come with data == NULL */
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

enum { TASK_PENDING = 0, TASK_RUNNING, TASK_OK, TASK_NOT_OK, TASK_SKIPPED };

/* Rank 0's view of the task list: which are pending, running, done. */
typedef struct {
    const MatrixTask *tasks;
    int n;
    unsigned char *state;
    int finished;   /* done or skipped */
    int pending;    /* not handed out, not skipped */
    const MatrixDispatchHooks *h;
} Board;

/* The first pending task whose dependency ended ok (-1: none ready); tasks
 * whose dependency did not are skipped on the way. */
static int board_pick(Board *b)
{
    for (int i = 0; i < b->n; ++i) {
        if (b->state[i] != TASK_PENDING) continue;
        int a = b->tasks[i].after;
        int dep = a >= 0 && a < b->n ? b->state[a] : TASK_OK;
        if (dep == TASK_OK) return i;
        if (dep == TASK_NOT_OK || dep == TASK_SKIPPED) {
            b->state[i] = TASK_SKIPPED;
            b->finished++;
            b->pending--;
            if (b->h->skipped) b->h->skipped(b->h->ctx, &b->tasks[i], a >= 0 ? &b->tasks[a] : NULL);
            i = -1; /* a skip may unblock nothing but skip more: scan again */
        }
    }
    return -1;
}

static void board_hand_out(Board *b, int i)
{
    b->state[i] = TASK_RUNNING;
    b->pending--;
}

/* A result of the task with caller's index `index`. */
static void board_done(Board *b, const MatrixResult *r)
{
    for (int i = 0; i < b->n; ++i)
        if (b->tasks[i].index == r->index && b->state[i] == TASK_RUNNING) {
            b->state[i] = r->outcome.status == CELL_OK ? TASK_OK : TASK_NOT_OK;
            b->finished++;
            return;
        }
}

/* A failure to inject on one rank, for the test of the error paths
 * (tests/matrix/test_matrix_mpi.sh): MPM_TEST_FAIL_RANK=R makes rank R fail
 * when it is handed its first cell. */
static int injected_failure(int rank)
{
    const char *v = getenv("MPM_TEST_FAIL_RANK");
    if (!v || !*v || atoi(v) != rank) return MPM_OK;
    return mpm_error(MPM_EINTERNAL, "injected failure (MPM_TEST_FAIL_RANK=%d)", rank);
}

static int serve(const MatrixTask *tasks, int n, int jobs, int use_mpi, const MatrixDispatchHooks *h)
{
    int ranks = 1;
    if (use_mpi) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    Slot *slots = calloc((size_t)jobs, sizeof *slots);
    Board b = {tasks, n, calloc((size_t)n + 1, 1), 0, n, h};
    int *waiting = calloc((size_t)ranks, sizeof *waiting);      /* ranks asking while no task was ready */
    unsigned char *said_bye = calloc((size_t)ranks, 1), *aborted = calloc((size_t)ranks, 1);
    char *failed = malloc(FAILED_TEXT);
    if (!slots || !b.state || !waiting || !said_bye || !aborted || !failed) {
        free(slots);
        free(b.state);
        free(waiting);
        free(said_bye);
        free(aborted);
        free(failed);
        return mpm_error(MPM_EINTERNAL, "out of memory");
    }
    Outbox out = {.n = 0};
    int n_waiting = 0, byes = 0, remote_running = 0, st = injected_failure(0);
    if (st) st = mpm_error_context(st, "rank 0");
    /* until every task is finished (or the study failed) and every worker has said bye */
    while ((!st && b.finished < n) || byes < ranks - 1) {
        int busy_round = 0;
        MatrixResult r;
        if (st) {
            /* the study failed: no new cell, none left running, every worker told */
            kill_all(slots, jobs);
            for (int k = 1; k < ranks; ++k)
                if (!said_bye[k] && !aborted[k] && !outbox_send(&out, NULL, 0, k, TAG_ABORT)) aborted[k] = 1;
            n_waiting = 0;
        }
        for (int i = 0; i < jobs && !st; ++i)
            if (slot_poll(&slots[i], 0, &r)) {
                board_done(&b, &r);
                busy_round = 1;
                st = h->done(h->ctx, &r);
            }
        Slot *s;
        int next;
        while (!st && (s = free_slot(slots, jobs)) && (next = board_pick(&b)) >= 0) {
            board_hand_out(&b, next);
            st = slot_start(s, &tasks[next]);
            busy_round = 1;
        }
        while (use_mpi) {
            int flag = 0;
            MPI_Status ms;
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
            if (!flag) break;
            busy_round = 1;
            int from = ms.MPI_SOURCE;
            if (ms.MPI_TAG == TAG_REQUEST) {
                MPI_Recv(NULL, 0, MPI_BYTE, from, TAG_REQUEST, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (!st) waiting[n_waiting++] = from; /* answered below */
            } else if (ms.MPI_TAG == TAG_RESULT) {
                MPI_Recv(&r, (int)sizeof r, MPI_BYTE, from, TAG_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                remote_running--;
                board_done(&b, &r);
                if (!st) st = h->done(h->ctx, &r); /* after a failure too the cell is recorded, if it can be */
                else h->done(h->ctx, &r);
            } else if (ms.MPI_TAG == TAG_FAILED) {
                MPI_Recv(failed, FAILED_TEXT, MPI_CHAR, from, TAG_FAILED, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                failed[FAILED_TEXT - 1] = '\0';
                if (!st) st = mpm_error(MPM_EINTERNAL, "%s", failed);
            } else if (ms.MPI_TAG == TAG_BYE) {
                MPI_Recv(NULL, 0, MPI_BYTE, from, TAG_BYE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                said_bye[from] = 1;
                byes++;
            } else {
                int bytes = 0;
                MPI_Get_count(&ms, MPI_BYTE, &bytes);
                MPI_Recv(failed, bytes < FAILED_TEXT ? bytes : FAILED_TEXT, MPI_BYTE, from, ms.MPI_TAG,
                         MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (!st) st = mpm_error(MPM_EINTERNAL, "unexpected MPI message (tag %d) from rank %d", ms.MPI_TAG, from);
            }
        }
        /* the waiting ranks: a ready task each, or stop once nothing is left to hand out */
        while (!st && n_waiting > 0) {
            next = board_pick(&b);
            int dest = waiting[0];
            if (next >= 0) {
                board_hand_out(&b, next);
                st = outbox_send(&out, &tasks[next], task_bytes(&tasks[next]), dest, TAG_TASK);
                remote_running++;
            } else if (b.pending == 0) {
                st = outbox_send(&out, NULL, 0, dest, TAG_STOP);
            } else {
                break; /* every remaining task waits for a running one */
            }
            memmove(waiting, waiting + 1, sizeof *waiting * (size_t)--n_waiting);
            busy_round = 1;
        }
        if (use_mpi) outbox_progress(&out);
        if (h->tick) h->tick(h->ctx, count_busy(slots, jobs) + remote_running);
        if (!busy_round) matrix_sleep_ms(POLL_MS);
    }
    kill_all(slots, jobs);
    for (int k = 1; k < ranks; ++k) outbox_send(&out, NULL, 0, k, TAG_FIN);
    if (use_mpi) outbox_flush(&out);
    free(slots);
    free(b.state);
    free(waiting);
    free(said_bye);
    free(aborted);
    free(failed);
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
    int asked = 0, stop = 0, aborted = 0, st = MPM_OK, first = 1;
    while (!st && !aborted && (!stop || count_busy(slots, jobs))) {
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
        int flag = 0;
        MPI_Status ms;
        if (!st) MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        if (flag) {
            busy_round = 1;
            if (ms.MPI_TAG == TAG_TASK) {
                asked = 0;
                MPI_Recv(task, (int)sizeof *task, MPI_BYTE, 0, TAG_TASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (first) st = injected_failure(rank);
                first = 0;
                if (!st) st = slot_start(free_slot(slots, jobs), task);
            } else {
                MPI_Recv(NULL, 0, MPI_BYTE, 0, ms.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (ms.MPI_TAG == TAG_ABORT) aborted = 1;
                else stop = 1; /* TAG_STOP */
                asked = 0;
            }
        }
        outbox_progress(&out);
        if (!busy_round) matrix_sleep_ms(POLL_MS);
    }
    if (st) { /* rank 0 reports it and ends the study everywhere */
        char text[FAILED_TEXT];
        snprintf(text, sizeof text, "rank %d: %s", rank, mpm_last_error());
        outbox_send(&out, text, (int)strlen(text) + 1, 0, TAG_FAILED);
        mpm_clear_error();
    }
    kill_all(slots, jobs);
    outbox_send(&out, NULL, 0, 0, TAG_BYE);
    /* until rank 0's FIN: whatever else it sent meanwhile (a task, an abort) is received and dropped */
    for (int fin = 0; !fin;) {
        int flag = 0;
        MPI_Status ms;
        MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        if (!flag) {
            outbox_progress(&out);
            matrix_sleep_ms(POLL_MS);
            continue;
        }
        MPI_Recv(task, (int)sizeof *task, MPI_BYTE, 0, ms.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        fin = ms.MPI_TAG == TAG_FIN;
    }
    outbox_flush(&out);
    free(slots);
    free(task);
    return MPM_OK;
}

int matrix_dispatch(const MatrixTask *tasks, int n, int jobs, int use_mpi, const MatrixDispatchHooks *hooks)
{
    if (jobs < 1) jobs = 1;
    int rank = 0;
    if (use_mpi) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank == 0 ? serve(tasks, n, jobs, use_mpi, hooks) : work(jobs);
}
