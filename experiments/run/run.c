#include "experiments/run/run.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/event_log.h"
#include "core/step.h"
#include "core/scene/scene_load.h"
#include "experiments/io/checkpoint.h"
#include "experiments/io/mpi_launcher.h"
#include "experiments/io/csv_write.h"
#include "experiments/io/machine_load.h"
#include "experiments/driver/library_startup.h"
#include "experiments/io/paths.h"
#include "experiments/run/ply.h"
#include "experiments/run/vtk.h"
#include "experiments/run/provenance.h"
#include "experiments/driver/registry.h"
#include "experiments/accuracy/run_accuracy.h"
#include "solvers/solver.h"
#include "solvers/solver_definition.h"

#define RUN_MAX_SOLVER_OPTS (RUN_MAX_LIST + 1) /* the user's, and linesearch=armijo for --armijo */

void run_config_default(RunConfig *c)
{
    memset(c, 0, sizeof *c);
    c->eps = SOLVE_EPS_DEFAULT;
    c->scale = 1.0;
    c->vtk_grid_min_mass = VTK_GRID_MIN_MASS_DEFAULT;
    c->rebalance_above = DIST_REBALANCE_ABOVE_DEFAULT;
}

void run_solve_settings(const RunConfig *cfg, SolveSettings *set)
{
    solve_settings_default(set);
    set->eps = cfg->eps;
    if (cfg->max_outer > 0) set->max_outer = cfg->max_outer;
    if (cfg->max_linear > 0) set->max_linear = cfg->max_linear;
}

/* The user's solver options, plus linesearch=armijo for --armijo. */
static int solver_option_list(const RunConfig *cfg, const char **list)
{
    int n = 0;
    if (cfg->armijo) list[n++] = "linesearch=armijo";
    for (int i = 0; i < cfg->n_solver_opts && n < RUN_MAX_SOLVER_OPTS; ++i) list[n++] = cfg->solver_opts[i];
    return n;
}

void run_session_config(const RunConfig *cfg, SessionConfig *sc, const char **list)
{
    int n = solver_option_list(cfg, list);
    *sc = (SessionConfig){.scene = cfg->scene, .scale = cfg->scale, .set = cfg->set, .n_set = cfg->n_set,
                          .asset_dir = cfg->asset_dir, .max_particles = cfg->max_particles, .solver = cfg->solver,
                          .solver_opts = list, .n_solver_opts = n, .threads = cfg->threads, .ranks = cfg->ranks,
                          .rebalance_above = cfg->rebalance_above};
}

/* Frame numbers >= 0 separated by commas (increasing when asked): the
 * value of `flag`. */
static int check_frame_list(const char *flag, const char *text, int increasing)
{
    int n = 0;
    long last = -1;
    const char *c = text;
    while (*c) {
        char *end;
        long f = strtol(c, &end, 10);
        if (end == c || f < 0 || f > 100000000 || (*end && *end != ',') || ++n > RUN_MAX_LIST)
            return mpm_error(MPM_EINPUT, "%s '%s': expected at most %d frame numbers >= 0 separated by commas", flag,
                             text, RUN_MAX_LIST);
        if (increasing && f <= last)
            return mpm_error(MPM_EINPUT, "%s '%s': frame %ld after %ld (expected increasing frame numbers)", flag, text,
                             f, last);
        last = f;
        c = *end ? end + 1 : end;
        if (*end && !*c) return mpm_error(MPM_EINPUT, "%s '%s': a comma at the end", flag, text);
    }
    if (!n) return mpm_error(MPM_EINPUT, "%s '': expected frame numbers", flag);
    return MPM_OK;
}

int run_check_frame_list(const char *text) { return check_frame_list("--checkpoint-at", text, 0); }

int run_check_sample_frames(const char *text) { return check_frame_list("--sample-frames", text, 1); }

/* The sampled frames of a checked --sample-frames text; their count. */
static int sample_list(const char *text, int *frames)
{
    int n = 0;
    for (const char *c = text; c && *c && n < RUN_MAX_LIST;) {
        char *end;
        frames[n++] = (int)strtol(c, &end, 10);
        c = *end ? end + 1 : end;
    }
    return n;
}

static void sample_path(const char *dir, int frame, char *path, size_t n)
{
    snprintf(path, n, "%s/frame_%04d.ckpt", dir, frame);
}

/* Is `frame` in the (checked) list, and the largest listed frame. */
static int frame_listed(const char *list, int frame, int *largest)
{
    int found = 0;
    *largest = -1;
    for (const char *c = list; c && *c;) {
        char *end;
        long f = strtol(c, &end, 10);
        found |= f == frame;
        if (f > *largest) *largest = (int)f;
        c = *end ? end + 1 : end;
    }
    return found;
}

int run_scene_fingerprint(const RunConfig *cfg, const Scene *scene, uint64_t *fp)
{
    FILE *f = fopen(scene->path, "rb");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot read the scene file again", scene->path);
    uint64_t h = CHECKPOINT_FNV_BASIS;
    unsigned char buf[65536];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) h = checkpoint_hash(h, buf, got);
    fclose(f);
    char scale[64];
    snprintf(scale, sizeof scale, "scale=%.17g", cfg->scale);
    h = checkpoint_hash(h, scale, strlen(scale) + 1);
    for (int i = 0; i < cfg->n_set; ++i) h = checkpoint_hash(h, cfg->set[i], strlen(cfg->set[i]) + 1);
    *fp = h;
    return MPM_OK;
}

