/* The run loop: frames of steps (step_begin, solver, step_end), CSV rows,
 * per-frame table, progress, and the failure and time-limit policy. */
#ifndef MPM_RUN_H
#define MPM_RUN_H

#include "core/scene/scene_load.h"
#include "core/step.h"
#include "solvers/solver.h"

/* What the run does when a step fails (a numerical breakdown: status failed,
 * the reason in steps.csv). Default RUN_STOP. */
typedef enum {
    RUN_STOP = 0,     /* write the step's and the frame's rows, end the run (exit 0) */
    RUN_CONTINUE = 1, /* apply the last accepted iterate and go on, unless the
                         simulation state itself broke (step_begin or step_end
                         failed): then stop as RUN_STOP */
} FailurePolicy;

#define RUN_MAX_LIST 64          /* --set and --solver-opt values */
#define RUN_SET_TEXT 256         /* characters of one --set key=value, with its NUL */

/* The settings of a run. Every field but the lists is set by one line of the
 * run settings table (experiments/cli/run_settings.c), which parses the
 * flags, reads the matrix-file keys and writes a cell's command line; a new
 * setting is a field here and a line there. */
typedef struct {
    const char *scene;          /* built-in name or JSON path */
    const char *solver;         /* solver spec: preset name or OUTER:INVERSE[:k=v,...] */
    int frames;                 /* <= 0: the scene's */
    double eps;                 /* CN tolerance */
    double scale;               /* dx multiplier */
    int threads;                /* <= 0: OpenMP default */
    const char *out_dir;        /* NULL: out/<scene>-<solver> */
    const char *set[RUN_MAX_LIST]; /* --set PATH=VALUE texts, in order (a later one wins) */
    int n_set;
    const char *solver_opts[RUN_MAX_LIST]; /* --solver-opt KEY=VALUE texts */
    int n_solver_opts;
    int history;                /* write iters.csv */
    const char *particles_dir;  /* PLY per frame when set */
    const char *vtk_dir;        /* ParaView series (experiments/run/vtk.h) when set */
    int vtk_grid;               /* with vtk_dir: also the grid series */
    const char *asset_dir;
    int armijo;                 /* the same as solver option linesearch=armijo */
    int quiet;                  /* no per-frame table */
    /* bounds on the work (0 = the default: 10000 iterations, no time limit) */
    int max_outer;              /* outer iterations per step */
    int max_linear;             /* PCG iterations per linear solve */
    double max_step_s;          /* a step's solve past this ends as timeout; the run goes on */
    double max_run_s;           /* past this the running step ends as timeout and the run stops */
    FailurePolicy on_failure;
    /* accuracy (experiments/accuracy/run_accuracy.h; NULL / 0 = off) */
    const char *error_ref;      /* --error-ref SOLVER[:eps] | auto[:eps] */
    const char *dt_from;        /* --dt-from RUN_DIR */
    const char *trajectory_ref; /* --trajectory-ref RUN_DIR */
    int trajectory;             /* --trajectory: OUT/trajectory.bin */
    size_t max_particles;       /* particle budget (--max-particles); 0: scene_default_max_particles() */
} RunConfig;

typedef struct {
    int frames, steps;          /* frames with at least one step row, step rows */
    long outer_iters, linear_iters, inner_iters;
    double wall_s, max_residual;
    int worst_status;           /* SolveStatus */
    int stopped;                /* the run ended early (failure policy or --max-run-seconds) */
    size_t particles;
    int threads;
} RunSummary;

/* One timestep: step_begin, the initial guess, the solve, step_end. dv grows
 * with the grid; its storage persists across calls (free *dv at the end). */
typedef struct StepWork {
    double *dv;
    int cap;
    /* optional (NULL = none): called after the solve and before step_end with
     * the step problem and the solver's dv, when the step is applied (the
     * reference solve of --error-ref). Its time is in no timing column
     * (StepInfo.after_solve_s); it must leave the problem's iterate cache at dv. */
    int (*after_solve)(void *ctx, StepProblem *pb, const double *dv);
    void *after_solve_ctx;
} StepWork;

typedef struct {
    double t, dt;               /* the step's start time and length */
    int active_nodes;
    double wall_s;              /* the whole step */
    double begin_s, end_s;      /* step_begin (P2G, BCs) and step_end (G2P, ...) */
    double after_solve_s;       /* the after-solve hook, not in wall_s or end_s */
    int advanced;               /* step_end ran: the simulation moved to the next step */
} StepInfo;

/* A numerical breakdown (MPM_ENUMERIC from step_begin, the solve or
 * step_end) is not an error here: ss->status is failed with the message in
 * ss->reason, and MPM_OK is returned. A failed solve is applied (step_end
 * with the last accepted iterate) only when apply_failed is set. Other
 * errors are returned. */
int run_step(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, IterHook hook, void *hook_ctx,
             int apply_failed, SolveStats *ss, StepInfo *info);

void run_config_default(RunConfig *c);
/* Loads cfg's scene with its scale, --set overrides, asset directory and
 * particle budget (scene_load). */
int run_scene_load(const RunConfig *cfg, Scene *scene);
/* Validates every setting of cfg without doing any work (no scene sampled,
 * no folder made): flags, limits, paths, the solver spec with its options
 * (solver_spec_check). MPM_EINPUT with one line naming the flag and value. */
int run_config_check(const RunConfig *cfg);
/* The solve settings cfg asks for. */
void run_solve_settings(const RunConfig *cfg, SolveSettings *set);
int run_simulation(const RunConfig *cfg, RunSummary *sum);

#endif
