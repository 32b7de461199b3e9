#include "experiments/driver/progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/event_log.h"

void progress_init(Progress *p, int total_frames)
{
    const char *ci = getenv("CI");
    p->enabled = isatty(STDERR_FILENO) && !(ci && *ci);
    p->total_frames = total_frames;
    p->t_start = event_clock();
    p->last_print = 0.0;
}

void progress_update(Progress *p, double fraction_done, int frame, int step, int iter, double residual, double step_s)
{
    if (!p->enabled) return;
    double now = event_clock();
    if (now - p->last_print < 0.2) return; /* at most 5 redraws a second */
    p->last_print = now;
    double elapsed = now - p->t_start;
    char eta[32] = "--";
    if (fraction_done > 1e-6) {
        double left = elapsed * (1.0 - fraction_done) / fraction_done;
        snprintf(eta, sizeof eta, "%dm%02ds", (int)(left / 60), (int)left % 60);
    }
    fprintf(stderr, "\r\033[Kframe %d/%d  step %d  iter %d  residual %.2e  step %.1fs  elapsed %.0fs  ETA %s",
            frame + 1, p->total_frames, step, iter, residual, step_s, elapsed, eta);
    fflush(stderr);
}

void progress_clear(Progress *p)
{
    if (!p->enabled) return;
    fprintf(stderr, "\r\033[K");
    fflush(stderr);
}