/* The machine's load over a window of the run (experiments/io/machine_load.h). */
typedef struct {
    double busy0, cpu0, t0, load_start;
    double others_cpu_s, elapsed_s;
    int cores, busy;
} LoadWindow;

static void load_window_start(LoadWindow *w)
{
    w->busy0 = machine_busy_seconds();
    w->cpu0 = process_cpu_seconds();
    w->load_start = machine_load1();
    w->t0 = event_clock();
}

/* comm: a run over ranks on this machine, whose every rank's CPU time is
 * the run's own (collective) */
static void load_window_end(LoadWindow *w, int threads, const CommOps *comm)
{
    double busy1 = machine_busy_seconds(), cpu1 = process_cpu_seconds();
    w->elapsed_s = event_clock() - w->t0;
    w->cores = (int)sysconf(_SC_NPROCESSORS_ONLN);
    w->others_cpu_s = -1.0;
    double own[2] = {cpu1 - w->cpu0, w->cpu0 >= 0 && cpu1 >= 0 ? 0.0 : 1.0}; /* CPU seconds, a failed reading */
    if (comm && comm->sum(comm->ctx, own, 2)) own[1] = 1.0;
    if (w->busy0 >= 0 && busy1 >= 0 && own[1] == 0.0) {
        w->others_cpu_s = (busy1 - w->busy0) - own[0];
        if (w->others_cpu_s < 0) w->others_cpu_s = 0.0; /* clock ticks of 10 ms against exact rusage */
    }
    w->busy = machine_was_busy(w->others_cpu_s, w->elapsed_s, threads, w->cores);
}

/* run.json gets "machine_load" once the frames have run. */
/* The output folder of the ranks but 0 of a distributed run: they write nothing. */
#define SECONDARY_RANK_DIR "/dev/null"

/* Adds key = value (taken) to DIR/run.json, written before the frames ran. */
static int add_to_run_json(const char *dir, const char *key, json_t *value)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/run.json", dir);
    json_t *root = json_load_file(path, JSON_DECODE_ANY, NULL);
    int st = MPM_OK;
    if (!root || !value || json_object_set_new(root, key, value) ||
        json_dump_file(root, path, JSON_INDENT(2) | JSON_PRESERVE_ORDER) != 0)
        st = mpm_error(MPM_EINPUT, "%s: cannot write", path);
    json_decref(root);
    return st;
}

static int add_machine_load(const char *dir, const LoadWindow *w)
{
    json_t *load = json_pack("{s:f, s:f, s:f, s:i, s:b}", "others_cpu_s", w->others_cpu_s, "elapsed_s", w->elapsed_s,
                             "load_start", w->load_start, "cores", w->cores, "machine_busy", w->busy);
    return add_to_run_json(dir, "machine_load", load);
}

static AccuracyConfig accuracy_config(const RunConfig *cfg)
{
    AccuracyConfig a = {cfg->error_ref, cfg->dt_from, cfg->trajectory_ref, cfg->trajectory};
    return a;
}

static int check_seconds(const char *flag, double v)
{
    if (!(v >= 0.0) || !isfinite(v)) return mpm_error(MPM_EINPUT, "%s %g: expected a number of seconds >= 0", flag, v);
    return MPM_OK;
}

int run_config_check(const RunConfig *cfg)
{
    int st;
    if (!cfg->scene || !cfg->scene[0]) return mpm_error(MPM_EINPUT, "run: --scene is required");
    if (!cfg->solver) return mpm_error(MPM_EINPUT, "run: --solver is required");
    if (!(cfg->scale > 0.0) || !isfinite(cfg->scale))
        return mpm_error(MPM_EINPUT, "--scale %g: expected a positive number", cfg->scale);
    if ((st = check_seconds("--max-step-seconds", cfg->max_step_s))) return st;
    if ((st = check_seconds("--max-run-seconds", cfg->max_run_s))) return st;
    if (cfg->on_failure != FAILURE_STOP && cfg->on_failure != FAILURE_CONTINUE)
        return mpm_error(MPM_EINPUT, "on_failure %d: expected stop or continue", (int)cfg->on_failure);
    SolveSettings set;
    run_solve_settings(cfg, &set);
    /* the ranges of eps and the iteration limits are the solver's to check
     * (0 asks for its default, which run_solve_settings keeps) */
    if (cfg->max_outer) set.max_outer = cfg->max_outer;
    if (cfg->max_linear) set.max_linear = cfg->max_linear;
    if ((st = solve_settings_check(&set))) return st;
    if ((st = paths_check_output_dir("--out", cfg->out_dir))) return st;
    if ((st = paths_check_output_dir("--particles", cfg->particles_dir))) return st;
    if ((st = paths_check_output_dir("--vtk", cfg->vtk_dir))) return st;
    if (cfg->vtk_grid && !cfg->vtk_dir) return mpm_error(MPM_EINPUT, "--vtk-grid: needs --vtk DIR");
    if (cfg->vtk_grid_min_mass != VTK_GRID_MIN_MASS_DEFAULT && !cfg->vtk_grid)
        return mpm_error(MPM_EINPUT, "--vtk-grid-min-mass %g: needs --vtk-grid", cfg->vtk_grid_min_mass);
    AccuracyConfig acc = accuracy_config(cfg);
    if ((st = run_accuracy_check(&acc))) return st;
    if (cfg->checkpoint_at && (st = run_check_frame_list(cfg->checkpoint_at))) return st;
    if (!cfg->sample_from != !cfg->sample_frames)
        return mpm_error(MPM_EINPUT, "%s: needs %s", cfg->sample_from ? "--sample-from" : "--sample-frames",
                         cfg->sample_from ? "--sample-frames" : "--sample-from");
    if (cfg->sample_frames) {
        /* each sampled frame runs alone: nothing that follows one trajectory */
        const char *other = cfg->from             ? "--from"
                            : cfg->checkpoint_at  ? "--checkpoint-at"
                            : cfg->checkpoint_every_s > 0 ? "--checkpoint-every-s"
                            : cfg->dt_from        ? "--dt-from"
                            : cfg->trajectory_ref ? "--trajectory-ref"
                            : cfg->trajectory     ? "--trajectory"
                            : cfg->vtk_dir        ? "--vtk"
                            : cfg->particles_dir  ? "--particles"
                            : cfg->frames > 0     ? "--frames"
                                                  : NULL;
        if (other)
            return mpm_error(MPM_EINPUT, "--sample-frames: not with %s (each sampled frame runs alone from its checkpoint)",
                             other);
    }
    if (cfg->from) {
        /* the replays and comparisons count frames from the start of the animation */
        if (cfg->dt_from || cfg->trajectory_ref || cfg->trajectory)
            return mpm_error(MPM_EINPUT, "--from: not with %s (they follow a run from frame 0)",
                             cfg->dt_from ? "--dt-from" : cfg->trajectory_ref ? "--trajectory-ref" : "--trajectory");
        int frame;
        if ((st = checkpoint_frame(cfg->from, &frame))) return st;
    }
    const char *opts[RUN_MAX_SOLVER_OPTS];
    int n = solver_option_list(cfg, opts);
    return solver_spec_check(cfg->solver, opts, n);
}

