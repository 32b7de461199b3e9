/* floor: core */
/* The event log (core/event_log.h), deadlines (core/deadline.h) and the
 * table of step phases (core/step_phases.h): registration by name (the same
 * name gives the same id, bad names and parents are refused), call counts of
 * nested and re-entered events, a parent's time covering its children's,
 * snapshot differences, refused begins and ends kept by the log, and
 * deadlines in the past and far in the future. Every check is on a count or
 * on an ordering that holds however long the work took, never on a
 * duration, so machine load cannot fail it. */
#include <math.h>
#include <string.h>

#include "core/deadline.h"
#include "core/error.h"
#include "core/event_log.h"
#include "core/step_phases.h"
#include "tests/common/testutil.h"

/* Rounding slack of a sum of a few clock differences (the clock itself is
 * monotonic, so an interval inside another is never longer). */
static const double SUM_SLACK = 1e-12;

static volatile double g_sink;

/* Something for the clock to measure (how long it takes is not checked). */
static void work(int n)
{
    double x = 0.0;
    for (int k = 0; k < n; ++k) x += sqrt((double)k);
    g_sink = x;
}

static void registration(EventId *outer, EventId *inner)
{
    int n0 = event_count();
    CHECK(event_register("test_outer", EVENT_NONE, outer) == MPM_OK, "register: %s", mpm_last_error());
    CHECK(event_register("test_inner", *outer, inner) == MPM_OK, "register a child: %s", mpm_last_error());
    CHECK(event_count() == n0 + 2, "%d events after two registrations, expected %d", event_count(), n0 + 2);
    EventId again = EVENT_NONE;
    CHECK(event_register("test_inner", *outer, &again) == MPM_OK && again == *inner,
          "the same name again: id %d, expected %d", again, *inner);
    CHECK(event_count() == n0 + 2, "registering again added an event (%d)", event_count());
    CHECK(event_name(*inner) && strcmp(event_name(*inner), "test_inner") == 0, "name of the child");
    CHECK(event_parent(*inner) == *outer && event_parent(*outer) == EVENT_NONE, "parents %d %d",
          event_parent(*inner), event_parent(*outer));

    /* refused: the same name under another parent, an unknown parent, bad names */
    EventId id;
    mpm_clear_error();
    CHECK(event_register("test_inner", EVENT_NONE, &id) == MPM_EINTERNAL && id == EVENT_NONE,
          "same name, another parent: accepted");
    mpm_clear_error();
    CHECK(event_register("test_orphan", event_count() + 5, &id) == MPM_EINTERNAL, "unknown parent: accepted");
    mpm_clear_error();
    CHECK(event_register("", EVENT_NONE, &id) == MPM_EINTERNAL, "empty name: accepted");
    mpm_clear_error();
    char long_name[EVENT_NAME_MAX + 2];
    memset(long_name, 'x', sizeof long_name - 1);
    long_name[sizeof long_name - 1] = '\0';
    CHECK(event_register(long_name, EVENT_NONE, &id) == MPM_EINTERNAL, "a name of %d characters: accepted",
          EVENT_NAME_MAX + 1);
    mpm_clear_error();
    CHECK(event_count() == n0 + 2, "a refused registration added an event (%d)", event_count());
    CHECK(event_name(event_count()) == NULL && event_name(-3) == NULL, "name of an unknown id");
}

/* rounds x (begin outer; inner twice; end outer) */
static void rounds(EventLog *log, EventId outer, EventId inner, int x)
{
    for (int r = 0; r < x; ++r) {
        CHECK(event_log_begin(log, outer) == MPM_OK, "begin outer");
        work(1000);
        for (int k = 0; k < 2; ++k) {
            CHECK(event_log_begin(log, inner) == MPM_OK, "begin inner");
            work(2000);
            CHECK(event_log_end(log, inner) == MPM_OK, "end inner");
        }
        CHECK(event_log_end(log, outer) == MPM_OK, "end outer");
    }
}

