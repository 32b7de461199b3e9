#include "experiments/driver/library_startup.h"


#include "core/event_log.h"
#include "core/error.h"

static double g_startup_s = 0.0;

int library_startup(const Solver *solver)
{
    double t0 = event_clock();
    int st = MPM_OK;
    /* the first parallel region creates the thread team */
#pragma omp parallel
    {
    }
    const InvApproxOps *inv = solver && solver->inv ? solver->inv->ops : NULL;
    if (inv && inv->library_startup) st = inv->library_startup();
    g_startup_s += event_clock() - t0;
    return st;
}

double library_startup_seconds(void) { return g_startup_s; }
