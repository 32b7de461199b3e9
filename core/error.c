#include "core/error.h"

#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

enum { MESSAGE_CAP = 1024 };

typedef struct {
    char text[MESSAGE_CAP];
    int set;
} Message;

/* Each thread's own message; worker threads of a parallel region write the
 * shared one under a lock (see error.h). */
static _Thread_local Message t_own;
static Message g_team;

static int in_worker(void) { return omp_in_parallel() && omp_get_thread_num() != 0; }

/* A message is one line: control characters that came in with a quoted
 * input value (a JSON key with an escaped newline, a tab in a file name)
 * become '?'. */
static void one_line(char *text)
{
    for (unsigned char *c = (unsigned char *)text; *c; ++c)
        if (*c < 0x20 || *c == 0x7f) *c = '?';
}

static void record(Message *m, const char *fmt, va_list ap)
{
    if (m->set) return; /* the first message of a failure is the most precise one */
    vsnprintf(m->text, sizeof m->text, fmt, ap);
    one_line(m->text);
    m->set = 1;
}

int mpm_error(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (in_worker()) {
#pragma omp critical(mpm_error_team)
        record(&g_team, fmt, ap);
    } else {
        record(&t_own, fmt, ap);
    }
    va_end(ap);
    return status;
}

/* The worker slot's message moves into the caller's own slot, so context
 * added after a parallel region prefixes it. */
static void adopt_team_message(void)
{
    if (t_own.set) return;
#pragma omp critical(mpm_error_team)
    {
        if (g_team.set) {
            memcpy(t_own.text, g_team.text, sizeof t_own.text);
            t_own.set = 1;
            g_team.set = 0;
            g_team.text[0] = '\0';
        }
    }
}

/* m = "<ctx>: <m>" (or ctx alone when m is empty), truncated to the buffer. */
static void prefix(Message *m, const char *ctx)
{
    char out[MESSAGE_CAP];
    size_t n = 0, cap = sizeof out - 1;
    const char *parts[3] = {ctx, m->set ? ": " : "", m->set ? m->text : ""};
    for (int k = 0; k < 3; ++k)
        for (const char *c = parts[k]; *c && n < cap; ++c) out[n++] = *c;
    out[n] = '\0';
    memcpy(m->text, out, n + 1);
    m->set = 1;
}

int mpm_error_context(int status, const char *fmt, ...)
{
    if (status == MPM_OK) return status;
    char ctx[MESSAGE_CAP];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx, sizeof ctx, fmt, ap);
    va_end(ap);
    one_line(ctx);
    if (in_worker()) {
#pragma omp critical(mpm_error_team)
        prefix(&g_team, ctx);
        return status;
    }
    adopt_team_message();
    prefix(&t_own, ctx);
    return status;
}

const char *mpm_last_error(void)
{
    if (!in_worker()) adopt_team_message();
    return t_own.set ? t_own.text : "";
}

void mpm_clear_error(void)
{
    t_own.set = 0;
    t_own.text[0] = '\0';
    if (in_worker()) return;
#pragma omp critical(mpm_error_team)
    {
        g_team.set = 0;
        g_team.text[0] = '\0';
    }
}
