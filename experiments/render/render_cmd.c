/* `mpmbench render`. See render_cmd.h. */
#include "experiments/render/render_cmd.h"

#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/threads.h"
#include "core/scene/scene_load.h"
#include "experiments/cli/run_settings.h"
#include "experiments/driver/frame_driver.h"
#include "experiments/render/render.h"
#include "experiments/run/run.h"
#include "solvers/solver.h"

#define RC_DEFAULT_LONG_SIDE 800
#define RC_MIN_SHORT_SIDE 160
#define RC_MAX_SIDE 16384
#define RC_FRAME_SAMPLES 40 /* per axis, collider neighbourhood sampling */

typedef struct {
    RunConfig run;   /* the run settings render takes: scene, solver, scale, set, asset dir, threads, budget */
    int frame, width, height;
    int view;        /* index into g_views */
    int color_by;    /* 0 material, 1 speed */
    const char *out;
} RenderArgs;

static const char *const g_views[] = {"front", "side", "top", "iso", NULL};
static const char *const g_colors[] = {"material", "speed", NULL};

/* ------------------------------------------------------------------ arguments */

#define R(field) offsetof(RenderArgs, field)

static const Option render_options[] = {
    {"--frame", NULL, "N", OPT_INT, 0, 0, NULL, NULL, R(frame), 0, NULL, 0,
     "simulate N frames with the solver first (default 0: the initial state)"},
    {"--out", NULL, "FILE.png", OPT_TEXT, 0, 0, "a file name", NULL, R(out), 0, NULL, 0,
     "the picture (default SCENE.png in the working directory)"},
    {"--view", NULL, "front|side|top|iso", OPT_CHOICE, 0, 0, NULL, g_views, R(view), 0, NULL, 0,
     "direction of view (default front)"},
    {"--color", NULL, "material|speed", OPT_CHOICE, 0, 0, NULL, g_colors, R(color_by), 0, NULL, 0,
     "colour the particles by material (default) or by speed"},
    {"--width", NULL, "W", OPT_INT, 1, RC_MAX_SIDE, "an image size in pixels", NULL, R(width), 0, NULL, 0,
     "image width (default: from the height and the framed box's aspect, else 800 on the longer side)"},
    {"--height", NULL, "H", OPT_INT, 1, RC_MAX_SIDE, "an image size in pixels", NULL, R(height), 0, NULL, 0,
     "image height (with both, the box is fitted into W x H)"},
    {NULL}};

/* the run settings of the simulated frames */
static const char *const render_settings[] = {"--scene",     "--solver",  "--scale",         "--set",
                                              "--asset-dir", "--threads", "--max-particles", NULL};
static const char *const render_required[] = {"--scene", NULL};

static void render_init(void *args)
{
    RenderArgs *a = args;
    run_config_default(&a->run);
    a->run.solver = "pn-pcg";
}

/* ------------------------------------------------------------------ colliders */

/* The domain walls the scene loader adds (core/scene/scene_load.c add_walls). */
static int is_domain_wall(const Collider *c)
{
    static const char *const names[] = {"wall_x_min", "wall_x_max", "wall_y_min",
                                        "wall_y_max", "wall_z_min", "wall_z_max"};
    if (strcmp(level_set_type_name(&c->shape), "half_space")) return 0;
    for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k)
        if (!strcmp(c->name, names[k])) return 1;
    return 0;
}

/* Vertical half-spaces (side walls, e.g. Boxes and Boards) would cover the
 * whole picture as huge planes: only floors (normal near +-y) are drawn. */
static int is_side_wall(const Scene *sc, const Collider *c, double t)
{
    if (strcmp(level_set_type_name(&c->shape), "half_space")) return 0;
    double x[3], n[3] = {0, 1, 0};
    for (int d = 0; d < 3; ++d) x[d] = 0.5 * (sc->domain_lo[d] + sc->domain_hi[d]);
    collider_phi(c, t, x, n);
    return fabs(n[1]) < 0.9;
}

