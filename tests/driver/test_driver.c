/* floor: driver */
/* The driver floor (experiments/driver/) used as a library, the way a program
 * embedding mpmbench uses it, with no file output:
 *  - session_open makes the solver from a spec, loads the scene with its
 *    overrides and initialises the simulation; bad input is MPM_EINPUT with
 *    one line and leaves nothing to free;
 *  - frame_driver_run advances N frames and calls back after every step and
 *    frame; it changes nothing in the numbers: the same steps driven one by
 *    one with time_step_run give bitwise the same residuals and iterations;
 *  - the run's time budget: spent inside a frame, that frame is handed over
 *    cut short (timeout, the reason); spent exactly at a frame's end, the next
 *    frame is handed over with no steps, status timeout and the reason, so
 *    the files of a run say why it ended (issue 28, "Also found"). The budget
 *    is 1 ns, so that any step exhausts it, whatever the machine's load. */
#include <math.h>
#include <string.h>

#include "core/error.h"
#include "experiments/driver/frame_driver.h"
#include "experiments/driver/session.h"
#include "tests/common/testutil.h"

#define MAX_STEPS 64
#define MAX_FRAMES 8

typedef struct {
    int steps;
    double residual[MAX_STEPS];
    int outer[MAX_STEPS];
    int frames;
    FrameSums frame[MAX_FRAMES];
    int stopping[MAX_FRAMES];
} Record;

static int record_step(void *ctx, const Simulation *sim, int frame, int step, const SolveStats *ss, const StepInfo *si)
{
    (void)sim, (void)frame, (void)step, (void)si;
    Record *r = ctx;
    if (r->steps < MAX_STEPS) {
        r->residual[r->steps] = ss->residual;
        r->outer[r->steps] = ss->outer_iters;
    }
    r->steps++;
    return MPM_OK;
}

static int record_frame(void *ctx, const Simulation *sim, const FrameSums *f, int stopping)
{
    (void)sim;
    Record *r = ctx;
    if (r->frames < MAX_FRAMES) {
        r->frame[r->frames] = *f;
        r->stopping[r->frames] = stopping;
    }
    r->frames++;
    return MPM_OK;
}

static int open_session(const char *scene, double scale, const char *solver, Session *s)
{
    SessionConfig c = {.scene = scene, .scale = scale, .solver = solver};
    int st = session_open(&c, s);
    CHECK(st == MPM_OK, "session %s/%s: %s", scene, solver, mpm_last_error());
    return st;
}

/* Frames through the driver, then the same steps one by one. */
static void embedding(void)
{
    Session a, b;
    if (open_session("bar3", 4.0, "pn-pcg", &a)) return;
    if (open_session("bar3", 4.0, "pn-pcg", &b)) {
        session_close(&a);
        return;
    }
    Record r;
    memset(&r, 0, sizeof r);
    SolveSettings set;
    solve_settings_default(&set);
    FrameDriver d = {.frames = 2, .after_step = record_step, .after_frame = record_frame, .ctx = &r};
    DriveTotals tot;
    char why[300];
    int st = frame_driver_run(&d, &a.sim, a.solver, &set, &tot, why, sizeof why);
    CHECK(st == MPM_OK, "drive: %s", mpm_last_error());
    CHECK(a.sim.frame == 2 && tot.frames == 2 && r.frames == 2 && !tot.stopped, "2 frames: sim %d, totals %d, calls %d",
          a.sim.frame, tot.frames, r.frames);
    CHECK(r.steps >= 2 && r.steps <= MAX_STEPS && tot.steps == r.steps, "steps: %d called back, %d in the totals",
          r.steps, tot.steps);
    CHECK(r.frame[0].steps + r.frame[1].steps == r.steps && r.frame[0].completed && r.frame[1].completed,
          "the frames' steps add up: %d + %d", r.frame[0].steps, r.frame[1].steps);
    CHECK(tot.worst_status == SOLVE_CONVERGED, "converged: %d", tot.worst_status);
    /* the same steps without the frame loop */
    StepWork w = {0};
    for (int k = 0; k < r.steps && k < MAX_STEPS; ++k) {
        SolveStats ss;
        StepInfo si;
        st = time_step_run(&b.sim, b.solver, &set, &w, NULL, NULL, 0, &ss, &si);
        CHECK(st == MPM_OK && si.advanced, "step %d: %s", k, mpm_last_error());
        CHECK(ss.residual == r.residual[k] && ss.outer_iters == r.outer[k],
              "step %d: residual %.17g vs %.17g, outer %d vs %d", k, ss.residual, r.residual[k], ss.outer_iters,
              r.outer[k]);
    }
    CHECK(b.sim.frame == 2 && b.sim.t == a.sim.t, "both at frame 2, t %.17g vs %.17g", b.sim.t, a.sim.t);
    time_step_work_free(&w);
    session_close(&a);
    session_close(&b);
}

