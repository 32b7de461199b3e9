/* Deadlines (deadline.h), on the event log's clock. */
#include "core/deadline.h"

#include "core/event_log.h"

Deadline deadline_in(double seconds, const char *reason)
{
    return (Deadline){.active = 1, .at = event_clock() + seconds, .reason = reason};
}

int deadline_passed(const Deadline *d) { return d->active && event_clock() >= d->at; }

const char *deadline_reason(const Deadline *d) { return d->reason ? d->reason : ""; }