static FILE *open_in(const char *dir, const char *name, int *status)
{
    if (!strcmp(dir, SECONDARY_RANK_DIR)) { /* a distributed run's rank other than 0 writes nothing */
        FILE *f = fopen("/dev/null", "w");
        if (!f) *status = mpm_error(MPM_EINTERNAL, "/dev/null: cannot write");
        return f;
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) *status = mpm_error(MPM_EINPUT, "%s: cannot write", path);
    return f;
}

/* What `run` writes as the frame driver goes: the CSV rows, the table, the
 * particles. */
typedef struct {
    const RunConfig *cfg;
    const Scene *scene;
    const Solver *solver;
    RunAccuracy *acc;
    FILE *steps_csv, *frames_csv, *iters_csv;
    int threads;
    VtkSeries *vtk;            /* --vtk: the ParaView series, else NULL */
    const char *out_dir;
    uint64_t fingerprint;      /* the scene's, for checkpoints */
    const CommOps *comm;       /* a distributed run's ranks, else NULL */
    int first_frame;           /* the frame the run starts at (0, or --from's) */
    double resume_clock;       /* event_clock() of the run's start or its last resume checkpoint */
} RunOutput;

/* --sample-frames: the state at the start of a sampled frame, from its checkpoint */
static int restore_sample(void *ctx, Simulation *sim, int frame)
{
    const RunOutput *o = ctx;
    char path[1200];
    sample_path(o->cfg->sample_from, frame, path, sizeof path);
    return checkpoint_read(path, sim, o->fingerprint);
}

static void write_iteration(void *ctx, int frame, int step, int iter, double elapsed, double residual, double energy)
{
    RunOutput *o = ctx;
    if (o->iters_csv)
        fprintf(o->iters_csv, "%d,%d,%d,%.6e,%.9e,%.12e\n", frame, step, iter, elapsed, residual, energy);
}

static int before_step(void *ctx, Simulation *sim, int frame, int step, StepWork *w)
{
    RunOutput *o = ctx;
    int largest;
    if (step == 0 && o->cfg->checkpoint_at && frame_listed(o->cfg->checkpoint_at, frame, &largest)) {
        char path[1200];
        snprintf(path, sizeof path, "%s/checkpoints", o->out_dir);
        int st = paths_mkdir_p(path);
        snprintf(path, sizeof path, "%s/checkpoints/frame_%04d.ckpt", o->out_dir, frame);
        if (st || (st = checkpoint_write(path, sim, o->fingerprint))) return st;
    }
    /* --checkpoint-every-s: where a stopped run goes on from (each replaces the last) */
    if (step == 0 && o->cfg->checkpoint_every_s > 0 && frame > o->first_frame &&
        event_clock() - o->resume_clock >= o->cfg->checkpoint_every_s) {
        char path[1200];
        snprintf(path, sizeof path, "%s/checkpoints", o->out_dir);
        int st = paths_mkdir_p(path);
        snprintf(path, sizeof path, "%s/checkpoints/resume.ckpt", o->out_dir);
        if (st || (st = checkpoint_write(path, sim, o->fingerprint))) return st;
        o->resume_clock = event_clock();
    }
    return run_accuracy_before_step(o->acc, sim, step, w);
}