static void counts_and_nesting(EventId outer, EventId inner)
{
    EventLog log = {0};
    rounds(&log, outer, inner, 3);
    EventTotals t;
    CHECK(event_log_snapshot(&log, &t) == MPM_OK, "snapshot: %s", mpm_last_error());
    CHECK(t.event[outer].calls == 3 && t.event[inner].calls == 6, "calls: outer %ld (3), inner %ld (6)",
          t.event[outer].calls, t.event[inner].calls);
    CHECK(t.event[inner].seconds >= 0.0 && t.event[outer].seconds >= t.event[inner].seconds - SUM_SLACK,
          "the parent's %.9g s does not cover its children's %.9g s", t.event[outer].seconds, t.event[inner].seconds);
    CHECK(event_log_seconds(&log, outer) == t.event[outer].seconds, "event_log_seconds differs from the snapshot");

    /* a re-entered event counts once, its outermost pair */
    long before = log.totals.event[outer].calls;
    CHECK(event_log_begin(&log, outer) == MPM_OK && event_log_begin(&log, outer) == MPM_OK, "begin twice");
    CHECK(event_log_end(&log, outer) == MPM_OK, "inner end");
    CHECK(log.totals.event[outer].calls == before, "the inner end of a re-entered event counted");
    CHECK(event_log_end(&log, outer) == MPM_OK, "outer end");
    CHECK(log.totals.event[outer].calls == before + 1, "re-entered: %ld calls, expected %ld",
          log.totals.event[outer].calls, before + 1);

    /* elapsed: of an open event only; an enclosing event's is the longer */
    CHECK(event_log_elapsed(&log, outer) == 0.0, "elapsed of a closed event");
    event_log_begin(&log, outer);
    work(1000);
    event_log_begin(&log, inner);
    work(1000);
    double e_inner = event_log_elapsed(&log, inner), e_outer = event_log_elapsed(&log, outer);
    CHECK(e_inner >= 0.0 && e_outer >= e_inner, "elapsed: outer %.9g < inner %.9g", e_outer, e_inner);
    event_log_end(&log, inner);
    event_log_end(&log, outer);

    /* end_with closes the event and passes the work's failure on */
    before = log.totals.event[inner].calls;
    event_log_begin(&log, inner);
    CHECK(event_log_end_with(&log, inner, MPM_ENUMERIC) == MPM_ENUMERIC, "end_with lost the work's status");
    CHECK(log.totals.event[inner].calls == before + 1 && log.depth[inner] == 0, "end_with did not close the event");
    CHECK(event_log_snapshot(&log, &t) == MPM_OK, "the log failed: %s", mpm_last_error());
}

static void snapshot_difference(EventId outer, EventId inner, EventId untouched)
{
    EventLog log;
    event_log_reset(&log);
    rounds(&log, outer, inner, 2);
    EventTotals then, now, diff;
    CHECK(event_log_snapshot(&log, &then) == MPM_OK, "snapshot");
    rounds(&log, outer, inner, 3);
    CHECK(event_log_snapshot(&log, &now) == MPM_OK, "snapshot");
    event_totals_since(&now, &then, &diff);
    CHECK(diff.event[outer].calls == 3 && diff.event[inner].calls == 6, "difference: outer %ld (3), inner %ld (6) calls",
          diff.event[outer].calls, diff.event[inner].calls);
    CHECK(diff.event[inner].seconds >= 0.0 && diff.event[outer].seconds >= diff.event[inner].seconds - SUM_SLACK,
          "difference: the parent's %.9g s below its children's %.9g s", diff.event[outer].seconds,
          diff.event[inner].seconds);
    CHECK(diff.event[untouched].calls == 0 && diff.event[untouched].seconds == 0.0, "an untouched event changed");
    CHECK(now.event[outer].seconds >= diff.event[outer].seconds, "a part longer than the whole");
    event_totals_since(&now, &then, &now); /* aliasing */
    CHECK(now.event[outer].calls == 3, "difference into its own input: %ld calls", now.event[outer].calls);
}

