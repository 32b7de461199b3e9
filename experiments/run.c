#include "experiments/run.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/step.h"
#include "experiments/paths.h"
#include "experiments/ply.h"
#include "experiments/progress.h"
#include "experiments/registry.h"
#include "solvers/mg/mg.h"
#include "solvers/solver.h"

void run_config_default(RunConfig *c)
{
    memset(c, 0, sizeof *c);
    c->eps = 1e-7;
    c->scale = 1.0;
}

static int mkdir_p(const char *path)
{
    char buf[1024];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) return mpm_error(MPM_EINPUT, "%s: path too long", path);
    for (char *s = buf + 1; *s; ++s) {
        if (*s != '/') continue;
        *s = '\0';
        if (mkdir(buf, 0755) != 0 && errno != EEXIST) return mpm_error(MPM_EINPUT, "%s: cannot create directory", buf);
        *s = '/';
    }
    if (mkdir(buf, 0755) != 0 && errno != EEXIST) return mpm_error(MPM_EINPUT, "%s: cannot create directory", buf);
    return MPM_OK;
}

static FILE *open_in(const char *dir, const char *name, int *status)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) *status = mpm_error(MPM_EINPUT, "%s: cannot write", path);
    return f;
}

typedef struct {
    FILE *iters;
    Progress *progress;
    int frame, step;
    double fraction;
} HookCtx;

static void iter_hook(void *ctx, int iter, double elapsed, double residual, double energy)
{
    HookCtx *h = ctx;
    if (h->iters)
        fprintf(h->iters, "%d,%d,%d,%.6e,%.9e,%.12e\n", h->frame, h->step, iter, elapsed, residual, energy);
    progress_update(h->progress, h->fraction, h->frame, h->step, iter, residual);
}

/* Records the exact configuration beside the tables, so every number says
 * how it was made (jansson escapes every string). */
static void write_run_json(const char *dir, const RunConfig *cfg, const Scene *sc, const SolverOptions *so,
                           int frames, int threads, int *status)
{
    json_t *opts = json_object(), *ovr = json_object();
    /* every option the solver consulted, with the value in effect (given or default) */
    for (int i = 0; i < so->n_asked; ++i) json_object_set_new(opts, so->asked[i], json_string(so->asked_value[i]));
    for (int i = 0; i < cfg->n_overrides; ++i)
        json_object_set_new(ovr, cfg->overrides[i].key, json_string(cfg->overrides[i].value));
    json_t *root = json_pack("{s:s, s:s, s:s, s:o, s:o, s:f, s:f, s:f, s:i, s:i, s:s, s:I}", "scene", sc->name,
                             "scene_path", sc->path, "solver", cfg->solver, "solver_options", opts, "overrides", ovr,
                             "eps", cfg->eps, "scale", cfg->scale, "dx", sc->dx, "frames", frames, "threads", threads,
                             "line_search", cfg->armijo ? "armijo" : "decrease", "particles",
                             (json_int_t)sc->particles.n);
    char path[1200];
    snprintf(path, sizeof path, "%s/run.json", dir);
    if (!root || json_dump_file(root, path, JSON_INDENT(2) | JSON_PRESERVE_ORDER) != 0)
        *status = mpm_error(MPM_EINPUT, "%s: cannot write", path);
    json_decref(root);
}

int run_step(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, IterHook hook, void *hook_ctx,
             SolveStats *ss, StepInfo *info)
{
    int status;
    double t0 = omp_get_wtime();
    if ((status = step_begin(sim))) return status;
    double t1 = omp_get_wtime();
    int n = sim->pb.n_nodes;
    if (n > w->cap) {
        int cap = n + n / 4 + 256;
        double *q = realloc(w->dv, sizeof(double) * 3 * (size_t)cap);
        if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: dv (%d nodes)", n);
        w->dv = q;
        w->cap = cap;
    }
    problem_initial_guess(&sim->pb, w->dv);
    if ((status = solver_solve(solver, &sim->pb, set, w->dv, ss, hook, hook_ctx))) return status;
    info->t = sim->t;
    info->dt = sim->dt;
    info->active_nodes = n;
    double t2 = omp_get_wtime();
    if ((status = step_end(sim, w->dv))) return status;
    double t3 = omp_get_wtime();
    info->wall_s = t3 - t0;
    info->begin_s = t1 - t0;
    info->end_s = t3 - t2;
    return MPM_OK;
}

