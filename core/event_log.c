/* The event registry and the event log (event_log.h). */
#include "core/event_log.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

typedef struct {
    char name[EVENT_NAME_MAX + 1];
    EventId parent;
} EventInfo;

/* One registry for the process: an id means the same event in every log. */
static EventInfo g_events[EVENT_MAX];
static int g_n_events;

double event_clock(void) { return omp_get_wtime(); }

static int registered(EventId id) { return id >= 0 && id < g_n_events; }

static int add_event(const char *name, EventId parent, EventId *id)
{
    for (int k = 0; k < g_n_events; ++k) {
        if (strcmp(g_events[k].name, name) != 0) continue;
        if (g_events[k].parent != parent)
            return mpm_error(MPM_EINTERNAL, "event %s: registered under %s, now asked under %s", name,
                             g_events[k].parent == EVENT_NONE ? "no parent" : g_events[g_events[k].parent].name,
                             parent == EVENT_NONE ? "no parent" : g_events[parent].name);
        *id = k;
        return MPM_OK;
    }
    if (g_n_events == EVENT_MAX)
        return mpm_error(MPM_EINTERNAL, "event %s: the registry is full (%d events, EVENT_MAX)", name, EVENT_MAX);
    snprintf(g_events[g_n_events].name, sizeof g_events[0].name, "%s", name);
    g_events[g_n_events].parent = parent;
    *id = g_n_events++;
    return MPM_OK;
}

int event_register(const char *name, EventId parent, EventId *id)
{
    *id = EVENT_NONE;
    if (!name || !name[0] || strlen(name) > EVENT_NAME_MAX)
        return mpm_error(MPM_EINTERNAL, "event name '%s': expected 1 to %d characters", name ? name : "(null)",
                         EVENT_NAME_MAX);
    int st;
    /* parts are created from serial code, but two registrations must never interleave */
#pragma omp critical(mpm_event_registry)
    {
        if (parent != EVENT_NONE && !registered(parent))
            st = mpm_error(MPM_EINTERNAL, "event %s: parent id %d is not registered", name, parent);
        else st = add_event(name, parent, id);
    }
    return st;
}

int event_count(void) { return g_n_events; }

const char *event_name(EventId id) { return registered(id) ? g_events[id].name : NULL; }

EventId event_parent(EventId id) { return registered(id) ? g_events[id].parent : EVENT_NONE; }

void event_log_reset(EventLog *log) { memset(log, 0, sizeof *log); }

/* A refused begin or end: reported now and kept for event_log_snapshot. */
static int refuse(EventLog *log, const char *what, EventId id)
{
    int st = registered(id) ? mpm_error(MPM_EINTERNAL, "event log: %s of event %s, which is not open", what,
                                        g_events[id].name)
                            : mpm_error(MPM_EINTERNAL, "event log: %s of event id %d, which is not registered", what, id);
    if (!log->status) log->status = st;
    return st;
}

int event_log_begin(EventLog *log, EventId id)
{
    if (!log) return MPM_OK;
    if (!registered(id)) return refuse(log, "begin", id);
    if (log->depth[id]++ == 0) log->began[id] = event_clock();
    return MPM_OK;
}

int event_log_end(EventLog *log, EventId id)
{
    if (!log) return MPM_OK;
    if (!registered(id) || log->depth[id] == 0) return refuse(log, "end", id);
    if (--log->depth[id] > 0) return MPM_OK; /* a re-entered event counts once, its outermost pair */
    log->totals.event[id].seconds += event_clock() - log->began[id];
    log->totals.event[id].calls++;
    return MPM_OK;
}

int event_log_end_with(EventLog *log, EventId id, int status)
{
    int ended = event_log_end(log, id);
    return status ? status : ended;
}

double event_log_seconds(const EventLog *log, EventId id)
{
    if (!log) return 0.0;
    return registered(id) ? log->totals.event[id].seconds : NAN;
}

double event_log_elapsed(const EventLog *log, EventId id)
{
    if (!log || !registered(id) || log->depth[id] == 0) return 0.0;
    return event_clock() - log->began[id];
}

int event_log_snapshot(const EventLog *log, EventTotals *out)
{
    *out = log->totals;
    if (log->status) return mpm_error(log->status, "event log: a begin or end was refused earlier");
    return MPM_OK;
}

void event_totals_since(const EventTotals *now, const EventTotals *then, EventTotals *out)
{
    for (int k = 0; k < EVENT_MAX; ++k) {
        out->event[k].seconds = now->event[k].seconds - then->event[k].seconds;
        out->event[k].calls = now->event[k].calls - then->event[k].calls;
    }
}