typedef struct {
    const Scene *sc;
    double t;
    const int *idx; /* drawn collider -> scene collider */
} SdfCtx;

static double sdf_cb(const void *ctx, int i, const double x[3])
{
    const SdfCtx *s = ctx;
    return collider_phi(&s->sc->colliders[s->idx[i]], s->t, x, NULL);
}

static double box_distance(const double p[3], const double lo[3], const double hi[3])
{
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
        double e = p[d] < lo[d] ? lo[d] - p[d] : (p[d] > hi[d] ? p[d] - hi[d] : 0);
        d2 += e * e;
    }
    return sqrt(d2);
}

static void grow(double lo[3], double hi[3], const double p[3])
{
    for (int d = 0; d < 3; ++d) {
        lo[d] = fmin(lo[d], p[d]);
        hi[d] = fmax(hi[d], p[d]);
    }
}

/* Grows [lo, hi] (the particles' box on entry) by the drawn colliders'
 * surfaces near it; see render_cmd.h. Surface samples: the points of a
 * regular grid over the neighbourhood whose |phi| is within half a cell
 * diagonal (phi is a distance or a lower bound of one, so every surface
 * point near the grid has such a sample).
 * With `empty` set (no particles), the neighbourhood is the domain, [lo, hi]
 * becomes the box of the bounded colliders' surfaces in it, and stays as it
 * was (the domain) when there are none. */
static int frame_colliders(const Scene *sc, double t, const int *idx, int n, int empty, double lo[3], double hi[3])
{
    double plo[3], phi_[3], ext = 0;
    for (int d = 0; d < 3; ++d) {
        plo[d] = lo[d];
        phi_[d] = hi[d];
        ext = fmax(ext, hi[d] - lo[d]);
    }
    if (!(ext > 0)) ext = 10 * sc->dx;
    const double pad = empty ? 0.0 : ext;
    const int G = RC_FRAME_SAMPLES;
    double nlo[3], cell[3], diag = 0;
    for (int d = 0; d < 3; ++d) {
        nlo[d] = plo[d] - pad;
        cell[d] = (phi_[d] - plo[d] + 2 * pad) / (G - 1);
        diag += cell[d] * cell[d];
    }
    double tol = 0.5 * sqrt(diag);
    size_t npts = (size_t)G * G * G;
    double *dist = malloc(npts * sizeof *dist); /* distance to the particle box of surface samples, else -1 */
    if (!dist) return mpm_error(MPM_EINTERNAL, "render: out of memory framing colliders");
    double glo[3] = {INFINITY, INFINITY, INFINITY}, ghi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (!empty) {
        memcpy(glo, plo, sizeof glo);
        memcpy(ghi, phi_, sizeof ghi);
    }
    for (int c = 0; c < n; ++c) {
        const Collider *col = &sc->colliders[idx[c]];
        int bounded = level_set_is_bounded(&col->shape);
        if (empty && !bounded) continue;
        double dmin = INFINITY;
#pragma omp parallel for reduction(min : dmin) schedule(static)
        for (long k = 0; k < (long)npts; ++k) {
            double p[3] = {nlo[0] + cell[0] * (double)(k % G), nlo[1] + cell[1] * (double)((k / G) % G),
                           nlo[2] + cell[2] * (double)(k / ((long)G * G))};
            double f = collider_phi(col, t, p, NULL);
            if (isfinite(f) && fabs(f) <= tol) {
                dist[k] = box_distance(p, plo, phi_);
                dmin = fmin(dmin, dist[k]);
            } else {
                dist[k] = -1;
            }
        }
        double limit = bounded ? INFINITY : dmin + 0.1 * ext + tol;
        for (size_t k = 0; k < npts; ++k) {
            if (dist[k] < 0 || dist[k] > limit) continue;
            double p[3] = {nlo[0] + cell[0] * (double)(k % G), nlo[1] + cell[1] * (double)((k / G) % G),
                           nlo[2] + cell[2] * (double)(k / ((size_t)G * G))};
            grow(glo, ghi, p);
        }
    }
    free(dist);
    if (glo[0] <= ghi[0]) {
        memcpy(lo, glo, sizeof glo);
        memcpy(hi, ghi, sizeof ghi);
    }
    return MPM_OK;
}