/* A 1 ns budget on `scene` (steps per frame as the scene makes them): what
 * the driver hands over. */
static void budget(const char *scene, double scale, int steps_per_frame)
{
    Session s;
    if (open_session(scene, scale, "pn-pcg", &s)) return;
    Record r;
    memset(&r, 0, sizeof r);
    SolveSettings set;
    solve_settings_default(&set);
    FrameDriver d = {.frames = 3, .max_run_s = 1e-9, .after_step = record_step, .after_frame = record_frame, .ctx = &r};
    DriveTotals tot;
    char why[300];
    int st = frame_driver_run(&d, &s.sim, s.solver, &set, &tot, why, sizeof why);
    CHECK(st == MPM_OK, "%s: drive: %s", scene, mpm_last_error());
    CHECK(r.steps == 1 && tot.stopped && strstr(why, "--max-run-seconds"), "%s: one step, then stopped: %d steps, '%s'",
          scene, r.steps, why);
    if (steps_per_frame == 1) {
        /* the step ended frame 0: frame 0 complete, frame 1 cut before its first step */
        CHECK(r.frames == 2, "%s: two frames handed over, got %d", scene, r.frames);
        CHECK(r.frame[0].completed && r.frame[0].status == SOLVE_CONVERGED && r.frame[0].steps == 1,
              "%s: frame 0 complete and converged (status %d, %d steps)", scene, r.frame[0].status, r.frame[0].steps);
        CHECK(r.frame[1].frame == 1 && r.frame[1].steps == 0 && !r.frame[1].completed &&
                  r.frame[1].status == SOLVE_TIMEOUT && strstr(r.frame[1].reason, "--max-run-seconds") &&
                  r.stopping[1],
              "%s: frame 1 cut before its first step, saying why (frame %d, %d steps, status %d, '%s')", scene,
              r.frame[1].frame, r.frame[1].steps, r.frame[1].status, r.frame[1].reason);
        CHECK(tot.frames == 1 && tot.worst_status == SOLVE_TIMEOUT, "%s: totals: %d frames, worst %d", scene,
              tot.frames, tot.worst_status);
    } else {
        CHECK(r.frames == 1 && !r.frame[0].completed && r.frame[0].status == SOLVE_TIMEOUT && r.stopping[0] &&
                  strstr(r.frame[0].reason, "--max-run-seconds"),
              "%s: frame 0 cut short after its first step (%d frames, status %d, '%s')", scene, r.frames,
              r.frame[0].status, r.frame[0].reason);
    }
    session_close(&s);
}

/* Bad input: one line, MPM_EINPUT, a zeroed session. */
static void bad_input(void)
{
    static const char *const bad_set[] = {"materials.E"};
    static const char *const neg_set[] = {"materials.soft.E=-5"};
    const struct {
        SessionConfig c;
        const char *want;
    } cases[] = {
        {{.scene = "drop", .scale = 3, .solver = "no-such-solver"}, "no-such-solver"},
        {{.scene = "no-such-scene", .scale = 3, .solver = "pn-pcg"}, "no-such-scene"},
        {{.scene = "drop", .scale = 3, .solver = "pn-pcg", .set = bad_set, .n_set = 1}, "--set 'materials.E'"},
        {{.scene = "drop", .scale = -1, .solver = "pn-pcg"}, "scale"},
        {{.scene = "drop", .scale = 3, .solver = "pn-pcg", .set = neg_set, .n_set = 1}, "materials.soft.E"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        Session s;
        mpm_clear_error();
        int st = session_open(&cases[i].c, &s);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), cases[i].want) && !strchr(mpm_last_error(), '\n'),
              "case %zu: status %d, '%s' (wanted '%s')", i, st, mpm_last_error(), cases[i].want);
        CHECK(s.solver == NULL && !s.has_scene && !s.has_sim, "case %zu: nothing left to free", i);
        session_close(&s); /* harmless on a closed session */
    }
    mpm_clear_error();
}

int main(void)
{
    embedding();
    budget("drop", 3.0, 1);
    budget("bar3", 4.0, 2);
    bad_input();
    return test_summary("test_driver");
}
