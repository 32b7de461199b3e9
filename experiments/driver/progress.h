/* One-line progress on a terminal (frame, step, the running step's outer
 * iteration, CN residual and time, elapsed, ETA);
 * silent when stderr is not a TTY or CI is set, so pipes and CI stay clean. */
#ifndef MPM_PROGRESS_H
#define MPM_PROGRESS_H

typedef struct {
    int enabled;
    int total_frames;
    double t_start, last_print;
} Progress;

void progress_init(Progress *p, int total_frames);
/* fraction_done in [0,1] of the simulated time of the run; step_s: time in
 * the running step's solve. */
void progress_update(Progress *p, double fraction_done, int frame, int step, int iter, double residual, double step_s);
void progress_clear(Progress *p);

#endif