/* ------------------------------------------------------------------ image size */

static void view_axes(const char *view, double right[3], double up[3])
{
    static const double a = 0.70710678118654752, b = 0.40824829046386302;
    const double *r, *u;
    static const double fr[3] = {1, 0, 0}, fu[3] = {0, 1, 0}, sr[3] = {0, 0, -1}, tu[3] = {0, 0, -1};
    static const double ir[3] = {a, 0, -a}, iu[3] = {-b, 2 * b, -b};
    if (!strcmp(view, "side")) { r = sr; u = fu; }
    else if (!strcmp(view, "top")) { r = fr; u = tu; }
    else if (!strcmp(view, "iso")) { r = ir; u = iu; }
    else { r = fr; u = fu; }
    memcpy(right, r, 3 * sizeof *r);
    memcpy(up, u, 3 * sizeof *u);
}

static void image_size(const RenderArgs *a, const double lo[3], const double hi[3], int *W, int *H)
{
    double right[3], up[3];
    view_axes(g_views[a->view], right, up);
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    for (int k = 0; k < 8; ++k) {
        double c[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double u = c[0] * right[0] + c[1] * right[1] + c[2] * right[2];
        double v = c[0] * up[0] + c[1] * up[1] + c[2] * up[2];
        umin = fmin(umin, u);
        umax = fmax(umax, u);
        vmin = fmin(vmin, v);
        vmax = fmax(vmax, v);
    }
    double aspect = (umax - umin) / (vmax - vmin); /* width / height */
    if (!isfinite(aspect) || !(aspect > 0)) aspect = 1;
    int w = a->width, h = a->height;
    if (!w && !h) {
        if (aspect >= 1) {
            w = RC_DEFAULT_LONG_SIDE;
            h = (int)lround(w / aspect);
        } else {
            h = RC_DEFAULT_LONG_SIDE;
            w = (int)lround(h * aspect);
        }
        if (w < RC_MIN_SHORT_SIDE) w = RC_MIN_SHORT_SIDE;
        if (h < RC_MIN_SHORT_SIDE) h = RC_MIN_SHORT_SIDE;
    } else if (!h) {
        double hh = w / aspect;
        h = hh < 1 ? 1 : (hh > RC_MAX_SIDE ? RC_MAX_SIDE : (int)lround(hh));
    } else if (!w) {
        double ww = h * aspect;
        w = ww < 1 ? 1 : (ww > RC_MAX_SIDE ? RC_MAX_SIDE : (int)lround(ww));
    }
    *W = w;
    *H = h;
}

/* ------------------------------------------------------------------ command */

static int render_state(const RenderArgs *a, const Scene *sc, const Particles *p, double t, const char *path)
{
    if (p->n > (size_t)INT_MAX) return mpm_error(MPM_EINPUT, "render: too many particles (%zu)", p->n);
    int n = (int)p->n;
    int status = MPM_OK;
    int *idx = malloc((size_t)(sc->n_colliders > 0 ? sc->n_colliders : 1) * sizeof *idx);
    double *speed = NULL;
    if (!idx) return mpm_error(MPM_EINTERNAL, "render: out of memory");
    int n_draw = 0;
    for (int c = 0; c < sc->n_colliders; ++c)
        if (!is_domain_wall(&sc->colliders[c]) && !is_side_wall(sc, &sc->colliders[c], t) &&
            collider_active(&sc->colliders[c], t))
            idx[n_draw++] = c;

    /* framed box: finite particles, then the colliders near them */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int n_finite = 0;
    for (int i = 0; i < n; ++i) {
        const double *x = p->x + 3 * (size_t)i;
        if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2])) continue;
        ++n_finite;
        grow(lo, hi, x);
    }
    if (n_finite == 0) { /* no particles (yet): the colliders in the domain, else the domain */
        memcpy(lo, sc->domain_lo, sizeof lo);
        memcpy(hi, sc->domain_hi, sizeof hi);
    }
    if (n_draw > 0 && (status = frame_colliders(sc, t, idx, n_draw, n_finite == 0, lo, hi))) goto done;
    double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    if (!(ext > 0)) ext = 10 * sc->dx;
    for (int d = 0; d < 3; ++d) {
        double margin = fmax(0.1 * (hi[d] - lo[d]), 0.05 * ext);
        lo[d] -= margin;
        hi[d] += margin;
    }

    RenderOptions ro;
    memset(&ro, 0, sizeof ro);
    image_size(a, lo, hi, &ro.width, &ro.height);
    snprintf(ro.view, sizeof ro.view, "%s", g_views[a->view]);
    ro.color_by = a->color_by;
    memcpy(ro.lo, lo, sizeof lo);
    memcpy(ro.hi, hi, sizeof hi);
    if (a->color_by == 1) {
        speed = malloc((size_t)(n > 0 ? n : 1) * sizeof *speed);
        if (!speed) {
            status = mpm_error(MPM_EINTERNAL, "render: out of memory");
            goto done;
        }
        for (int i = 0; i < n; ++i) {
            const double *v = p->v + 3 * (size_t)i;
            speed[i] = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        }
        ro.scalar = speed;
    }
    SdfCtx ctx = {sc, t, idx};
    status = render_png(path, n, p->x, p->mat, sc->n_materials, n_draw, sdf_cb, &ctx, &ro);
    if (!status) printf("wrote %s (%dx%d, %s view, t = %.4g s, %d particles)\n", path, ro.width, ro.height, g_views[a->view], t, n);
