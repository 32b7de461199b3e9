/* The table of a time step's phases (step_phases.h). */
#include "core/step_phases.h"

#include "core/error.h"

static const struct {
    const char *name;
    int parent; /* a StepPhase, or -1 */
} g_phases[STEP_PHASES] = {
    [STEP_P2G] = {"p2g", -1},
    [STEP_ASSEMBLE] = {"assemble", STEP_SOLVE},
    [STEP_SETUP] = {"setup", STEP_SOLVE},
    [STEP_SOLVE] = {"solve", -1},
    [STEP_LINESEARCH] = {"linesearch", STEP_SOLVE},
    [STEP_G2P] = {"g2p", -1},
};

const char *step_phase_name(StepPhase p) { return p >= 0 && p < STEP_PHASES ? g_phases[p].name : "?"; }

int step_phases_register(EventId ids[STEP_PHASES])
{
    /* top-level phases first: a parent is registered before its children */
    for (int pass = 0; pass < 2; ++pass)
        for (int p = 0; p < STEP_PHASES; ++p) {
            int parent = g_phases[p].parent;
            if ((parent < 0) != (pass == 0)) continue;
            int st = event_register(g_phases[p].name, parent < 0 ? EVENT_NONE : ids[parent], &ids[p]);
            if (st) return st;
        }
    return MPM_OK;
}

double step_phase_seconds(const EventTotals *t, const EventId ids[STEP_PHASES], StepPhase p)
{
    double s = t->event[ids[p]].seconds;
    for (int q = 0; q < STEP_PHASES; ++q)
        if (g_phases[q].parent == (int)p) s -= t->event[ids[q]].seconds;
    return s > 0.0 ? s : 0.0;
}
