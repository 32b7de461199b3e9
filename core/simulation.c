/* Simulation set-up and the time-step rule (see simulation.h). */
#include "core/simulation.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/collider.h"
#include "core/error.h"

/* Gast et al. 2015 section 6.3: friction is applied only when some slip
 * collider has it. */
static int scene_has_friction(const Scene *sc)
{
    for (int c = 0; c < sc->n_colliders; ++c)
        if (sc->colliders[c].kind == COLLIDER_SLIP && sc->colliders[c].friction > 0.0) return 1;
    return 0;
}

int sim_init(Simulation *sim, const Scene *scene)
{
    memset(sim, 0, sizeof *sim);
    sim->scene = scene;
    sim->frame_dt = 1.0 / scene->fps;
    int st = particles_copy(&sim->p, &scene->particles);
    if (st) return st;
    /* per-particle plastic state only where a material reads it (snow hardening) */
    for (int m = 0; m < scene->n_materials; ++m) {
        const Material *mt = &scene->materials[m];
        if (mt->plasticity == PLASTICITY_SNOW && mt->hardening != 0.0 && (st = particles_enable_plastic_state(&sim->p)))
            return st;
    }
    sim->has_friction = scene_has_friction(scene);
    return MPM_OK;
}

void sim_free(Simulation *sim)
{
    particles_free(&sim->p);
    grid_free(&sim->grid);
    stencils_free(&sim->st);
    problem_free(&sim->pb);
    free(sim->vnew);
    free(sim->grad);
    decomposition_free(&sim->decomp);
    dist_grid_free(&sim->dist);
    memset(sim, 0, sizeof *sim);
}

int sim_next_dt(const Simulation *sim, double *dt_out)
{
    const Scene *sc = sim->scene;
    const Particles *p = &sim->p;
    double vmax = 0.0;
    size_t fastest = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t k = 0; k < p->n; ++k) {
        const double *v = p->v + 3 * k, *x = p->x + 3 * k;
        double s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (s > vmax || isnan(s)) vmax = s, fastest = k; /* a NaN is kept (s > NaN is false) and refused below */
        for (int d = 0; d < 3; ++d) {
            if (x[d] < lo[d]) lo[d] = x[d];
            if (x[d] > hi[d]) hi[d] = x[d];
        }
    }
    if (sim->comm) { /* over every rank's particles: every rank takes the same step */
        double r[7] = {vmax, -lo[0], -lo[1], -lo[2], hi[0], hi[1], hi[2]};
        int st = sim->comm->max(sim->comm->ctx, r, 7);
        if (st) return st;
        vmax = r[0];
        for (int d = 0; d < 3; ++d) lo[d] = -r[1 + d], hi[d] = r[4 + d];
    }
    vmax = sqrt(vmax);
    const char *who = "particle";
    int collider = -1;
    /* collider surface speeds over the particle box enlarged by 4 dx (reference §1.1) */
    for (int d = 0; d < 3; ++d) {
        lo[d] -= 4 * sc->dx;
        hi[d] += 4 * sc->dx;
    }
    for (int c = 0; c < sc->n_colliders; ++c) {
        const Collider *col = &sc->colliders[c];
        if (!collider_active(col, sim->t)) continue;
        double s = sc->cfl_rule == CFL_RULE_REFERENCE ? collider_max_speed_reference(col, sim->t, lo, hi)
                                                      : collider_max_speed(col, sim->t, lo, hi);
        if (s > vmax || isnan(s)) vmax = s, who = "collider", collider = c;
    }
    char name[96];
    if (collider >= 0)
        snprintf(name, sizeof name, "collider %s", sc->colliders[collider].name);
    else
        snprintf(name, sizeof name, "%s %zu", who, fastest);
    if (!isfinite(vmax))
        return mpm_error(MPM_ENUMERIC, "t = %.9g s: the CFL speed of %s is not finite (%g m/s)", sim->t, name, vmax);
    double dt = vmax > 0.0 ? sc->cfl * sc->dx / vmax : sc->max_dt;
    if (dt > sc->max_dt) dt = sc->max_dt;
    if (!(dt >= sc->min_dt))
        return mpm_error(MPM_ENUMERIC, "t = %.9g s: the CFL step %g s (speed %g m/s of %s) is below min_dt %g s",
                         sim->t, dt, vmax, name, sc->min_dt);
    double rest = sim->frame_dt - sim->t_in_frame;
    if (sim->t_in_frame + dt >= sim->frame_dt) dt = rest;
    else if (sim->t_in_frame + 2 * dt > sim->frame_dt) dt = 0.5 * rest;
    *dt_out = dt;
    return MPM_OK;
}