done:
    free(speed);
    free(idx);
    return status;
}

static int render_run(void *args, const char *operand, int *exit_code)
{
    (void)operand, (void)exit_code;
    const RenderArgs *a = args;
    const char *solver_opts[RUN_MAX_LIST + 1];
    SessionConfig sc;
    run_session_config(&a->run, &sc, solver_opts);
    Session ses;
    int status = session_open(&sc, &ses);
    if (status) return status;
    char path[1100];
    if (a->out) snprintf(path, sizeof path, "%s", a->out);
    else snprintf(path, sizeof path, "%s.png", ses.scene.name);
    if (a->frame > 0) {
        /* the frames as `run` simulates them (no limits; a failed step ends the command) */
        SolveSettings set;
        solve_settings_default(&set);
        FrameDriver driver = {.frames = a->frame, .progress = 1};
        DriveTotals sum;
        char why[300];
        if ((status = frame_driver_run(&driver, &ses.sim, ses.solver, &set, &sum, why, sizeof why))) goto done;
        if (sum.stopped) {
            status = mpm_error(MPM_EINTERNAL, "%s", why);
            goto done;
        }
        if (sum.worst_status != SOLVE_CONVERGED)
            fprintf(stderr, "mpmbench: warning: some steps did not converge (worst status %s)\n",
                    solve_status_name((SolveStatus)sum.worst_status));
    }
    /* frame 0: the scene's particles as sampled (the simulation's copy may be reordered) */
    status = render_state(a, &ses.scene, a->frame > 0 ? &ses.sim.p : &ses.scene.particles, ses.sim.t, path);
done:
    session_close(&ses);
    return status;
}

const Command render_command = {
    .name = "render",
    .required = render_required,
    .summary = "A PNG picture of a scene: its initial state, or its state after simulating --frame N frames with "
               "--solver (default pn-pcg).",
    .notes = "Particles are coloured by material or speed; colliders are drawn, the domain walls and vertical\n"
             "half-spaces are not. The framed box is the particles' box with the colliders near it, plus a margin.\n",
    .groups = {{render_options, 0, NULL, 0, NULL}, {run_settings, 0, render_settings, R(run), "run settings"}},
    .n_groups = 2,
    .args_size = sizeof(RenderArgs),
    .init = render_init,
    .run = render_run};