static int write_step(void *ctx, const Simulation *sim, int frame, int step, const SolveStats *ss, const StepInfo *si)
{
    RunOutput *o = ctx;
    FILE *f = o->steps_csv;
    /* over ranks: the whole scene's particles and (owned) nodes, and the blocks every rank
     * assembled (ghost rows included); every rank sums, rank 0 writes */
    double counts[3] = {(double)sim->p.n, o->comm ? (double)sim->dist.n_owned : (double)si->active_nodes,
                        (double)ss->hessian_blocks};
    if (o->comm && o->comm->sum(o->comm->ctx, counts, 3)) return MPM_EINTERNAL;
    /* t and dt read back as the same doubles (--dt-from replays them) */
    csv_write_name(f, o->scene->name);
    fputc(',', f);
    csv_write_name(f, o->solver->name);
    fprintf(f, ",%d,%d,%.17g,%.17g,%zu,%d,%lld,%d,%ld,%d,%.6e,%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d,%ld,",
            frame, step, si->t, si->dt, (size_t)counts[0], (int)counts[1],
            (long long)counts[2], ss->outer_iters, ss->linear_iters, ss->ls_evals, ss->residual,
            solve_status_name(ss->status), si->wall_s, si->begin_s, ss->assemble_s, ss->setup_s, ss->solve_s,
            ss->linesearch_s, si->end_s, o->threads, ss->inner_iters);
    fprintf(f, "%.9g,", ss->energy_increase_max);
    run_accuracy_step_fields(f, o->acc);
    csv_write_text(f, ss->reason); /* the reason stays the last field */
    fputc('\n', f);
    /* each step's row is on disk when the step ends: a frame of a large scene
     * takes minutes, and a run stopped inside it keeps its finished steps */
    fflush(f);
    return MPM_OK;
}

/* --vtk-grid: is there a grid to write, and its heaviest node (the whole
 * scene's over ranks: collective). */
static int vtk_grid_frame(const RunOutput *o, const Simulation *sim, VtkGridFrame *grid, int *with_grid)
{
    *grid = (VtkGridFrame){&sim->grid, sim->vnew, o->comm ? sim->dist.owned : NULL, 0.0};
    *with_grid = o->vtk && o->vtk->grid && sim->vnew && (o->comm || sim->grid.n > 0);
    if (*with_grid) grid->heaviest = vtk_heaviest_node(&sim->grid, grid->owned);
    if (o->comm && o->vtk && o->vtk->grid && o->comm->max(o->comm->ctx, &grid->heaviest, 1)) return MPM_EINTERNAL;
    return MPM_OK;
}

static int write_frame_files(RunOutput *o, const Simulation *sim, const FrameSums *fs, int stopping,
                             const VtkGridFrame *grid);

/* Over ranks the frame's collectives come first and an agreement last: a
 * rank that failed to write stops every rank before the next step's
 * collectives. */
static int write_frame(void *ctx, const Simulation *sim, const FrameSums *fs, int stopping)
{
    RunOutput *o = ctx;
    VtkGridFrame grid;
    int with_grid = 0;
    int status = vtk_grid_frame(o, sim, &grid, &with_grid);
    if (!status) status = write_frame_files(o, sim, fs, stopping, with_grid ? &grid : NULL);
    return o->comm ? comm_agree(o->comm, status) : status;
}

static int write_frame_files(RunOutput *o, const Simulation *sim, const FrameSums *fs, int stopping,
                             const VtkGridFrame *grid)
{
    FILE *f = o->frames_csv;
    /* complete 0: the run's time limit cut the frame short (not a frame to time) */
    csv_write_name(f, o->scene->name);
    fputc(',', f);
    csv_write_name(f, o->solver->name);
    fprintf(f, ",%d,%d,%ld,%ld,%.6f,%.6e,%s,%d,%ld,%d,", fs->frame, fs->steps,
            fs->outer_iters, fs->linear_iters, fs->wall_s, fs->max_residual, solve_status_name((SolveStatus)fs->status),
            o->threads, fs->inner_iters, fs->completed);
    int status = run_accuracy_frame_end(o->acc, sim, fs->frame, fs->steps, fs->completed, f);
    csv_write_text(f, fs->reason);
    fputc('\n', f);
    if (status) return status;
    fflush(f);
    if (!o->cfg->quiet)
        printf("%6d %6d %8ld %9ld %9ld %10.3f %12.3e  %s\n", fs->frame, fs->steps, fs->outer_iters, fs->linear_iters,
               fs->inner_iters, fs->wall_s, fs->max_residual, solve_status_name((SolveStatus)fs->status));
    fflush(stdout);
    if (o->cfg->particles_dir && !stopping) {
        char path[1200];
        snprintf(path, sizeof path, "%s/frame_%04d.ply", o->cfg->particles_dir, fs->frame + 1);
        if ((status = ply_write_particles(path, &sim->p))) return status;
    }
    if (o->vtk && !stopping)
        return vtk_series_frame(o->vtk, fs->frame + 1, sim->t, &sim->p, o->scene->materials, o->scene->n_materials,
                                grid);
    return MPM_OK;
}

/* Records the exact configuration beside the tables, so every number says
 * how it was made (jansson escapes every string). */
