/* The common set-up of a simulation (session.h). */
#include "experiments/driver/session.h"

#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/vec.h"
#include "experiments/driver/library_startup.h"
#include "experiments/driver/registry.h"

int session_check_override(const char *text)
{
    const char *eq = strchr(text, '=');
    if (!eq || eq == text) return mpm_error(MPM_EINPUT, "--set '%s': expected key=value", text);
    if (strlen(text) >= SESSION_SET_TEXT) return mpm_error(MPM_EINPUT, "--set '%s': too long", text);
    return MPM_OK;
}

#define SESSION_MAX_SET 64

int session_load_scene(const SessionConfig *c, Scene *scene)
{
    if (c->n_set > SESSION_MAX_SET)
        return mpm_error(MPM_EINPUT, "--set: %d overrides, at most %d", c->n_set, SESSION_MAX_SET);
    SceneOverride ov[SESSION_MAX_SET];
    char text[SESSION_MAX_SET][SESSION_SET_TEXT];
    for (int i = 0; i < c->n_set; ++i) {
        int st = session_check_override(c->set[i]);
        if (st) return st;
        snprintf(text[i], SESSION_SET_TEXT, "%s", c->set[i]);
        char *eq = strchr(text[i], '=');
        *eq = '\0';
        ov[i].key = text[i];
        ov[i].value = eq + 1;
    }
    SceneLoadOptions lo = {.scale = c->scale, .overrides = ov, .n_overrides = c->n_set,
                           .asset_dir = c->asset_dir, .max_particles = c->max_particles};
    return scene_load(c->scene, &lo, scene);
}

int session_open(const SessionConfig *c, Session *s)
{
    memset(s, 0, sizeof *s);
    int st = MPM_OK;
    if (c->solver && (st = solver_from_spec(c->solver, c->solver_opts, c->n_solver_opts, &s->solver))) return st;
    if (c->threads > 0) omp_set_num_threads(c->threads);
    s->threads = omp_get_max_threads();
    if ((st = library_startup(s->solver))) goto fail;
    if ((st = session_load_scene(c, &s->scene))) goto fail;
    s->has_scene = 1;
    s->has_sim = 1; /* sim_free undoes a partial sim_init */
    if ((st = sim_init(&s->sim, &s->scene))) goto fail;
    if (c->distributed) {
        if ((st = registry_comm_open(&s->comm))) goto fail;
        s->has_comm = 1;
        /* every rank sees the same count: all of them stop here or none */
        if (c->ranks > 0 && s->comm.ranks != c->ranks) {
            st = mpm_error(MPM_EINPUT, "--ranks %d: this run is on %d MPI ranks", c->ranks, s->comm.ranks);
            goto fail;
        }
        if ((st = sim_distribute(&s->sim, &s->comm))) goto fail;
        s->sim.rebalance_above = c->rebalance_above;
        vec_sum_over_ranks(&s->comm);
    }
    return MPM_OK;
fail:
    session_close(s);
    return st;
}

void session_close(Session *s)
{
    if (s->has_comm) {
        vec_sum_over_ranks(NULL);
        s->comm.close(s->comm.ctx);
    }
    if (s->has_sim) sim_free(&s->sim);
    if (s->has_scene) scene_free(&s->scene);
    solver_destroy(s->solver);
    memset(s, 0, sizeof *s);
}
