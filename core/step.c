#include "core/step.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/collider.h"
#include "core/dist/dist_sim.h"
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
    /* over ranks every rank takes part (the gradient's halo sum), Dirichlet nodes or not */
    if (!sim->has_friction || (!sim->comm && pb->n_dirichlet == 0)) return MPM_OK;
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
        /* a ghost's v^{n+1} comes from its owner after this (its mass and gradient are 0 here) */
        if (pb->bc[i] != BC_SLIP || (pb->owned && !pb->owned[i])) continue;
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
static int grid_to_particles(Simulation *sim)
{
    const Scene *sc = sim->scene;
    if (sc->transfer == TRANSFER_APIC && sc->position_update == POSITION_FORWARD_EULER) {
        transfer_g2p(&sim->grid, &sim->st, &sim->p, sim->vnew, sim->dt, sc->apic_ratio);
        return MPM_OK;
    }
    G2POptions opt = {.kind = sc->transfer,
                      .apic_ratio = sc->apic_ratio,
                      .flip_alpha = sc->flip_alpha,
                      .advect = sc->position_update == POSITION_FORWARD_EULER};
    transfer_g2p_opts(&sim->grid, &sim->st, &sim->p, sim->vnew, sim->dt, &opt);
    if (sc->position_update != POSITION_BACKWARD_EULER) return MPM_OK;
    /* over ranks the velocity field needs the nodes other ranks have around this one's */
    if (sim->comm) return dist_backward_euler(sim);
    position_update_backward_euler(&sim->grid, &sim->st, &sim->p, sim->vnew, sim->dt, &sim->pos_stats);
    return MPM_OK;
}

/* Gast et al. 2015 section 6.1 step 2, first step only, after the P2G. */
static int estimate_volumes(Simulation *sim)
{
    if (!sim->scene->volumes_from_density || sim->volumes_done) return MPM_OK;
    Grid *g = &sim->grid;
    /* over ranks the particles read their ghost nodes' whole mass, the owners' */
    if (sim->comm && sim->comm->halo_copy(sim->comm->ctx, g->mass, 1)) return MPM_EINTERNAL;
    transfer_volumes_from_density(g, &sim->st, &sim->p);
    for (int i = 0; sim->comm && i < g->n; ++i)
        if (!sim->dist.owned[i]) g->mass[i] = 0.0; /* ghosts carry no mass (dist_p2g_halo) */
    sim->volumes_done = 1;
    return MPM_OK;
}

/* ---- end of the section 6 options ---- */

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

/* Every active node must get a positive, finite mass from P2G (its velocity
 * is momentum / mass): under- or overflow is a numerical breakdown. */
static int check_node_masses(const Simulation *sim)
{
    const Grid *g = &sim->grid;
    const unsigned char *owned = sim->comm ? sim->dist.owned : NULL; /* a ghost's mass is its owner's */
    int bad = g->n;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (int i = 0; i < g->n; ++i)
        if ((!owned || owned[i]) && !(g->mass[i] > 0.0 && g->mass[i] <= 1e300) && i < bad) bad = i;
    if (bad == g->n) return MPM_OK;
    const double dx = g->dx;
    return mpm_error(MPM_ENUMERIC, "t = %.9g s: grid node %d at (%g, %g, %g) got mass %g from P2G", sim->t, bad,
                     g->coord[3 * bad] * dx, g->coord[3 * bad + 1] * dx, g->coord[3 * bad + 2] * dx, g->mass[bad]);
}

/* Over MPI ranks: every rank's worst status, so all stop together when one
 * fails (its own message, or "another rank failed"); st itself on one
 * process. */
static int ranks_agree(const Simulation *sim, int st) { return sim->comm ? comm_agree(sim->comm, st) : st; }

int step_begin(Simulation *sim)
{
    const Scene *sc = sim->scene;
    int st;
    if (sim->dt_next > 0.0) sim->dt = sim->dt_next; /* a replayed step (--dt-from) */
    else if ((st = sim_next_dt(sim, &sim->dt))) return st;
    sim->dt_next = 0.0;
    if (sim->comm) /* a rank's grid: its particles' nodes, the owned nodes only others reach, the halo */
        st = dist_grid_build(&sim->dist, &sim->decomp, sim->comm, &sim->grid, &sim->st, &sim->p, sc->dx);
    else
        st = grid_build(&sim->grid, &sim->st, &sim->p, sc->dx);
    if (st) return st;
    if (sc->transfer == TRANSFER_MLS) { /* SPEC 9: MLS gradients everywhere, fused P2G */
        stencils_use_mls_gradients(&sim->st, &sim->p, sc->dx);
        transfer_p2g_mls(&sim->grid, &sim->st, &sim->p, NULL);
    } else {
        transfer_p2g(&sim->grid, &sim->st, &sim->p);
    }
    if (sim->comm && (st = dist_p2g_halo(sim))) return st;
    st = ranks_agree(sim, check_node_masses(sim));
    if (st) return st;
    if ((st = estimate_volumes(sim))) return st;
    sim->pb.comm = sim->comm;
    sim->pb.owned = sim->comm ? sim->dist.owned : NULL;
    sim->pb.decomp = sim->comm ? &sim->decomp : NULL;
    sim->pb.comm_failed = 0;
    st = problem_prepare(&sim->pb, &sim->grid, &sim->st, &sim->p, sc->materials, sc->n_materials, sim->dt, sc->gravity);
    if (!st && sim->pb.comm_failed) st = mpm_error(MPM_EINTERNAL, "t = %.9g s: a halo exchange failed", sim->t);
    if ((st = ranks_agree(sim, st))) return st;
    problem_mark_dirichlet(&sim->pb, sc->n_colliders ? collider_dirichlet : NULL, sim);
    return MPM_OK;
}

