/* The phases of a time step as events of the event log (core/event_log.h):
 * the one table of them, in the order of steps.csv's columns <name>_s.
 *
 *   p2g         the first half of the step (core/step.c: P2G, the grid)
 *   solve       the solver's whole solve, with three sub-phases:
 *     assemble    tangent stiffness, Hessian assembly or matrix-free diagonal
 *     setup       the inverse approximation's setup
 *     linesearch  every energy and gradient evaluation
 *   g2p         the second half (G2P, the particle update)
 *
 * A phase's column is its time less that of its sub-phases in this table,
 * so the columns add up to the step: the solve's is the remainder, the
 * direction (Krylov solves, the two-loop recursion) and the stopping tests.
 * It lives in core/ because it names phases, no implementation: the solver
 * layer times the solve's phases and the driver P2G and G2P, each through
 * this table. */
#ifndef MPM_STEP_PHASES_H
#define MPM_STEP_PHASES_H

#include "core/event_log.h"

typedef enum { STEP_P2G, STEP_ASSEMBLE, STEP_SETUP, STEP_SOLVE, STEP_LINESEARCH, STEP_G2P, STEP_PHASES } StepPhase;

/* "p2g", "assemble", ... */
const char *step_phase_name(StepPhase p);
/* Registers the phases (idempotent) and sets ids[p] to phase p's event. */
int step_phases_register(EventId ids[STEP_PHASES]);
/* Phase p's column in t (a snapshot or a difference of two): its event's
 * seconds less its sub-phases', never below 0. */
double step_phase_seconds(const EventTotals *t, const EventId ids[STEP_PHASES], StepPhase p);

#endif
