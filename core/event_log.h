/* The event log: where the program's phases are timed and counted, the idea
 * of PETSc's PetscLogEvent. This file is the one place the clock is read.
 *
 * An event is a named phase, registered once at run time (a part registers
 * its events when it is created; registering a name again gives the same
 * id), optionally with a parent event: a sub-phase, begun only while its
 * parent is open, so the parent's time covers its children's (multigrid's
 * smoothing inside the inverse approximation's apply; the assembly inside
 * the solve). The names are the program's: this file knows none of them.
 *
 * An EventLog accumulates, per event, the seconds and the number of calls
 * between event_log_begin and event_log_end. Events nest; an event begun
 * again while open (a wrapper re-entered through a nested object) counts
 * once, its outermost pair. begin and end are called from serial code only.
 * One log can record a whole time step: a caller hands its own log to the
 * solver (solvers/solver.h) and times its own phases through the same one.
 * To report one step or one solve, take a snapshot before and after and
 * the difference (event_totals_since).
 *
 * A begin or end that is refused (an id not registered, an end without its
 * begin) returns MPM_EINTERNAL and is also kept in the log, so that a
 * caller that cannot pass a status on (a wrapper returning an energy) still
 * has the failure reported by the next event_log_snapshot. */
#ifndef MPM_EVENT_LOG_H
#define MPM_EVENT_LOG_H

/* Events the registry holds; the names are at most EVENT_NAME_MAX chars. */
enum { EVENT_MAX = 64, EVENT_NAME_MAX = 31 };

typedef int EventId;
enum { EVENT_NONE = -1 }; /* no parent */

/* Registers `name` under `parent` (EVENT_NONE: a top-level phase) and sets
 * *id. A name already registered gives its id again when the parent is the
 * same one; a different parent, an unknown parent, an empty or too long
 * name and a full registry are refused (MPM_EINTERNAL). */
int event_register(const char *name, EventId parent, EventId *id);
/* Events registered so far: ids are 0 .. event_count() - 1, in
 * registration order (a parent before its children). */
int event_count(void);
/* The event's name; NULL for an id not registered. */
const char *event_name(EventId id);
/* The event's parent; EVENT_NONE for a top-level or unknown event. */
EventId event_parent(EventId id);

/* Seconds on OpenMP's wall clock: what every time in this file, and
 * every Deadline (core/deadline.h), is measured in. */
double event_clock(void);

typedef struct {
    double seconds;
    long calls;
} EventTotal;

/* A snapshot of a log, or the difference of two, indexed by EventId. */
typedef struct {
    EventTotal event[EVENT_MAX];
} EventTotals;

/* Zero-initialised (EventLog log = {0}, or event_log_reset) is an empty log. */
typedef struct {
    EventTotals totals;
    double began[EVENT_MAX]; /* event_clock() at the outermost begin of an open event */
    int depth[EVENT_MAX];    /* begins not yet ended */
    int status;              /* MPM_OK, or the first refused begin or end */
} EventLog;

void event_log_reset(EventLog *log);
/* Opens / closes event `id`. log NULL: nothing is timed (MPM_OK). */
int event_log_begin(EventLog *log, EventId id);
int event_log_end(EventLog *log, EventId id);
/* Ends `id` after work that returned `status`, so that the event is closed
 * on every path: returns status when it is a failure, else the end's. The
 * idiom: if (!(st = event_log_begin(log, id))) st = event_log_end_with(log, id, work()); */
int event_log_end_with(EventLog *log, EventId id, int status);
/* The event's accumulated seconds (completed intervals); 0 for a NULL log,
 * NAN for an id not registered. */
double event_log_seconds(const EventLog *log, EventId id);
/* Seconds since the open event `id` began (its outermost begin); 0 when it
 * is not open or log is NULL. */
double event_log_elapsed(const EventLog *log, EventId id);
/* out = the log's totals now. Returns the log's status: a begin or end
 * refused earlier is reported here (MPM_EINTERNAL). */
int event_log_snapshot(const EventLog *log, EventTotals *out);
/* out = now - then, event by event (out may alias either). */
void event_totals_since(const EventTotals *now, const EventTotals *then, EventTotals *out);

#endif
