/* The `run` command: a RunConfig (the command line's and a matrix cell's
 * settings) turned into a driver session and frame loop
 * (experiments/driver/), whose steps and frames it writes as steps.csv,
 * frames.csv, iters.csv, run.json, the per-frame table, PLY and VTK. */
#ifndef MPM_RUN_H
#define MPM_RUN_H

#include <stdint.h>

#include "core/scene/scene_load.h"
#include "experiments/driver/frame_driver.h"
#include "experiments/driver/session.h"
#include "solvers/solver.h"

#define RUN_MAX_LIST 64          /* --set and --solver-opt values */
#define RUN_MAX_RANKS 65536      /* --ranks: a bound on typing errors, not on the decomposition */
#define RUN_SET_TEXT SESSION_SET_TEXT /* characters of one --set key=value, with its NUL */

/* The settings of a run. Every field but the lists is set by one line of the
 * run settings table (experiments/cli/run_settings.c), which parses the
 * flags, reads the matrix-file keys and writes a cell's command line; a new
 * setting is a field here and a line there. */
typedef struct {
    const char *scene;          /* built-in name or JSON path */
    const char *solver;         /* solver spec: preset name or OUTER:INVERSE[:k=v,...] */
    int frames;                 /* <= 0: the scene's */
    double eps;                 /* CN tolerance (default SOLVE_EPS_DEFAULT, solvers/solver.h) */
    double scale;               /* dx multiplier */
    int threads;                /* <= 0: OpenMP default */
    int ranks;                  /* > 0: the MPI ranks the run must find itself on (a matrix cell runs under mpirun -np ranks) */
    double rebalance_above;     /* over ranks: cut the grid again past this imbalance (0: never) */
    const char *out_dir;        /* NULL: out/<scene>-<solver> */
    const char *set[RUN_MAX_LIST]; /* --set PATH=VALUE texts, in order (a later one wins) */
    int n_set;
    const char *solver_opts[RUN_MAX_LIST]; /* --solver-opt KEY=VALUE texts */
    int n_solver_opts;
    int history;                /* write iters.csv */
    const char *particles_dir;  /* PLY per frame when set */
    const char *vtk_dir;        /* ParaView series (experiments/run/vtk.h) when set */
    int vtk_grid;               /* with vtk_dir: also the grid series */
    double vtk_grid_min_mass;   /* grid nodes lighter than this times the frame's heaviest are left out */
    const char *asset_dir;
    int armijo;                 /* the same as solver option linesearch=armijo */
    int quiet;                  /* no per-frame table */
    /* bounds on the work (0 = the default: solve_settings_default's iterations, no time limit) */
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
    /* checkpoints (experiments/io/checkpoint.h; NULL = none) */
    const char *checkpoint_at;  /* --checkpoint-at F,F,...: OUT/checkpoints/frame_NNNN.ckpt at those frames' starts */
    double checkpoint_every_s;  /* --checkpoint-every-s S: OUT/checkpoints/resume.ckpt at a frame's start once S
                                 * seconds passed since the run began or the last one (0 = none) */
    const char *from;           /* --from FILE: continue from a checkpoint, bit for bit */
    const char *sample_from;    /* --sample-from DIR: a run's checkpoints folder */
    const char *sample_frames;  /* --sample-frames F,F,...: time each frame alone from its checkpoint in sample_from */
} RunConfig;

typedef struct {
    DriveTotals totals;         /* frames with at least one step row, step rows, iterations, ... */
    size_t particles;
    int threads;
} RunSummary;

void run_config_default(RunConfig *c);
/* What a checkpoint must have been written for: the scene file's bytes, the
 * scale and every --set, in order (experiments/io/checkpoint.h).
 * MPM_EINPUT when the scene file cannot be read again. */
int run_scene_fingerprint(const RunConfig *cfg, const Scene *scene, uint64_t *fingerprint);

/* The driver session cfg asks for (scene, scale, overrides, budget,
 * solver with the user's options, threads); `list` holds the solver
 * options' storage (RUN_MAX_LIST + 1 entries). */
void run_session_config(const RunConfig *cfg, SessionConfig *sc, const char **list);
/* Validates every setting of cfg without doing any work (no scene sampled,
 * no folder made): flags, limits, paths, the solver spec with its options
 * (solver_spec_check). MPM_EINPUT with one line naming the flag and value. */
int run_config_check(const RunConfig *cfg);
/* --checkpoint-at's value: frame numbers >= 0 separated by commas (at most
 * RUN_MAX_LIST); MPM_EINPUT naming the flag and the text otherwise. */
int run_check_frame_list(const char *text);
/* --sample-frames' value: increasing frame numbers >= 0 separated by commas. */
int run_check_sample_frames(const char *text);
/* The solve settings cfg asks for. */
void run_solve_settings(const RunConfig *cfg, SolveSettings *set);
int run_simulation(const RunConfig *cfg, RunSummary *sum);

#endif
