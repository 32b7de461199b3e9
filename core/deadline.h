/* A deadline: the time after which no new iteration starts, with the human
 * reason for it. The caller (the frame driver: --max-step-seconds,
 * --max-run-seconds) sets it; a solver is handed it through its solve
 * context (SolveSettings, PcgOptions, MinresOptions, InvSetupInput) and
 * asks deadline_passed() at the top of an iteration, so no solver reads a
 * clock. Zero-initialised is no deadline. */
#ifndef MPM_DEADLINE_H
#define MPM_DEADLINE_H

typedef struct {
    int active;         /* 0: no deadline */
    double at;          /* event_clock() seconds (core/event_log.h) */
    const char *reason; /* e.g. "--max-step-seconds 5", for the status reason; may be NULL */
} Deadline;

/* A deadline `seconds` from now (negative: already passed). */
Deadline deadline_in(double seconds, const char *reason);
/* 1 when d is active and the clock has reached it, else 0. */
int deadline_passed(const Deadline *d);
/* d's reason, "" when it has none. */
const char *deadline_reason(const Deadline *d);

#endif