static int worse(int a, int b) { return a > b ? a : b; } /* SolveStatus is ordered by severity */

int run_simulation(const RunConfig *cfg, RunSummary *sum)
{
    int status = MPM_OK;
    memset(sum, 0, sizeof *sum);
    if ((status = paths_check_output_dir("--out", cfg->out_dir)) ||
        (status = paths_check_output_dir("--particles", cfg->particles_dir)))
        return status;
    const SolverPreset *preset = registry_find(cfg->solver);
    if (!preset) return mpm_error(MPM_EINPUT, "unknown solver '%s' (see: mpmbench list solvers)", cfg->solver);
    if (!(cfg->eps > 0.0) || !isfinite(cfg->eps)) return mpm_error(MPM_EINPUT, "--eps %g: expected a positive number", cfg->eps);
    if (!(cfg->scale > 0.0) || !isfinite(cfg->scale)) return mpm_error(MPM_EINPUT, "--scale %g: expected a positive number", cfg->scale);
    SolverOptions so;
    if ((status = registry_options(preset, cfg->solver_opts, cfg->n_solver_opts, &so))) return status;
    if (cfg->threads > 0) omp_set_num_threads(cfg->threads);
    int threads = omp_get_max_threads();

    Scene scene;
    SceneLoadOptions lo = {.scale = cfg->scale, .overrides = cfg->overrides, .n_overrides = cfg->n_overrides,
                           .asset_dir = cfg->asset_dir, .max_particles = cfg->max_particles};
    if ((status = scene_load(cfg->scene, &lo, &scene))) return status;
    int frames = cfg->frames > 0 ? cfg->frames : scene.frames;

    char out_dir[1024];
    if (cfg->out_dir) snprintf(out_dir, sizeof out_dir, "%s", cfg->out_dir);
    else snprintf(out_dir, sizeof out_dir, "out/%s-%s", scene.name, preset->name);
    Solver *solver = NULL;
    Simulation sim;
    memset(&sim, 0, sizeof sim);
    FILE *steps_csv = NULL, *frames_csv = NULL, *iters_csv = NULL;
    StepWork work = {NULL, 0};
    if ((status = mkdir_p(out_dir))) goto done;
    if (cfg->particles_dir && (status = mkdir_p(cfg->particles_dir))) goto done;
    if ((status = solver_create(preset, &so, &solver))) goto done;
    if (!(steps_csv = open_in(out_dir, "steps.csv", &status))) goto done;
    if (!(frames_csv = open_in(out_dir, "frames.csv", &status))) goto done;
    if (cfg->history && !(iters_csv = open_in(out_dir, "iters.csv", &status))) goto done;
    write_run_json(out_dir, cfg, &scene, &solver->opts, frames, threads, &status);
    if (status) goto done;
    fprintf(steps_csv, "scene,solver,frame,step,t,dt,particles,active_nodes,hessian_blocks,outer_iters,linear_iters,"
                       "ls_evals,residual,status,wall_s,p2g_s,assemble_s,setup_s,solve_s,linesearch_s,g2p_s,threads\n");
    fprintf(frames_csv, "scene,solver,frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,threads\n");
    if (iters_csv) fprintf(iters_csv, "frame,step,iter,elapsed_s,residual,energy\n");

    if ((status = sim_init(&sim, &scene))) goto done;
    sum->particles = scene.particles.n;
    sum->threads = threads;
    Progress prog;
    progress_init(&prog, frames);
    SolveSettings set;
    solve_settings_default(&set);
    set.eps = cfg->eps;
    set.armijo = cfg->armijo;
    if (!cfg->quiet) {
        printf("scene %s (%zu particles, dx %.4g m), solver %s, eps %.1e, %d threads\n", scene.name, scene.particles.n,
               scene.dx, preset->name, cfg->eps, threads);
        printf("%6s %6s %8s %9s %10s %12s  %s\n", "frame", "steps", "outer", "linear", "wall_s", "max_resid", "status");
    }
    HookCtx hook = {iters_csv, &prog, 0, 0, 0.0};
    double run_t0 = omp_get_wtime();
    while (sim.frame < frames) {
        int frame = sim.frame, fsteps = 0, fstatus = SOLVE_CONVERGED;
        long fouter = 0, flinear = 0;
        double fwall = 0.0, fmaxres = 0.0;
        while (sim.frame == frame) {
            hook.frame = frame;
            hook.step = fsteps;
            hook.fraction = (frame + sim.t_in_frame / sim.frame_dt) / frames;
            SolveStats ss;
            StepInfo si;
            if ((status = run_step(&sim, solver, &set, &work, iter_hook, &hook, &ss, &si))) goto done;
            fprintf(steps_csv, "%s,%s,%d,%d,%.9g,%.9g,%zu,%d,%lld,%d,%ld,%d,%.6e,%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d\n",
                    scene.name, preset->name, frame, fsteps, si.t, si.dt, sim.p.n, si.active_nodes,
                    (long long)ss.hessian_blocks, ss.outer_iters, ss.linear_iters, ss.ls_evals, ss.residual,
                    solve_status_name(ss.status), si.wall_s, si.begin_s, ss.assemble_s, ss.setup_s, ss.solve_s,
                    ss.linesearch_s, si.end_s, threads);
            fsteps++;
            fouter += ss.outer_iters;
            flinear += ss.linear_iters;
            fwall += si.wall_s;
            if (ss.residual > fmaxres) fmaxres = ss.residual;
            fstatus = worse(fstatus, ss.status);
        }
        fprintf(frames_csv, "%s,%s,%d,%d,%ld,%ld,%.6f,%.6e,%s,%d\n", scene.name, preset->name, frame, fsteps, fouter,
                flinear, fwall, fmaxres, solve_status_name(fstatus), threads);
        fflush(steps_csv);
        fflush(frames_csv);
        progress_clear(&prog);
        if (!cfg->quiet)
            printf("%6d %6d %8ld %9ld %10.3f %12.3e  %s\n", frame, fsteps, fouter, flinear, fwall, fmaxres,
                   solve_status_name(fstatus));
        fflush(stdout);
        if (cfg->particles_dir) {
            char path[1200];
            snprintf(path, sizeof path, "%s/frame_%04d.ply", cfg->particles_dir, frame + 1);
            if ((status = ply_write_particles(path, &sim.p))) goto done;
        }
        sum->frames++;
        sum->steps += fsteps;
        sum->outer_iters += fouter;
        sum->linear_iters += flinear;
        if (fmaxres > sum->max_residual) sum->max_residual = fmaxres;
        sum->worst_status = worse(sum->worst_status, fstatus);
    }
    sum->wall_s = omp_get_wtime() - run_t0;
    if (!cfg->quiet) {
        printf("total: %d frames, %d steps, %ld outer, %ld linear iterations, %.3f s wall (%.3f s/frame), worst status %s\n",
               sum->frames, sum->steps, sum->outer_iters, sum->linear_iters, sum->wall_s,
               sum->frames ? sum->wall_s / sum->frames : 0.0, solve_status_name((SolveStatus)sum->worst_status));
        printf("wrote %s/steps.csv and %s/frames.csv%s\n", out_dir, out_dir, iters_csv ? " and iters.csv" : "");
    }
    /* multigrid solvers: the hierarchy of the last setup (HOT Fig. 8: blocks per row per level);
     * none when every step converged at its initial guess */
    MgInfo mgi;
    if (!status && mg_is_multigrid(solver->inv) && mg_get_info(solver->inv, &mgi) == MPM_OK && mgi.n_levels > 0) {
        if (!cfg->quiet) mg_print_info(&mgi, stdout);
        FILE *lv = open_in(out_dir, "mg_levels.csv", &status);
        if (!lv) goto done;
        fprintf(lv, "level,nodes,blocks,blocks_per_row_avg,blocks_per_row_max\n");
        for (int l = 0; l < mgi.n_levels; ++l)
            fprintf(lv, "%d,%d,%lld,%.2f,%d\n", l, mgi.n[l], (long long)mgi.nnzb[l], mgi.avg_row[l], mgi.max_row[l]);
        fclose(lv);
    }
done:
    if (steps_csv) fclose(steps_csv);
    if (frames_csv) fclose(frames_csv);
    if (iters_csv) fclose(iters_csv);
    free(work.dv);
    sim_free(&sim);
    solver_destroy(solver);
    scene_free(&scene);
    return status;
}
