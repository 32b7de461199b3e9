/* The run settings table (run_settings.h). */
#include "experiments/cli/run_settings.h"

#include <stdio.h>
#include <string.h>

#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/threads.h"
#include "experiments/accuracy/error_ref.h"
#include "experiments/driver/registry.h"
#include "experiments/run/vtk.h"
#include "solvers/solver.h"

_Static_assert(RUN_MAX_LIST == OPT_LIST_MAX, "RunConfig lists hold OPT_LIST_MAX values");
_Static_assert(sizeof(FailurePolicy) == sizeof(int), "on_failure is set as an int");

static int check_solver(const char *spec) { return solver_spec_check(spec, NULL, 0); }

static const char *const on_failure_names[] = {"stop", "continue", NULL}; /* FailurePolicy order */

#define F(field) offsetof(RunConfig, field)
#define MATRIX_ALL (OPT_IN_DEFAULTS | OPT_IN_SCENES)

/* Table order is the order of the help and of a cell's command line; the
 * matrix axes of these keys vary in this order too (scene slowest). */
const Option run_settings[] = {
    {"--scene", "scene", "NAME|FILE", OPT_TEXT, 0, 0, "a scene name or file", NULL, F(scene), 0, NULL,
     OPT_IN_DEFAULTS | OPT_AXIS | OPT_ID_ALWAYS | OPT_KEY_SCENE | OPT_ARGV_ALWAYS,
     "built-in scene (mpmbench list scenes) or a scene JSON file"},
    {"--solver", "solver", "SPEC", OPT_TEXT, 0, 0, "a solver spec", NULL, F(solver), 0, check_solver,
     OPT_IN_DEFAULTS | OPT_AXIS | OPT_ID_ALWAYS | OPT_ARGV_ALWAYS,
     "preset (mpmbench list solvers) or OUTER:INVERSE[:key=value,...]"},
    {"--eps", "eps", "E", OPT_REAL, 0, 0, NULL, NULL, F(eps), 0, NULL,
     OPT_MIN_OPEN | OPT_IN_DEFAULTS | OPT_AXIS | OPT_ID_ALWAYS | OPT_ARGV_ALWAYS,
     "tolerance of the characteristic-norm stopping rule (default " OPT_SPELLED(SOLVE_EPS_DEFAULT) ")"},
    {"--scale", "scale", "S", OPT_REAL, 0, 0, NULL, NULL, F(scale), 0, NULL,
     OPT_MIN_OPEN | MATRIX_ALL | OPT_AXIS | OPT_ID_ALWAYS | OPT_ARGV_ALWAYS,
     "grid spacing times S (particle counts scale as 1/S^3; default 1)"},
    {"--threads", "threads", "T", OPT_INT, 1, MPM_MAX_THREADS, "an integer number of threads", NULL, F(threads), 0,
     NULL, OPT_IN_DEFAULTS | OPT_AXIS | OPT_ID_ALWAYS, "OpenMP threads (default: OMP_NUM_THREADS or every core)"},
    {"--ranks", "ranks", "R", OPT_INT, 1, RUN_MAX_RANKS, "an integer number of MPI ranks", NULL, F(ranks), 0, NULL,
     MATRIX_ALL | OPT_AXIS | OPT_ID_GIVEN,
     "the MPI ranks the scene is split over: the run refuses any other count (launch it as mpirun -np R mpmbench "
     "run; in a matrix file the runner does, docs/distributed.md)"},
    {"--rebalance-above", "rebalance_above", "X", OPT_REAL, 0, 1e9, "a ratio >= 0", NULL, F(rebalance_above), 0, NULL,
     MATRIX_ALL | OPT_ID_GIVEN,
     "over ranks: cut the grid again when the busiest rank holds more than X times the mean particles (default "
     OPT_SPELLED(DIST_REBALANCE_ABOVE_DEFAULT) "; 0: never)"},
    {"--frames", "frames", "N", OPT_INT, 1, 0, NULL, NULL, F(frames), 0, NULL, MATRIX_ALL | OPT_ID_ALWAYS,
     "frames to simulate (default: the scene's)"},
    {"--set", "set", "PATH=VALUE", OPT_LIST, 0, 0, "key=value", NULL, F(set), F(n_set), session_check_override,
     MATRIX_ALL | OPT_ID_ALWAYS | OPT_KEY_JSON,
     "override a scene field by its JSON path, e.g. materials.middle.E=1e9 (repeatable)"},
    {"--solver-opt", "solver_opts", "KEY=VALUE", OPT_LIST, 0, 0, "key=value", NULL, F(solver_opts), F(n_solver_opts),
     NULL, OPT_IN_DEFAULTS | OPT_ID_ALWAYS, "a solver option (mpmbench list solvers; repeatable)"},
    {"--history", "history", NULL, OPT_SWITCH, 0, 0, NULL, NULL, F(history), 0, NULL, OPT_IN_DEFAULTS | OPT_ID_ALWAYS,
     "write iters.csv: residual and energy at every outer iteration"},
    {"--armijo", "armijo", NULL, OPT_SWITCH, 0, 0, NULL, NULL, F(armijo), 0, NULL, OPT_IN_DEFAULTS | OPT_ID_ALWAYS,
     "the solver option linesearch=armijo"},
    {"--particles", "particles", "DIR", OPT_TEXT, 0, 0, "a directory name", NULL, F(particles_dir), 0, NULL,
     OPT_IN_DEFAULTS | OPT_ID_ALWAYS | OPT_KEY_SUBDIR,
     "a binary PLY of the particles per frame into DIR (in a matrix file: true = the cell's particles/)"},
    {"--vtk", NULL, "DIR", OPT_TEXT, 0, 0, "a directory name", NULL, F(vtk_dir), 0, NULL, 0,
     "a ParaView time series of the particles into DIR (particles.pvd over binary VTK XML files, one per frame)"},
    {"--vtk-grid", NULL, NULL, OPT_SWITCH, 0, 0, NULL, NULL, F(vtk_grid), 0, NULL, 0,
     "with --vtk: also the grid series (grid.pvd: active nodes, mass and velocity)"},
    {"--vtk-grid-min-mass", NULL, "R", OPT_REAL, 0, 1, "a fraction in [0, 1]", NULL, F(vtk_grid_min_mass), 0, NULL, 0,
     "with --vtk-grid: leave out the nodes lighter than R times the frame's heaviest node (default "
     OPT_SPELLED(VTK_GRID_MIN_MASS_DEFAULT) "; 0 keeps every node): a node that only the tail of a particle's "
     "weights reaches carries a velocity far from any particle's"},
    {"--asset-dir", "asset_dir", "DIR", OPT_TEXT, 0, 0, "a directory name", NULL, F(asset_dir), 0, NULL,
     OPT_IN_DEFAULTS | OPT_KEY_DIR, "where a scene's mesh files are (default: beside the scene file)"},
    {"--error-ref", "error_ref", "SOLVER[:EPS]|auto[:EPS]", OPT_TEXT, 0, 0, "a reference solver spec", NULL,
     F(error_ref), 0, error_ref_check, MATRIX_ALL | OPT_AXIS | OPT_ID_GIVEN,
     "each step's error against a reference solve of the same step problem (steps.csv err_h, e_gap, err_v_max)"},
    {"--trajectory", "trajectory", NULL, OPT_SWITCH, 0, 0, NULL, NULL, F(trajectory), 0, NULL,
     OPT_IN_DEFAULTS | OPT_ID_GIVEN, "write OUT/trajectory.bin (a reference run's particle states)"},
    {"--max-outer", "max_outer", "N", OPT_INT, 1, 0, NULL, NULL, F(max_outer), 0, NULL, MATRIX_ALL | OPT_ID_GIVEN,
     "outer iterations per step (default 10000)"},
    {"--max-linear", "max_linear", "N", OPT_INT, 1, 0, NULL, NULL, F(max_linear), 0, NULL, MATRIX_ALL | OPT_ID_GIVEN,
     "PCG iterations per linear solve (default 10000)"},
    {"--max-step-seconds", "max_step_seconds", "S", OPT_REAL, 0, 1e9, "seconds", NULL, F(max_step_s), 0, NULL,
     OPT_MIN_OPEN | MATRIX_ALL | OPT_ID_GIVEN, "a step's solve past S seconds ends as timeout; the run goes on"},
    {"--max-run-seconds", "max_run_seconds", "S", OPT_REAL, 0, 1e9, "seconds", NULL, F(max_run_s), 0, NULL,
     OPT_MIN_OPEN | MATRIX_ALL | OPT_ID_GIVEN, "past S seconds the running step ends as timeout and the run stops"},
    {"--on-failure", "on_failure", NULL, OPT_CHOICE, 0, 0, NULL, on_failure_names, F(on_failure), 0, NULL,
     MATRIX_ALL | OPT_ID_GIVEN, "after a failed step: end the run (default) or go on from the last iterate"},
    {"--dt-from", NULL, "RUN_DIR", OPT_TEXT, 0, 0, "a run directory", NULL, F(dt_from), 0, NULL, 0,
     "replay that run's time steps (a reference run made with --trajectory)"},
    {"--trajectory-ref", NULL, "RUN_DIR", OPT_TEXT, 0, 0, "a run directory", NULL, F(trajectory_ref), 0, NULL, 0,
     "the trajectory error per frame against that run (frames.csv pos_rms, pos_max, vel_rms)"},
    {"--checkpoint-at", NULL, "F,F,...", OPT_TEXT, 0, 0, "frame numbers", NULL, F(checkpoint_at), 0,
     run_check_frame_list, 0,
     "write the whole simulation state at the start of these frames (0 = the initial state) into "
     "OUT/checkpoints/frame_NNNN.ckpt"},
    {"--checkpoint-every-s", NULL, "S", OPT_REAL, 0, 1e9, "seconds", NULL, F(checkpoint_every_s), 0, NULL,
     OPT_MIN_OPEN,
     "also write OUT/checkpoints/resume.ckpt at the start of a frame once S seconds have passed since the run began "
     "or since the last one (each replaces the one before), so that a long run stopped midway goes on with --from "
     "(a matrix's checkpoint reference run does so by itself)"},
    {"--from", NULL, "FILE", OPT_TEXT, 0, 0, "a checkpoint file", NULL, F(from), 0, NULL, 0,
     "continue from a checkpoint (--checkpoint-at) of the same scene, scale and --set: the steps from its frame on "
     "are those of the run that wrote it, bit for bit; --frames is still the last frame"},
    {"--sample-from", NULL, "DIR", OPT_TEXT, 0, 0, "a checkpoints folder", NULL, F(sample_from), 0, NULL, 0,
     "with --sample-frames: the folder of a run's checkpoints (its OUT/checkpoints)"},
    {"--sample-frames", NULL, "F,F,...", OPT_TEXT, 0, 0, "increasing frame numbers", NULL, F(sample_frames), 0,
     run_check_sample_frames, 0,
     "time these frames only, each alone from its checkpoint in --sample-from, so that runs of different "
     "solvers are timed on the same states (frames.csv: one row each; a matrix reference's sample_frames)"},
    {"--max-particles", NULL, "N", OPT_SIZE, 1, 1e12, "a whole number of particles", NULL, F(max_particles), 0, NULL,
     0, "refuse a scene above N particles (default: physical memory / 16 KiB)"},
    {"--quiet", NULL, NULL, OPT_SWITCH, 0, 0, NULL, NULL, F(quiet), 0, NULL, 0, "no per-frame table on stdout"},
    {"--out", NULL, "DIR", OPT_TEXT, 0, 0, "a directory name", NULL, F(out_dir), 0, NULL, 0,
     "output folder (default out/SCENE-SOLVER)"},
    {NULL} /* end (OptionGroup tables may be given by their end) */
};
const int run_settings_count = (int)(sizeof run_settings / sizeof run_settings[0]) - 1;
_Static_assert(sizeof run_settings / sizeof run_settings[0] <= RUN_SETTINGS_MAX + 1, "at most RUN_SETTINGS_MAX settings");

