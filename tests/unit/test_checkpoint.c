/* floor: app */
/* Checkpoints (experiments/io/checkpoint.h) restart a simulation bit for bit:
 * a run of frames 0..N and a run restarted from the checkpoint written at the
 * start of frame k give identical steps from k on (t, dt, residual, outer and
 * linear iterations, then every particle field at the end). Scenes: sauce
 * (a source emitting during the run, von Mises plasticity, a moving source
 * collider) and snowball-drop (snow hardening: the Jp field).
 * A file that is not a checkpoint, is truncated, has one byte changed, or was
 * written for another scene is refused with one line naming the file, and
 * the simulation is left as it was. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "experiments/driver/frame_driver.h"
#include "experiments/driver/session.h"
#include "experiments/io/checkpoint.h"
#include "tests/common/testutil.h"

#define MAX_STEPS 256

typedef struct {
    int n, from_frame;
    double t[MAX_STEPS], dt[MAX_STEPS], residual[MAX_STEPS];
    int outer[MAX_STEPS], linear[MAX_STEPS];
    const char *ckpt_path; /* written at the start of frame ckpt_frame (NULL: none) */
    int ckpt_frame;
    uint64_t fingerprint;
} Trace;

static int before_step(void *ctx, Simulation *sim, int frame, int step, StepWork *w)
{
    (void)w;
    Trace *tr = ctx;
    if (tr->ckpt_path && step == 0 && frame == tr->ckpt_frame)
        return checkpoint_write(tr->ckpt_path, sim, tr->fingerprint);
    return MPM_OK;
}

static int after_step(void *ctx, const Simulation *sim, int frame, int step, const SolveStats *ss, const StepInfo *si)
{
    (void)sim, (void)step;
    Trace *tr = ctx;
    if (frame < tr->from_frame || tr->n >= MAX_STEPS) return MPM_OK;
    tr->t[tr->n] = si->t;
    tr->dt[tr->n] = si->dt;
    tr->residual[tr->n] = ss->residual;
    tr->outer[tr->n] = ss->outer_iters;
    tr->linear[tr->n] = ss->linear_iters;
    tr->n++;
    return MPM_OK;
}

static int drive(Session *s, int frames, Trace *tr)
{
    SolveSettings set;
    solve_settings_default(&set);
    FrameDriver d = {.frames = frames, .before_step = before_step, .after_step = after_step, .ctx = tr};
    DriveTotals tot;
    char why[300];
    int st = frame_driver_run(&d, &s->sim, s->solver, &set, &tot, why, sizeof why);
    CHECK(st == MPM_OK && !tot.stopped, "drive: %s %s", mpm_last_error(), why);
    return st;
}

static int same_particles(const Particles *a, const Particles *b)
{
    if (a->n != b->n || (a->Jp == NULL) != (b->Jp == NULL)) return 0;
    size_t n = a->n;
    return !memcmp(a->x, b->x, 3 * n * sizeof(double)) && !memcmp(a->v, b->v, 3 * n * sizeof(double)) &&
           !memcmp(a->C, b->C, 9 * n * sizeof(double)) && !memcmp(a->F, b->F, 9 * n * sizeof(double)) &&
           !memcmp(a->mass, b->mass, n * sizeof(double)) && !memcmp(a->vol, b->vol, n * sizeof(double)) &&
           !memcmp(a->mat, b->mat, n * sizeof(int)) && !memcmp(a->id, b->id, n * sizeof(size_t)) &&
           (!a->Jp || !memcmp(a->Jp, b->Jp, n * sizeof(double)));
}

