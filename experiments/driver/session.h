/* The set-up every client of the driver shares (run, render, bench, and a
 * program that embeds mpmbench): the solver made from its spec, the OpenMP
 * team, the libraries' start-up, the scene loaded with its overrides and the
 * simulation initialised. Done here once, in this order, so no client skips
 * a part (a library started inside the first timed step, say).
 *
 *     SessionConfig c = {.scene = "bar3", .scale = 3, .solver = "hot"};
 *     Session s;
 *     int st = session_open(&c, &s);        // every input checked first
 *     ... frame_driver_run(&driver, &s.sim, s.solver, &settings, &totals, ...)
 *     session_close(&s);
 */
#ifndef MPM_SESSION_H
#define MPM_SESSION_H

#include <stddef.h>

#include "core/scene/scene_load.h"
#include "core/simulation.h"
#include "solvers/solver.h"

#define SESSION_SET_TEXT 256 /* characters of one PATH=VALUE override, with its NUL */

typedef struct {
    const char *scene;              /* built-in name or JSON path */
    double scale;                   /* grid spacing multiplier; <= 0 is refused */
    const char *const *set;         /* PATH=VALUE scene overrides, in order (a later one wins) */
    int n_set;
    const char *asset_dir;          /* NULL: beside the scene file */
    size_t max_particles;           /* 0: scene_default_max_particles() */
    const char *solver;             /* solver spec (preset or OUTER:INVERSE[:k=v,...]); NULL: none (bench) */
    const char *const *solver_opts; /* KEY=VALUE options applied after the spec's */
    int n_solver_opts;
    int threads;                    /* <= 0: OpenMP's default (OMP_NUM_THREADS or every core) */
    int distributed;                /* split the scene over the MPI ranks the program runs on (core/dist/) */
    int ranks;                      /* > 0 and distributed: the ranks it must find */
    double rebalance_above;         /* distributed: a new cut past this imbalance (0: never; dist_sim.h) */
} SessionConfig;

/* Not to be copied: sim points into scene. */
typedef struct {
    Solver *solver;  /* NULL when the config names none */
    Scene scene;
    Simulation sim;
    int threads;     /* the size of the OpenMP team the session runs on */
    int has_scene, has_sim;
    CommOps comm;    /* distributed: the ranks' communication (sim.comm points here) */
    int has_comm;
} Session;

/* Checks an override text: PATH=VALUE, shorter than SESSION_SET_TEXT.
 * MPM_EINPUT naming --set otherwise. */
int session_check_override(const char *text);

/* Loads c's scene with its scale, overrides, asset folder and particle
 * budget (scene_load), nothing else: for checking a scene without running it. */
int session_load_scene(const SessionConfig *c, Scene *scene);

/* Makes the solver (checking the spec and every option before any work),
 * sizes the OpenMP team, starts the libraries the solver needs (MPI,
 * hypre, CHOLMOD; library_startup.h: timed apart from the steps), loads the
 * scene and initialises the simulation; distributed, splits it over the
 * ranks (sim_distribute) and makes the solvers' reductions sum over them
 * (vec_sum_over_ranks) until session_close. On an error nothing is left to
 * free. */
int session_open(const SessionConfig *c, Session *s);

void session_close(Session *s);

#endif