/* With domain walls the domain faces are sticky walls, but a particle
 * within 1.5 dx of one still takes velocity from free nodes inside, so
 * G2P's x += dt v can carry it across the face (it stops only once no free
 * node reaches it, half a cell in, and a fast particle overshoots in one
 * step). Material reaching a sticky wall stays there: the particle is put
 * back on the face and its outward velocity removed. Particles that stay
 * inside are untouched, so runs that never reach a wall do not change. */
static void hold_at_walls(Simulation *sim)
{
    const Scene *sc = sim->scene;
    Particles *p = &sim->p;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < p->n; ++k)
        for (int d = 0; d < 3; ++d) {
            double *x = p->x + 3 * k + d, *v = p->v + 3 * k + d;
            if (*x < sc->domain_lo[d]) {
                *x = sc->domain_lo[d];
                if (*v < 0) *v = 0;
            } else if (*x > sc->domain_hi[d]) {
                *x = sc->domain_hi[d];
                if (*v > 0) *v = 0;
            }
        }
}

static int finite9(const double *a)
{
    double s = 0.0;
    for (int k = 0; k < 9; ++k) s += a[k] * 0.0;
    return s == 0.0; /* x * 0 is NaN exactly for NaN and infinite x */
}

/* The state after a step: finite positions, velocities and F, and every
 * particle inside the domain. A failure is a numerical breakdown of the
 * step (MPM_ENUMERIC) naming the lowest such particle. */
static int check_state(const Simulation *sim)
{
    const Scene *sc = sim->scene;
    const Particles *p = &sim->p;
    size_t bad = p->n;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (size_t k = 0; k < p->n; ++k) {
        const double *x = p->x + 3 * k, *v = p->v + 3 * k;
        int ok = finite9(p->F + 9 * k) && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
        for (int d = 0; d < 3; ++d) ok &= x[d] >= sc->domain_lo[d] && x[d] <= sc->domain_hi[d];
        if (!ok && k < bad) bad = k;
    }
    if (bad == p->n) return MPM_OK;
    const double *x = p->x + 3 * bad, *v = p->v + 3 * bad, *F = p->F + 9 * bad;
    int finite = finite9(F) && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]) && isfinite(x[0]) &&
                 isfinite(x[1]) && isfinite(x[2]);
    if (!finite)
        return mpm_error(MPM_ENUMERIC,
                         "t = %.9g s: particle %zu became non-finite (x = (%g, %g, %g), v = (%g, %g, %g), F00 = %g)",
                         sim->t, bad, x[0], x[1], x[2], v[0], v[1], v[2], F[0]);
    return mpm_error(MPM_ENUMERIC,
                     "t = %.9g s: particle %zu at (%g, %g, %g) left the domain [%g, %g, %g]-[%g, %g, %g]%s",
                     sim->t, bad, x[0], x[1], x[2], sc->domain_lo[0], sc->domain_lo[1], sc->domain_lo[2],
                     sc->domain_hi[0], sc->domain_hi[1], sc->domain_hi[2],
                     sc->domain_walls ? "" : " (no domain_walls)");
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
    /* over ranks: the solver's dv is zero at the ghosts; G2P reads their owners' v^{n+1} */
    if (sim->comm && (fst = sim->comm->halo_copy(sim->comm->ctx, sim->vnew, 3))) return fst;
    if ((fst = grid_to_particles(sim))) return fst;
    if (sc->needs_plasticity) {
        int st = plasticity_apply(&sim->p, sc->materials, sc->n_materials);
        if (st) return st;
    }
    if (sc->n_sources) { /* particle sources emit after the step [t, t + dt] (SPEC 2 item 8) */
        /* over ranks every rank emits the same particles and keeps its own */
        const size_t before = sim->p.n;
        double total = (double)before;
        if (sim->comm && sim->comm->sum(sim->comm->ctx, &total, 1)) return MPM_EINTERNAL;
        int st = ranks_agree(sim, source_emit_all(sc->sources, sc->n_sources, &sim->p, sim->t, sim->dt));
        if (!st && sim->comm) st = dist_keep_emitted(sim, before, total);
        if (st) return st;
    }
    sim->t += sim->dt;
    sim->t_in_frame += sim->dt;
    if (sim->t_in_frame >= sim->frame_dt * (1.0 - 1e-12)) {
        sim->t_in_frame = 0.0;
        sim->frame++;
    }
    if (sc->domain_walls) hold_at_walls(sim);
    int st = ranks_agree(sim, check_state(sim));
    if (!st && sim->comm) { /* particles into the ranks owning their new base blocks */
        size_t sent = 0;
        st = dist_migrate(sim, &sent);
        sim->dist.migrated += sent;
        if (!st) st = dist_rebalance(sim);
    }
    return st;
}