static void restart(const char *scene, double scale, int k, int frames, const char *path)
{
    const uint64_t fp = 0x1234abcdULL;
    Session a, b;
    SessionConfig c = {.scene = scene, .scale = scale, .solver = "pn-pcg", .threads = 2};
    if (session_open(&c, &a) || session_open(&c, &b)) {
        CHECK(0, "%s: sessions: %s", scene, mpm_last_error());
        return;
    }
    static Trace full, again;
    memset(&full, 0, sizeof full);
    memset(&again, 0, sizeof again);
    full = (Trace){.from_frame = k, .ckpt_path = path, .ckpt_frame = k, .fingerprint = fp};
    again.from_frame = k;
    if (drive(&a, frames, &full)) goto done;
    int st = checkpoint_read(path, &b.sim, fp);
    CHECK(st == MPM_OK && b.sim.frame == k, "%s: read at frame %d: %s", scene, b.sim.frame, mpm_last_error());
    if (st) goto done;
    int at;
    CHECK(checkpoint_frame(path, &at) == MPM_OK && at == k, "%s: checkpoint_frame %d", scene, at);
    if (drive(&b, frames, &again)) goto done;
    CHECK(full.n > 0 && full.n == again.n, "%s: %d and %d steps from frame %d", scene, full.n, again.n, k);
    int differ = -1;
    for (int i = 0; i < full.n && i < again.n && differ < 0; ++i)
        if (full.t[i] != again.t[i] || full.dt[i] != again.dt[i] || full.residual[i] != again.residual[i] ||
            full.outer[i] != again.outer[i] || full.linear[i] != again.linear[i])
            differ = i;
    CHECK(differ < 0, "%s: step %d from frame %d differs: t %.17g/%.17g dt %.17g/%.17g res %.17g/%.17g", scene, differ,
          k, differ >= 0 ? full.t[differ] : 0, differ >= 0 ? again.t[differ] : 0, differ >= 0 ? full.dt[differ] : 0,
          differ >= 0 ? again.dt[differ] : 0, differ >= 0 ? full.residual[differ] : 0,
          differ >= 0 ? again.residual[differ] : 0);
    CHECK(same_particles(&a.sim.p, &b.sim.p) && a.sim.t == b.sim.t, "%s: the same %zu particles at the end", scene,
          a.sim.p.n);
done:
    session_close(&a);
    session_close(&b);
}

/* Copies path to bad with one change: truncate to `keep` bytes (keep >= 0) or
 * flip byte `flip`. */
static void spoil(const char *path, const char *bad, long keep, long flip)
{
    FILE *f = fopen(path, "rb"), *g = fopen(bad, "wb");
    if (!f || !g) {
        if (f) fclose(f);
        if (g) fclose(g);
        CHECK(0, "cannot copy %s", path);
        return;
    }
    long i = 0;
    for (int ch; (ch = fgetc(f)) != EOF && (keep < 0 || i < keep); ++i) fputc(i == flip ? ch ^ 0x10 : ch, g);
    fclose(f);
    fclose(g);
}

static void refused(const char *path, const char *dir)
{
    Session s;
    SessionConfig c = {.scene = "sauce", .scale = 4, .solver = "pn-pcg"};
    if (session_open(&c, &s)) return;
    const uint64_t fp = 0x1234abcdULL;
    char bad[1200];
    snprintf(bad, sizeof bad, "%s/bad.ckpt", dir);
    const struct {
        long keep, flip;
        uint64_t fp;
        const char *want;
    } cases[] = {
        {-1, -1, fp + 1, "written for another scene"},
        {100, -1, fp, "damaged or truncated"},
        {-1, 300, fp, "damaged or truncated"},
        {-1, 3, fp, "not an mpmbench checkpoint"},
        {10, -1, fp, "not a complete checkpoint"},
    };
    double t0 = s.sim.t;
    size_t n0 = s.sim.p.n;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        spoil(path, bad, cases[i].keep, cases[i].flip);
        mpm_clear_error();
        int st = checkpoint_read(bad, &s.sim, cases[i].fp);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), cases[i].want) && strstr(mpm_last_error(), "bad.ckpt") &&
                  !strchr(mpm_last_error(), '\n'),
              "case %zu: %d '%s' (wanted '%s')", i, st, mpm_last_error(), cases[i].want);
        CHECK(s.sim.t == t0 && s.sim.p.n == n0 && s.sim.frame == 0, "case %zu: the simulation unchanged", i);
    }
    mpm_clear_error();
    CHECK(checkpoint_read("/nonexistent/x.ckpt", &s.sim, fp) == MPM_EINPUT, "a missing file");
    mpm_clear_error();
    remove(bad);
    session_close(&s);
}

int main(void)
{
    char dir[] = "/tmp/mpm_ckpt_XXXXXX";
    if (!mkdtemp(dir)) return 1;
    char path[1200];
    snprintf(path, sizeof path, "%s/sauce.ckpt", dir);
    restart("sauce", 4.0, 5, 9, path); /* the source emits from frame 1 */
    refused(path, dir);
    remove(path);
    snprintf(path, sizeof path, "%s/snow.ckpt", dir);
    restart("snowball-drop", 5.0, 3, 6, path);
    remove(path);
    rmdir(dir);
    return test_summary("test_checkpoint");
}