int run_setting_index(const char *key) { return option_find_key(run_settings, run_settings_count, key); }

const Option *run_setting_by_flag(const char *flag)
{
    int i = option_find_flag(run_settings, run_settings_count, flag);
    return i < 0 ? NULL : &run_settings[i];
}

const Option *run_setting_by_key(const char *key)
{
    int i = option_find_key(run_settings, run_settings_count, key);
    return i < 0 ? NULL : &run_settings[i];
}

/* Appends one NUL-terminated argument. */
static int push(char *buf, size_t cap, size_t *used, int *argc, const char *arg)
{
    size_t n = strlen(arg) + 1;
    if (n > cap - *used) return mpm_error(MPM_EINPUT, "cell command line too long");
    memcpy(buf + *used, arg, n);
    *used += n;
    (*argc)++;
    return MPM_OK;
}

int run_config_argv(const RunConfig *cfg, char *buf, size_t cap, int *argc)
{
    RunConfig def;
    run_config_default(&def);
    size_t used = 0;
    *argc = 0;
    int st = push(buf, cap, &used, argc, "run");
    for (int k = 0; k < run_settings_count && !st; ++k) {
        const Option *o = &run_settings[k];
        if (o->type == OPT_LIST) {
            int n = *(const int *)(const void *)((const char *)cfg + o->count_offset);
            const char *const *list = (const char *const *)(const void *)((const char *)cfg + o->offset);
            for (int i = 0; i < n && !st; ++i)
                if (!(st = push(buf, cap, &used, argc, o->flag))) st = push(buf, cap, &used, argc, list[i]);
            continue;
        }
        if (!(o->flags & OPT_ARGV_ALWAYS) && option_equal(o, cfg, &def)) continue;
        OptionValue v;
        option_get(o, cfg, &v);
        if (o->type == OPT_TEXT && !v.s) continue;
        if (o->type == OPT_SWITCH) {
            if (v.i) st = push(buf, cap, &used, argc, o->flag);
            continue;
        }
        char text[64];
        const char *arg = text;
        if (o->type == OPT_TEXT) arg = v.s;
        else option_format(o, &v, text, sizeof text);
        if (!(st = push(buf, cap, &used, argc, o->flag))) st = push(buf, cap, &used, argc, arg);
    }
    return st;
}

int run_config_equal(const RunConfig *a, const RunConfig *b, const char **first_diff)
{
    for (int k = 0; k < run_settings_count; ++k)
        if (!option_equal(&run_settings[k], a, b)) {
            if (first_diff) *first_diff = run_settings[k].flag;
            return 0;
        }
    return 1;
}
