#include "core/step.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/collider.h"
#include "core/error.h"
#include "core/plasticity.h"
#include "core/transfer.h"

static int copy_particles(Particles *dst, const Particles *src)
{
    int st = particles_reserve(dst, src->n);
    if (st) return st;
    if (src->Jp && (st = particles_enable_plastic_state(dst))) return st;
    size_t n = src->n;
    dst->n = n;
    if (n == 0) return MPM_OK; /* a scene that starts empty (sources only): no arrays yet */
    memcpy(dst->x, src->x, sizeof(double) * 3 * n);
    memcpy(dst->v, src->v, sizeof(double) * 3 * n);
    memcpy(dst->C, src->C, sizeof(double) * 9 * n);
    memcpy(dst->F, src->F, sizeof(double) * 9 * n);
    memcpy(dst->mass, src->mass, sizeof(double) * n);
    memcpy(dst->vol, src->vol, sizeof(double) * n);
    memcpy(dst->mat, src->mat, sizeof(int) * n);
    if (src->Jp) memcpy(dst->Jp, src->Jp, sizeof(double) * n);
    return MPM_OK;
}

int sim_init(Simulation *sim, const Scene *scene)
{
    memset(sim, 0, sizeof *sim);
    sim->scene = scene;
    sim->frame_dt = 1.0 / scene->fps;
    int st = copy_particles(&sim->p, &scene->particles);
    if (st) return st;
    /* per-particle plastic state only where a material reads it (snow hardening) */
    for (int m = 0; m < scene->n_materials; ++m) {
        const Material *mt = &scene->materials[m];
        if (mt->plasticity == PLASTICITY_SNOW && mt->hardening != 0.0 && (st = particles_enable_plastic_state(&sim->p)))
            return st;
    }
    return MPM_OK;
}

void sim_free(Simulation *sim)
{
    particles_free(&sim->p);
    grid_free(&sim->grid);
    stencils_free(&sim->st);
    problem_free(&sim->pb);
    free(sim->vnew);
    memset(sim, 0, sizeof *sim);
}

double sim_next_dt(const Simulation *sim)
{
    const Scene *sc = sim->scene;
    const Particles *p = &sim->p;
    double vmax = 0.0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t k = 0; k < p->n; ++k) {
        const double *v = p->v + 3 * k, *x = p->x + 3 * k;
        double s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (s > vmax) vmax = s;
        for (int d = 0; d < 3; ++d) {
            if (x[d] < lo[d]) lo[d] = x[d];
            if (x[d] > hi[d]) hi[d] = x[d];
        }
    }
    vmax = sqrt(vmax);
    /* collider surface speeds over the particle box enlarged by 4 dx (reference §1.1) */
    for (int d = 0; d < 3; ++d) {
        lo[d] -= 4 * sc->dx;
        hi[d] += 4 * sc->dx;
    }
    for (int c = 0; c < sc->n_colliders; ++c) {
        if (!collider_active(&sc->colliders[c], sim->t)) continue;
        double s = collider_max_speed(&sc->colliders[c], sim->t, lo, hi);
        if (s > vmax) vmax = s;
    }
    double dt = vmax > 0.0 ? sc->cfl * sc->dx / vmax : sc->max_dt;
    if (dt > sc->max_dt) dt = sc->max_dt;
    if (dt < 1e-6) dt = 1e-6;
    double rest = sim->frame_dt - sim->t_in_frame;
    if (sim->t_in_frame + dt >= sim->frame_dt) dt = rest;
    else if (sim->t_in_frame + 2 * dt > sim->frame_dt) dt = 0.5 * rest;
    return dt;
}

/* Dirichlet nodes from colliders posed at t^n (SPEC 2 item 3): sticky wins,
 * slip colliders add their normals. Called per node, possibly concurrently. */