static void refusals(EventId outer)
{
    EventLog log = {0};
    const EventId unknown = event_count() + 7;
    mpm_clear_error();
    CHECK(event_log_begin(&log, unknown) == MPM_EINTERNAL, "begin of an unknown id accepted");
    CHECK(event_log_begin(&log, -1) == MPM_EINTERNAL, "begin of id -1 accepted");
    CHECK(event_log_end(&log, outer) == MPM_EINTERNAL, "end without begin accepted");
    CHECK(log.totals.event[outer].calls == 0, "a refused end counted");
    CHECK(isnan(event_log_seconds(&log, unknown)), "seconds of an unknown id: %g", event_log_seconds(&log, unknown));
    EventTotals t;
    mpm_clear_error();
    CHECK(event_log_snapshot(&log, &t) == MPM_EINTERNAL, "a refused begin is not kept by the log");
    mpm_clear_error();
    event_log_reset(&log);
    CHECK(event_log_snapshot(&log, &t) == MPM_OK, "a reset log still fails");

    /* no log: nothing timed, nothing refused */
    CHECK(event_log_begin(NULL, outer) == MPM_OK && event_log_end(NULL, outer) == MPM_OK, "NULL log refused");
    CHECK(event_log_seconds(NULL, outer) == 0.0 && event_log_elapsed(NULL, outer) == 0.0, "NULL log has time");
}

static void deadlines(void)
{
    Deadline none = {0};
    Deadline past = deadline_in(-1.0, "a past deadline");
    Deadline far = deadline_in(1e6, NULL);
    CHECK(!deadline_passed(&none), "no deadline passed");
    CHECK(deadline_passed(&past), "a deadline a second ago has not passed");
    CHECK(!deadline_passed(&far), "a deadline in 1e6 s has passed");
    CHECK(strcmp(deadline_reason(&past), "a past deadline") == 0 && strcmp(deadline_reason(&far), "") == 0,
          "reasons '%s' '%s'", deadline_reason(&past), deadline_reason(&far));
    CHECK(past.at < far.at && event_clock() >= past.at, "deadline times out of order");
}

static void step_phases(void)
{
    EventId ids[STEP_PHASES], again[STEP_PHASES];
    CHECK(step_phases_register(ids) == MPM_OK && step_phases_register(again) == MPM_OK, "register the phases");
    CHECK(memcmp(ids, again, sizeof ids) == 0, "registering the phases again changed their ids");
    for (int p = 0; p < STEP_PHASES; ++p) {
        CHECK(strcmp(event_name(ids[p]), step_phase_name((StepPhase)p)) == 0, "phase %d: event %s, name %s", p,
              event_name(ids[p]), step_phase_name((StepPhase)p));
        for (int q = 0; q < p; ++q) CHECK(ids[p] != ids[q], "phases %d and %d share an event", p, q);
    }
    CHECK(event_parent(ids[STEP_ASSEMBLE]) == ids[STEP_SOLVE] && event_parent(ids[STEP_P2G]) == EVENT_NONE,
          "phase parents");
    /* columns from given totals: the solve's is its remainder, never below 0 */
    EventTotals t;
    memset(&t, 0, sizeof t);
    t.event[ids[STEP_SOLVE]].seconds = 10.0;
    t.event[ids[STEP_ASSEMBLE]].seconds = 1.0;
    t.event[ids[STEP_SETUP]].seconds = 2.0;
    t.event[ids[STEP_LINESEARCH]].seconds = 3.0;
    t.event[ids[STEP_P2G]].seconds = 5.0;
    CHECK(step_phase_seconds(&t, ids, STEP_SOLVE) == 4.0, "solve column %g, expected 4",
          step_phase_seconds(&t, ids, STEP_SOLVE));
    CHECK(step_phase_seconds(&t, ids, STEP_SETUP) == 2.0 && step_phase_seconds(&t, ids, STEP_P2G) == 5.0,
          "a phase without sub-phases is its event's time");
    t.event[ids[STEP_SOLVE]].seconds = 5.0;
    CHECK(step_phase_seconds(&t, ids, STEP_SOLVE) == 0.0, "solve column below 0");
}

int main(void)
{
    EventId outer, inner, untouched;
    registration(&outer, &inner);
    CHECK(event_register("test_untouched", EVENT_NONE, &untouched) == MPM_OK, "register");
    counts_and_nesting(outer, inner);
    snapshot_difference(outer, inner, untouched);
    refusals(outer);
    deadlines();
    step_phases();
    return test_summary("test_event_log");
}