static void write_run_json(const char *dir, const RunConfig *cfg, const Scene *sc, const Solver *solver,
                           const SolveSettings *set, const RunAccuracy *acc, int frames, int first_frame, int threads,
                           int *status)
{
    AccuracyConfig ac = accuracy_config(cfg);
    const SolverOptions *so = &solver->opts;
    json_t *opts = json_object(), *ovr = json_object();
    /* every option the solver consulted, with the value in effect (given or default) */
    for (int i = 0; i < so->n_asked; ++i) json_object_set_new(opts, so->asked[i], json_string(so->asked_value[i]));
    for (int i = 0; i < cfg->n_set; ++i) {
        const char *eq = strchr(cfg->set[i], '='); /* checked when the scene was loaded */
        char key[RUN_SET_TEXT];
        snprintf(key, sizeof key, "%.*s", eq ? (int)(eq - cfg->set[i]) : 0, cfg->set[i]);
        json_object_set_new(ovr, key, json_string(eq ? eq + 1 : ""));
    }
    json_t *limits = json_pack("{s:i, s:i, s:f, s:f, s:s}", "max_outer", set->max_outer, "max_linear", set->max_linear,
                               "max_step_seconds", cfg->max_step_s, "max_run_seconds", cfg->max_run_s, "on_failure",
                               cfg->on_failure == FAILURE_CONTINUE ? "continue" : "stop");
    json_t *root = json_pack("{s:s, s:s, s:s, s:s, s:s, s:o, s:o, s:f, s:f, s:f, s:i, s:i, s:s, s:o, s:I}", "scene",
                             sc->name, "scene_path", sc->path, "solver", cfg->solver, "outer_method",
                             solver->outer->ops->name, "inverse_approximation", solver->inv->ops->name,
                             "solver_options", opts, "overrides", ovr, "eps", cfg->eps, "scale", cfg->scale, "dx",
                             sc->dx, "frames", frames, "threads", threads, "line_search", solver->ls->name, "limits",
                             limits, "particles", (json_int_t)sc->particles.n);
    char definition[4096], hash[SOLVER_DEFINITION_HASH_LEN];
    if (root && solver_definition(solver, definition, sizeof definition, hash) == MPM_OK) {
        /* what the solver ran, whatever its name: a study is stale for it when
         * the current build's definition of the same spec hashes differently */
        json_object_set_new(root, "solver_definition", json_string(definition));
        json_object_set_new(root, "solver_definition_hash", json_string(hash));
    } else if (root) {
        *status = MPM_EINTERNAL;
    }
    if (root) json_object_set_new(root, "accuracy", (json_t *)run_accuracy_json(&ac, acc));
    if (root) /* where the run started and where it leaves checkpoints */
        json_object_set_new(root, "checkpoints",
                            json_pack("{s:o, s:i, s:o, s:o, s:o, s:o}", "from",
                                      cfg->from ? json_string(cfg->from) : json_null(), "first_frame", first_frame,
                                      "at", cfg->checkpoint_at ? json_string(cfg->checkpoint_at) : json_null(),
                                      "every_s",
                                      cfg->checkpoint_every_s > 0 ? json_real(cfg->checkpoint_every_s) : json_null(),
                                      "sample_from", cfg->sample_from ? json_string(cfg->sample_from) : json_null(),
                                      "sample_frames",
                                      cfg->sample_frames ? json_string(cfg->sample_frames) : json_null()));
    if (root) json_object_set_new(root, "startup_s", json_real(library_startup_seconds()));
    /* threads each phase ran on: the inverse approximation's library may
     * not use the run's OpenMP team (hypre: 1 in Debian's build) */
    const InvApprox *inv = solver->inv;
    if (root)
        json_object_set_new(root, "phase_threads",
                            json_pack("{s:i, s:i, s:i, s:i, s:i, s:i, s:i}", "p2g", threads, "assemble", threads,
                                      "inverse_setup", inv->setup_threads ? inv->setup_threads : threads,
                                      "inverse_apply", inv->apply_threads ? inv->apply_threads : threads, "solve",
                                      threads, "linesearch", threads, "g2p", threads));
    if (root) json_object_set_new(root, "provenance", provenance_json(threads, 0));
    char path[1200];
    snprintf(path, sizeof path, "%s/run.json", dir);
    if (!root || json_dump_file(root, path, JSON_INDENT(2) | JSON_PRESERVE_ORDER) != 0)
        *status = mpm_error(MPM_EINPUT, "%s: cannot write", path);
    json_decref(root);
}

/* A distributed run's split into run.json ("distributed": the rank count,
 * each rank's particles and owned nodes at the end, the particles each
 * sent away over the run, and what each communicated: the halo's seconds
 * and bytes, per step too, the collectives and their seconds). Collective:
 * every rank gathers, rank 0 writes. */