static void collider_dirichlet(const void *ctx, StepProblem *pb, int i, const double x[3])
{
    const Simulation *sim = ctx;
    const Scene *sc = sim->scene;
    double t = sim->t;
    for (int c = 0; c < sc->n_colliders; ++c) {
        const Collider *col = &sc->colliders[c];
        if (col->kind != COLLIDER_STICKY || !collider_active(col, t)) continue;
        if (collider_phi(col, t, x, NULL) <= 0.0) {
            double v[3];
            collider_velocity(col, t, x, v);
            problem_set_dirichlet(pb, i, v, NULL);
            return;
        }
    }
    for (int c = 0; c < sc->n_colliders; ++c) {
        const Collider *col = &sc->colliders[c];
        if (col->kind != COLLIDER_SLIP || !collider_active(col, t)) continue;
        double nrm[3];
        if (collider_phi(col, t, x, nrm) > 0.0) continue;
        double v[3];
        collider_velocity(col, t, x, v);
        problem_set_dirichlet(pb, i, v, nrm);
    }
}

int step_begin(Simulation *sim)
{
    const Scene *sc = sim->scene;
    int st;
    sim->dt = sim_next_dt(sim);
    if ((st = grid_build(&sim->grid, &sim->st, &sim->p, sc->dx))) return st;
    transfer_p2g(&sim->grid, &sim->st, &sim->p);
    if ((st = problem_prepare(&sim->pb, &sim->grid, &sim->st, &sim->p, sc->materials, sc->n_materials, sim->dt,
                              sc->gravity)))
        return st;
    problem_mark_dirichlet(&sim->pb, sc->n_colliders ? collider_dirichlet : NULL, sim);
    return MPM_OK;
}

int step_end(Simulation *sim, const double *dv)
{
    const Scene *sc = sim->scene;
    Grid *g = &sim->grid;
    if (g->n > sim->cap_nodes) {
        int cap = g->n + g->n / 4 + 256;
        double *v = realloc(sim->vnew, sizeof(double) * 3 * (size_t)cap);
        if (!v) return mpm_error(MPM_EINTERNAL, "out of memory: grid velocities");
        sim->vnew = v;
        sim->cap_nodes = cap;
    }
    /* v^{n+1} = v^n + dv*, the iterate at which the stopping rule held (SPEC 2 item 5) */
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < 3 * (size_t)g->n; ++k) sim->vnew[k] = g->v[k] + dv[k];
    transfer_g2p(g, &sim->st, &sim->p, sim->vnew, sim->dt, sc->apic_ratio);
    if (sc->needs_plasticity) {
        int st = plasticity_apply(&sim->p, sc->materials, sc->n_materials);
        if (st) return st;
    }
    if (sc->n_sources) { /* particle sources emit after the step [t, t + dt] (SPEC 2 item 8) */
        int st = source_emit_all(sc->sources, sc->n_sources, &sim->p, sim->t, sim->dt);
        if (st) return st;
    }
    sim->t += sim->dt;
    sim->t_in_frame += sim->dt;
    if (sim->t_in_frame >= sim->frame_dt * (1.0 - 1e-12)) {
        sim->t_in_frame = 0.0;
        sim->frame++;
    }
    /* a NaN or a particle that left the domain ends the run with a message */
    const Particles *p = &sim->p;
    size_t bad = (size_t)-1;
    for (size_t k = 0; k < p->n && bad == (size_t)-1; ++k)
        for (int d = 0; d < 3; ++d) {
            double x = p->x[3 * k + d];
            if (!isfinite(x) || x < sc->domain_lo[d] || x > sc->domain_hi[d]) {
                bad = k;
                break;
            }
        }
    if (bad != (size_t)-1) {
        const double *x = p->x + 3 * bad;
        return mpm_error(MPM_EINTERNAL, "particle %zu at (%g, %g, %g) left the domain or became non-finite at t = %g s",
                         bad, x[0], x[1], x[2], sim->t);
    }
    return MPM_OK;
}
