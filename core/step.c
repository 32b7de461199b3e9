#include "core/step.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/collider.h"
#include "core/error.h"
#include "core/plasticity.h"
#include "core/transfer.h"

/* Grows a 3-per-node buffer to hold n nodes (with slack), keeping it otherwise. */
static int grow_node_buffer(double **buf, int *cap, int n, const char *what)
{
    if (n <= *cap) return MPM_OK;
    int c = n + n / 4 + 256;
    double *q = realloc(*buf, sizeof(double) * 3 * (size_t)c);
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: %s", what);
    *buf = q;
    *cap = c;
    return MPM_OK;
}

/* ---- Gast et al. 2015 section 6 options (scene fields, off by default) ---- */

static int scene_has_friction(const Scene *sc)
{
    for (int c = 0; c < sc->n_colliders; ++c)
        if (sc->colliders[c].kind == COLLIDER_SLIP && sc->colliders[c].friction > 0.0) return 1;
    return 0;
}

/* Coulomb friction at slip-collider nodes after the solve, on the grid
 * velocity v^{n+1} before G2P (collider_friction; Stomakhin et al. 2013
 * section 8, Gast et al. 2015 section 5.1). The normal impulse is
 * the collision impulse of the solve: at the constrained minimiser dv* the
 * unconstrained gradient g_i of E at a slip node is the impulse the
 * constraint applied (Gast 5.1: dt f_col = grad E' - grad E, the projected
 * gradient being ~0), so jn = g_i.n / m_i. problem_gradient projects only
 * when the problem has Dirichlet nodes, hence n_dirichlet is set to 0 around
 * the call (and restored). */
static int apply_collider_friction(Simulation *sim, const double *dv)
{
    const Scene *sc = sim->scene;
    StepProblem *pb = &sim->pb;
    Grid *g = &sim->grid;
    if (!sim->has_friction || pb->n_dirichlet == 0) return MPM_OK;
    int st = grow_node_buffer(&sim->grad, &sim->cap_grad, g->n, "friction gradient");
    if (st) return st;
    int nd = pb->n_dirichlet;
    pb->n_dirichlet = 0;
    problem_energy(pb, dv);
    problem_gradient(pb, dv, sim->grad);
    pb->n_dirichlet = nd;
    const double t = sim->t, dx = g->dx;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < g->n; ++i) {
        if (pb->bc[i] != BC_SLIP) continue;
        double x[3] = {g->coord[3 * i] * dx, g->coord[3 * i + 1] * dx, g->coord[3 * i + 2] * dx};
        for (int c = 0; c < sc->n_colliders; ++c) {
            const Collider *col = &sc->colliders[c];
            if (col->kind != COLLIDER_SLIP || !(col->friction > 0.0) || !collider_active(col, t)) continue;
            double n[3], vc[3];
            if (collider_phi(col, t, x, n) > 0.0) continue;
            collider_velocity(col, t, x, vc);
            const double *gi = sim->grad + 3 * (size_t)i;
            double jn = (gi[0] * n[0] + gi[1] * n[1] + gi[2] * n[2]) / g->mass[i];
            collider_friction(n, vc, col->friction, jn, sim->vnew + 3 * (size_t)i);
        }
    }
    return MPM_OK;
}

/* G2P and the position update the scene chose. The default (APIC,
 * forward Euler) is the original call, so existing scenes are unchanged. */
static void grid_to_particles(Simulation *sim)
{
    const Scene *sc = sim->scene;
    if (sc->transfer == TRANSFER_APIC && sc->position_update == POSITION_FORWARD_EULER) {
        transfer_g2p(&sim->grid, &sim->st, &sim->p, sim->vnew, sim->dt, sc->apic_ratio);
        return;
    }
    G2POptions opt = {.kind = sc->transfer,
                      .apic_ratio = sc->apic_ratio,
                      .flip_alpha = sc->flip_alpha,
                      .advect = sc->position_update == POSITION_FORWARD_EULER};
    transfer_g2p_opts(&sim->grid, &sim->st, &sim->p, sim->vnew, sim->dt, &opt);
    if (sc->position_update == POSITION_BACKWARD_EULER)
        position_update_backward_euler(&sim->grid, &sim->st, &sim->p, sim->vnew, sim->dt, &sim->pos_stats);
}

/* Gast et al. 2015 section 6.1 step 2, first step only, after the P2G. */
static void estimate_volumes(Simulation *sim)
{
    if (!sim->scene->volumes_from_density || sim->volumes_done) return;
    transfer_volumes_from_density(&sim->grid, &sim->st, &sim->p);
    sim->volumes_done = 1;
}

/* ---- end of the section 6 options ---- */

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
    sim->dt = sim->dt_next > 0.0 ? sim->dt_next : sim_next_dt(sim);
    sim->dt_next = 0.0;
    if ((st = grid_build(&sim->grid, &sim->st, &sim->p, sc->dx))) return st;
    transfer_p2g(&sim->grid, &sim->st, &sim->p);
    estimate_volumes(sim);
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
    int gst = grow_node_buffer(&sim->vnew, &sim->cap_nodes, g->n, "grid velocities");
    if (gst) return gst;
    /* v^{n+1} = v^n + dv*, the iterate at which the stopping rule held (SPEC 2 item 5) */
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < 3 * (size_t)g->n; ++k) sim->vnew[k] = g->v[k] + dv[k];
    int fst = apply_collider_friction(sim, dv);
    if (fst) return fst;
    grid_to_particles(sim);
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