enum { DIST_PARTICLES, DIST_NODES, DIST_MOVED, DIST_HALO_S, DIST_HALO_SENT, DIST_HALO_RECEIVED, DIST_HALO_OPS, DIST_COLL_OPS, DIST_COLL_S, DIST_FIELDS };
static int add_distribution(const char *out_dir, const Session *ses, int steps)
{
    const CommOps *c = &ses->comm;
    const int R = c->ranks;
    double *v = calloc(DIST_FIELDS * (size_t)R, sizeof(double));
    if (!v) return mpm_error(MPM_EINTERNAL, "out of memory");
    CommStats cs = {0};
    if (c->stats) c->stats(c->ctx, &cs);
    v[DIST_PARTICLES * R + c->rank] = (double)ses->sim.p.n;
    v[DIST_NODES * R + c->rank] = ses->sim.dist.n_owned;
    v[DIST_MOVED * R + c->rank] = (double)ses->sim.dist.migrated;
    v[DIST_HALO_S * R + c->rank] = cs.halo_s;
    v[DIST_HALO_SENT * R + c->rank] = cs.halo_bytes_sent;
    v[DIST_HALO_RECEIVED * R + c->rank] = cs.halo_bytes_received;
    v[DIST_HALO_OPS * R + c->rank] = (double)cs.halo_ops;
    v[DIST_COLL_OPS * R + c->rank] = (double)cs.collectives;
    v[DIST_COLL_S * R + c->rank] = cs.collective_s;
    int st = c->sum(c->ctx, v, DIST_FIELDS * R);
    if (!st && c->rank == 0) {
        json_t *d = json_object(), *parts = json_array(), *nodes = json_array(), *moved = json_array();
        json_t *halo_s = json_array(), *sent = json_array(), *received = json_array(), *sent_step = json_array();
        json_t *ops = json_array(), *coll_ops = json_array(), *coll_s = json_array();
        for (int r = 0; r < R; ++r) {
            json_array_append_new(parts, json_integer((json_int_t)v[DIST_PARTICLES * R + r]));
            json_array_append_new(nodes, json_integer((json_int_t)v[DIST_NODES * R + r]));
            json_array_append_new(moved, json_integer((json_int_t)v[DIST_MOVED * R + r]));
            json_array_append_new(halo_s, json_real(v[DIST_HALO_S * R + r]));
            json_array_append_new(sent, json_real(v[DIST_HALO_SENT * R + r]));
            json_array_append_new(received, json_real(v[DIST_HALO_RECEIVED * R + r]));
            json_array_append_new(sent_step, json_real(steps > 0 ? v[DIST_HALO_SENT * R + r] / steps : 0.0));
            json_array_append_new(ops, json_integer((json_int_t)v[DIST_HALO_OPS * R + r]));
            json_array_append_new(coll_ops, json_integer((json_int_t)v[DIST_COLL_OPS * R + r]));
            json_array_append_new(coll_s, json_real(v[DIST_COLL_S * R + r]));
        }
        json_object_set_new(d, "ranks", json_integer(R));
        json_object_set_new(d, "decomposition", json_string("4x4x4 node blocks along a Morton curve, cut by particles"));
        json_object_set_new(d, "particles_per_rank", parts);
        json_object_set_new(d, "owned_nodes_per_rank", nodes);
        json_object_set_new(d, "particles_sent_per_rank", moved);
        /* the same on every rank: the counts they cut by were summed */
        json_object_set_new(d, "rebalance_above", json_real(ses->sim.rebalance_above));
        json_object_set_new(d, "recuts", json_integer(ses->sim.recuts));
        json_object_set_new(d, "worst_imbalance", json_real(ses->sim.worst_imbalance));
        /* the whole run (set-up and output included) */
        json_object_set_new(d, "halo_ops_per_rank", ops);
        json_object_set_new(d, "halo_seconds_per_rank", halo_s);
        json_object_set_new(d, "halo_bytes_sent_per_rank", sent);
        json_object_set_new(d, "halo_bytes_received_per_rank", received);
        json_object_set_new(d, "halo_bytes_sent_per_step_per_rank", sent_step);
        json_object_set_new(d, "collectives_per_rank", coll_ops);
        json_object_set_new(d, "collective_seconds_per_rank", coll_s);
        st = add_to_run_json(out_dir, "distributed", d);
    }
    free(v);
    return st;
}

