/* The run loop: frames of steps (step_begin, solver, step_end), CSV rows,
 * per-frame table, progress. */
#ifndef MPM_RUN_H
#define MPM_RUN_H

#include "core/scene.h"
#include "core/step.h"
#include "solvers/solver.h"

typedef struct {
    const char *scene;          /* built-in name or JSON path */
    const char *solver;         /* registry name */
    int frames;                 /* <= 0: the scene's */
    double eps;                 /* CN tolerance */
    double scale;               /* dx multiplier */
    int threads;                /* <= 0: OpenMP default */
    const char *out_dir;        /* NULL: out/<scene>-<solver> */
    const SceneOverride *overrides;
    int n_overrides;
    const char *const *solver_opts;
    int n_solver_opts;
    int history;                /* write iters.csv */
    const char *particles_dir;  /* PLY per frame when set */
    const char *asset_dir;
    int armijo;
    int quiet;                  /* no per-frame table */
    size_t max_particles;       /* particle budget (--max-particles); 0: scene_default_max_particles() */
} RunConfig;

typedef struct {
    int frames, steps;
    long outer_iters, linear_iters;
    double wall_s, max_residual;
    int worst_status;           /* SolveStatus */
    size_t particles;
    int threads;
} RunSummary;

/* One timestep: step_begin, the initial guess, the solve, step_end. dv grows
 * with the grid; its storage persists across calls (free *dv at the end). */
typedef struct {
    double *dv;
    int cap;
} StepWork;

typedef struct {
    double t, dt;               /* the step's start time and length */
    int active_nodes;
    double wall_s;              /* the whole step */
    double begin_s, end_s;      /* step_begin (P2G, BCs) and step_end (G2P, ...) */
} StepInfo;

int run_step(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, IterHook hook, void *hook_ctx,
             SolveStats *ss, StepInfo *info);

void run_config_default(RunConfig *c);
int run_simulation(const RunConfig *cfg, RunSummary *sum);

#endif