int run_simulation(const RunConfig *cfg, RunSummary *sum)
{
    int status = MPM_OK;
    memset(sum, 0, sizeof *sum);
    /* every input checked before any work */
    if ((status = run_config_check(cfg))) return status;
    const char *solver_opts[RUN_MAX_SOLVER_OPTS];
    SessionConfig scfg;
    run_session_config(cfg, &scfg, solver_opts);
    /* under mpirun the scene is split over the ranks (docs/distributed.md) */
    scfg.distributed = under_mpi_launcher();
    if (scfg.distributed) {
        const char *other = cfg->particles_dir    ? "--particles"
                            : cfg->trajectory     ? "--trajectory"
                            : cfg->trajectory_ref ? "--trajectory-ref"
                            : cfg->dt_from        ? "--dt-from"
                            : cfg->error_ref      ? "--error-ref"
                            : cfg->checkpoint_at  ? "--checkpoint-at"
                            : cfg->checkpoint_every_s > 0 ? "--checkpoint-every-s"
                            : cfg->from           ? "--from"
                            : cfg->sample_frames  ? "--sample-frames"
                                                  : NULL;
        if (other) return mpm_error(MPM_EINPUT, "%s: not in a run over MPI ranks yet (docs/distributed.md)", other);
    } else if (cfg->ranks > 1) {
        return mpm_error(MPM_EINPUT, "--ranks %d: this run is one process; launch it as mpirun -np %d mpmbench run ...",
                         cfg->ranks, cfg->ranks);
    }
    SolveSettings set;
    run_solve_settings(cfg, &set);
    AccuracyConfig acfg = accuracy_config(cfg);
    RunAccuracy acc;
    memset(&acc, 0, sizeof acc);
    /* the solver, the thread team, the libraries (started and timed here, not
     * in the first step), the scene and the simulation */
    Session ses;
    if ((status = session_open(&scfg, &ses))) return status;
    Solver *solver = ses.solver;
    const Scene *scene = &ses.scene;
    Simulation *sim = &ses.sim;
    int threads = ses.threads;
    const int secondary = ses.has_comm && ses.comm.rank > 0; /* writes nothing, prints nothing */
    RunConfig own = *cfg;
    if (secondary) own.quiet = 1;
    cfg = &own;
    if ((status = run_accuracy_create(&acfg, &acc))) {
        run_accuracy_free(&acc);
        session_close(&ses);
        return status;
    }
    int frames = cfg->frames > 0 ? cfg->frames : scene->frames;
    int samples[RUN_MAX_LIST], n_samples = cfg->sample_frames ? sample_list(cfg->sample_frames, samples) : 0;
    if (n_samples) frames = samples[n_samples - 1] + 1; /* the last frame the run reaches */
    /* the reference runs and checkpoints match this scene: checked before the output folder is made */
    uint64_t fingerprint = 0;
    int largest = -1;
    if (cfg->checkpoint_at) frame_listed(cfg->checkpoint_at, -1, &largest);
    if ((status = run_accuracy_bind(&acfg, scene, frames, &acc)) ||
        ((cfg->from || cfg->checkpoint_at || cfg->checkpoint_every_s > 0 || n_samples) &&
         (status = run_scene_fingerprint(cfg, scene, &fingerprint))) ||
        (cfg->from && (status = checkpoint_read(cfg->from, sim, fingerprint)))) {
        run_accuracy_free(&acc);
        session_close(&ses);
        return status;
    }
    for (int i = 0; i < n_samples && !status; ++i) { /* every sampled state is there and of this scene */
        char path[1200];
        sample_path(cfg->sample_from, samples[i], path, sizeof path);
        if ((status = checkpoint_read(path, sim, fingerprint)))
            status = mpm_error_context(status, "--sample-frames %d", samples[i]);
        else if (sim->frame != samples[i])
            status = mpm_error(MPM_EINPUT, "--sample-frames %d: %s starts at frame %d", samples[i], path, sim->frame);
    }
    if (status) {
        run_accuracy_free(&acc);
        session_close(&ses);
        return status;
    }
    if (cfg->from && sim->frame >= frames)
        status = mpm_error(MPM_EINPUT, "--from %s starts at frame %d: --frames %d leaves nothing to run", cfg->from,
                           sim->frame, frames);
    else if (largest >= frames)
        status = mpm_error(MPM_EINPUT, "--checkpoint-at %s: frame %d is not before the run's end (%d frames)",
                           cfg->checkpoint_at, largest, frames);
    else if (largest >= 0 && largest < sim->frame)
        status = mpm_error(MPM_EINPUT, "--checkpoint-at %s: frame %d is before the checkpoint's frame %d",
                           cfg->checkpoint_at, largest, sim->frame);
    if (status) {
        run_accuracy_free(&acc);
        session_close(&ses);
        return status;
    }

    char out_dir[1024];
    if (secondary) snprintf(out_dir, sizeof out_dir, "%s", SECONDARY_RANK_DIR);
    else if (cfg->out_dir) snprintf(out_dir, sizeof out_dir, "%s", cfg->out_dir);
    else snprintf(out_dir, sizeof out_dir, "out/%s-%s", scene->name, solver->name);
    FILE *steps_csv = NULL, *frames_csv = NULL, *iters_csv = NULL;
    VtkSeries vtk;
    memset(&vtk, 0, sizeof vtk);
    if (!secondary && (status = paths_mkdir_p(out_dir))) goto setup_end;
    if (cfg->particles_dir && (status = paths_mkdir_p(cfg->particles_dir))) goto setup_end;
    if (cfg->vtk_dir && (status = vtk_series_open(&vtk, cfg->vtk_dir, cfg->vtk_grid, cfg->vtk_grid_min_mass,
                                                  ses.has_comm ? ses.comm.rank : 0, ses.has_comm ? ses.comm.ranks : 1)))
        goto setup_end;
    if (!(steps_csv = open_in(out_dir, "steps.csv", &status))) goto setup_end;
    if (!(frames_csv = open_in(out_dir, "frames.csv", &status))) goto setup_end;
    if (cfg->history && !(iters_csv = open_in(out_dir, "iters.csv", &status))) goto setup_end;
    if ((status = run_accuracy_open(&acc, out_dir, scene))) goto setup_end;
    if (!secondary)
        write_run_json(out_dir, cfg, scene, solver, &set, &acc, frames, n_samples ? samples[0] : sim->frame, threads,
                       &status);
    if (status) goto setup_end;
    fprintf(steps_csv, "scene,solver,frame,step,t,dt,particles,active_nodes,hessian_blocks,outer_iters,linear_iters,"
                       "ls_evals,residual,status,wall_s,p2g_s,assemble_s,setup_s,solve_s,linesearch_s,g2p_s,threads,"
                       "inner_iters,max_energy_rise,%s,reason\n",
            run_accuracy_step_header);
    fprintf(frames_csv,
            "scene,solver,frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,threads,inner_iters,complete,%s,"
            "reason\n",
            run_accuracy_frame_header);
    if (iters_csv) fprintf(iters_csv, "frame,step,iter,elapsed_s,residual,energy\n");

    if (cfg->vtk_dir && (status = vtk_series_frame(&vtk, sim->frame, sim->t, &sim->p, scene->materials, scene->n_materials,
                                                   NULL)))
        goto setup_end;
setup_end:
    /* over ranks a rank that could not make its files stops every rank
     * here, before the first step's collectives */
    if (ses.has_comm) status = comm_agree(&ses.comm, status);
    if (status) goto done;
    sum->particles = scene->particles.n;
    sum->threads = threads;
    if (!cfg->quiet) {
        printf("scene %s (%zu particles, dx %.4g m), solver %s, eps %.1e, %d thread%s\n", scene->name, scene->particles.n,
               scene->dx, solver->name, cfg->eps, threads, threads == 1 ? "" : "s");
        if (acc.ref) printf("error reference: %s (its time is in ref_s, not in the timings)\n", error_ref_describe(acc.ref));
        printf("%6s %6s %8s %9s %9s %10s %12s  %s\n", "frame", "steps", "outer", "linear", "inner", "wall_s",
               "max_resid", "status");
    }
    RunOutput out = {cfg,     scene,   solver,      &acc, steps_csv, frames_csv, iters_csv, threads,
                     cfg->vtk_dir ? &vtk : NULL, out_dir, fingerprint, ses.has_comm ? &ses.comm : NULL,
                     sim->frame, event_clock()};
    FrameDriver driver = {.frames = frames,
                          .sample_frames = samples,
                          .n_samples = n_samples,
                          .restore = restore_sample,
                          .on_failure = cfg->on_failure,
                          .progress = !secondary,
                          .max_step_s = cfg->max_step_s,
                          .max_run_s = cfg->max_run_s,
                          .before_step = before_step,
                          .after_step = write_step,
                          .after_frame = write_frame,
                          .iteration = write_iteration,
                          .ctx = &out};
    char stop_reason[300];
    /* the machine's load while the frames run: a time taken while other
     * processes used the cores the run needed is not a valid time */
    LoadWindow load;
    load_window_start(&load);
    if ((status = frame_driver_run(&driver, sim, solver, &set, &sum->totals, stop_reason, sizeof stop_reason))) goto done;
    /* over ranks on this machine, every rank's threads are the run's own */
    const int run_threads = ses.has_comm ? threads * ses.comm.ranks : threads;
    load_window_end(&load, run_threads, ses.has_comm ? &ses.comm : NULL);
    fflush(steps_csv);
    fflush(frames_csv);
    const DriveTotals *tot = &sum->totals;
    if (tot->stopped && !secondary) fprintf(stderr, "mpmbench: run stopped: %s\n", stop_reason);
    if (!cfg->quiet) {
        printf("total: %d frames, %d steps, %ld outer, %ld linear, %ld inner iterations, %.3f s wall (%.3f s/frame), "
               "worst status %s\n",
               tot->frames, tot->steps, tot->outer_iters, tot->linear_iters, tot->inner_iters, tot->wall_s,
               tot->frames ? tot->wall_s / tot->frames : 0.0, solve_status_name((SolveStatus)tot->worst_status));
        printf("wrote %s/steps.csv and %s/frames.csv%s\n", out_dir, out_dir, iters_csv ? " and iters.csv" : "");
    }
    /* a matrix cell's load is the runner's to report (cells.csv machine_busy) */
    if (load.busy && !getenv("MPM_MATRIX_CELL") && !secondary)
        fprintf(stderr,
                "mpmbench: warning: other processes used %.1f CPU-seconds of the run's %.1f s on %d cores while it "
                "ran on %d thread%s: its times are not valid (machine_load in run.json; on a shared machine "
                "run with fewer threads, or OMP_WAIT_POLICY=passive)\n",
                load.others_cpu_s, load.elapsed_s, load.cores, run_threads, run_threads == 1 ? "" : "s");
    /* the parts' statistics through the view op: the hierarchy of the last
     * setup (HOT Fig. 8: blocks per row per level; none when every step
     * converged at its initial guess) and the named statistics; every rank
     * takes it (a parallel library's view is collective), rank 0 writes it */
    InvView view;
    solver_view(solver, cfg->quiet || secondary ? NULL : stdout, &view);
    if (ses.has_comm && (status = add_distribution(out_dir, &ses, tot->steps))) goto done;
    if (secondary) goto done;
    if ((status = add_machine_load(out_dir, &load))) goto done;
    /* the library's own view of its last setup (PETSc's KSPView): the
     * options in effect, defaults included */
    if (view.library_view[0] && (status = add_to_run_json(out_dir, "inverse_view", json_string(view.library_view))))
        goto done;
    if (view.n_levels > 0) {
        FILE *lv = open_in(out_dir, "mg_levels.csv", &status);
        if (!lv) goto done;
        fprintf(lv, "level,nodes,blocks,blocks_per_row_avg,blocks_per_row_max\n");
        for (int l = 0; l < view.n_levels; ++l)
            fprintf(lv, "%d,%d,%lld,%.2f,%d\n", l, view.level[l].nodes, (long long)view.level[l].blocks,
                    view.level[l].blocks_per_row_avg, view.level[l].blocks_per_row_max);
        fclose(lv);
    }
    FILE *is = open_in(out_dir, "inverse_stats.csv", &status);
    if (!is) goto done;
    fprintf(is, "inverse,key,value\n");
    for (int k = 0; k < view.n_stats; ++k)
        fprintf(is, "%s,%s,%.9g\n", solver->inv->ops->name, view.stat[k].key, view.stat[k].value);
    fclose(is);
done:
    if (steps_csv) fclose(steps_csv);
    if (frames_csv) fclose(frames_csv);
    if (iters_csv) fclose(iters_csv);
    vtk_series_free(&vtk);
    run_accuracy_free(&acc);
    session_close(&ses);
    return status;
}
