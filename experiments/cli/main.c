/* mpmbench command line. Exit status: 0 success, 2 bad usage or input (one
 * line on stderr), 1 internal failure. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/threads.h"
#include "experiments/bench/bench.h"
#include "experiments/matrix/matrix_cmd.h"
#include "experiments/run/registry.h"
#include "experiments/render/render_cmd.h"
#include "experiments/run/run.h"

#define MAX_LIST 64

static void usage(FILE *f)
{
    fprintf(f,
            "usage:\n"
            "  mpmbench list solvers|scenes\n"
            "  mpmbench run --scene NAME|FILE --solver NAME|OUTER:INVERSE[:key=value,...] [--frames N] [--eps E]\n"
            "               [--scale S] [--threads T] [--out DIR] [--set key=value ...] [--solver-opt key=value ...]\n"
            "               [--history] [--particles DIR] [--vtk DIR [--vtk-grid]] [--asset-dir DIR] [--armijo] [--quiet]\n"
            "               [--max-particles N]\n"
            "               [--max-outer N] [--max-linear N] [--max-step-seconds S] [--max-run-seconds S]\n"
            "               [--on-failure stop|continue] [--error-ref SOLVER[:eps]|auto[:eps]] [--trajectory]\n"
            "               [--dt-from RUN_DIR] [--trajectory-ref RUN_DIR]\n"
            "  mpmbench bench spmv|assemble|hessvec|p2g|g2p|all --scene NAME [--transfer apic|mls] [--scale S] [--threads T]\n"
            "               [--set key=value ...]\n"
            "  mpmbench render --scene NAME|FILE [--frame N] [--out FILE.png] [--solver NAME] [--scale S] [--set key=value ...]\n"
            "               [--view front|side|top|iso] [--color material|speed] [--width W] [--height H] [--asset-dir DIR] [--threads T]\n"
            "  mpmbench matrix run FILE [--out DIR] [--only GLOB ...] [--dry-run] [--jobs N] [--threads T] [--asset-dir DIR]\n"
            "               [--check]  (under mpirun -np K: the cells spread over K ranks; --check: pass/fail\n"
            "               per cell into DIR/check.csv, exit 1 when a cell failed)\n"
            "  mpmbench matrix report DIR     (DIR/report.md and PNGs from a matrix run)\n");
}

static void print_scene(const char *name, const char *desc, void *ctx)
{
    (void)ctx;
    printf("%-16s %s\n", name, desc);
}

static int parse_double(const char *flag, const char *s, double *out)
{
    char *end = NULL;
    double v = strtod(s, &end);
    if (!s[0] || *end) return mpm_error(MPM_EINPUT, "%s '%s': expected a number", flag, s);
    *out = v;
    return MPM_OK;
}

static int parse_int(const char *flag, const char *s, int *out)
{
    char *end = NULL;
    long v = strtol(s, &end, 10);
    if (!s[0] || *end || v < -1000000000L || v > 1000000000L)
        return mpm_error(MPM_EINPUT, "%s '%s': expected an integer", flag, s);
    *out = (int)v;
    return MPM_OK;
}

static int split_set(const char *arg, SceneOverride *ov, char *storage, size_t cap)
{
    const char *eq = strchr(arg, '=');
    if (!eq || eq == arg) return mpm_error(MPM_EINPUT, "--set '%s': expected key=value", arg);
    if (strlen(arg) + 1 > cap) return mpm_error(MPM_EINPUT, "--set '%s': too long", arg);
    strcpy(storage, arg);
    storage[eq - arg] = '\0';
    ov->key = storage;
    ov->value = storage + (eq - arg) + 1;
    return MPM_OK;
}

typedef struct {
    RunConfig run;
    SceneOverride overrides[MAX_LIST];
    char override_text[MAX_LIST][256];
    const char *solver_opts[MAX_LIST];
    const char *what; /* bench target */
} Args;

static int parse_args(int argc, char **argv, int first, Args *a)
{
    RunConfig *c = &a->run;
    int st;
    for (int i = first; i < argc; ++i) {
        const char *f = argv[i];
        int has_val = i + 1 < argc;
        const char *val = has_val ? argv[i + 1] : NULL;
#define NEED_VAL()                                                               \
    do {                                                                         \
        if (!has_val) return mpm_error(MPM_EINPUT, "%s: missing value", f);      \
        ++i;                                                                     \
    } while (0)
        if (!strcmp(f, "--scene")) { NEED_VAL(); c->scene = val; }
        else if (!strcmp(f, "--solver")) { NEED_VAL(); c->solver = val; }
        else if (!strcmp(f, "--frames")) {
            NEED_VAL();
            if ((st = parse_int(f, val, &c->frames))) return st;
            if (c->frames < 1) return mpm_error(MPM_EINPUT, "--frames %d: expected >= 1", c->frames);
        } else if (!strcmp(f, "--eps")) { NEED_VAL(); if ((st = parse_double(f, val, &c->eps))) return st; }
        else if (!strcmp(f, "--max-outer") || !strcmp(f, "--max-linear")) {
            NEED_VAL();
            int *dst = !strcmp(f, "--max-outer") ? &c->max_outer : &c->max_linear;
            if ((st = parse_int(f, val, dst))) return st;
            if (*dst < 1) return mpm_error(MPM_EINPUT, "%s %s: expected an integer >= 1", f, val);
        } else if (!strcmp(f, "--max-step-seconds") || !strcmp(f, "--max-run-seconds")) {
            NEED_VAL();
            double *dst = !strcmp(f, "--max-step-seconds") ? &c->max_step_s : &c->max_run_s;
            if ((st = parse_double(f, val, dst))) return st;
            if (!(*dst > 0.0) || *dst > 1e9) return mpm_error(MPM_EINPUT, "%s %s: expected seconds in (0, 1e9]", f, val);
        } else if (!strcmp(f, "--on-failure")) {
            NEED_VAL();
            if (!strcmp(val, "stop")) c->on_failure = RUN_STOP;
            else if (!strcmp(val, "continue")) c->on_failure = RUN_CONTINUE;
            else return mpm_error(MPM_EINPUT, "--on-failure '%s': expected stop or continue", val);
        }
        else if (!strcmp(f, "--scale")) { NEED_VAL(); if ((st = parse_double(f, val, &c->scale))) return st; }
        else if (!strcmp(f, "--threads")) {
            NEED_VAL();
            if ((st = threads_parse(f, val, &c->threads))) return st;
        } else if (!strcmp(f, "--max-particles")) {
            NEED_VAL();
            if ((st = scene_parse_particle_budget(f, val, &c->max_particles))) return st;
        } else if (!strcmp(f, "--out")) { NEED_VAL(); c->out_dir = val; }
        else if (!strcmp(f, "--particles")) { NEED_VAL(); c->particles_dir = val; }
        else if (!strcmp(f, "--vtk")) { NEED_VAL(); c->vtk_dir = val; }
        else if (!strcmp(f, "--vtk-grid")) c->vtk_grid = 1;
        else if (!strcmp(f, "--error-ref")) { NEED_VAL(); c->error_ref = val; }
        else if (!strcmp(f, "--dt-from")) { NEED_VAL(); c->dt_from = val; }
        else if (!strcmp(f, "--trajectory-ref")) { NEED_VAL(); c->trajectory_ref = val; }
        else if (!strcmp(f, "--trajectory")) c->trajectory = 1;
        else if (!strcmp(f, "--asset-dir")) { NEED_VAL(); c->asset_dir = val; }
        else if (!strcmp(f, "--set")) {
            NEED_VAL();
            if (c->n_overrides >= MAX_LIST) return mpm_error(MPM_EINPUT, "too many --set options");
            if ((st = split_set(val, &a->overrides[c->n_overrides], a->override_text[c->n_overrides], 256))) return st;
            c->n_overrides++;
        } else if (!strcmp(f, "--solver-opt")) {
            NEED_VAL();
            if (c->n_solver_opts >= MAX_LIST) return mpm_error(MPM_EINPUT, "too many --solver-opt options");
            a->solver_opts[c->n_solver_opts++] = val;
        } else if (!strcmp(f, "--history")) c->history = 1;
        else if (!strcmp(f, "--armijo")) c->armijo = 1;
        else if (!strcmp(f, "--quiet")) c->quiet = 1;
        else return mpm_error(MPM_EINPUT, "unknown option '%s' (see: mpmbench --help)", f);
#undef NEED_VAL
    }
    c->overrides = a->overrides;
    c->solver_opts = a->solver_opts;
    return MPM_OK;
}

static int cmd_list(int argc, char **argv)
{
    if (argc < 3) return mpm_error(MPM_EINPUT, "list: expected 'solvers' or 'scenes'");
    if (!strcmp(argv[2], "solvers")) {
        registry_print(stdout);
        return MPM_OK;
    }
    if (!strcmp(argv[2], "scenes")) return scene_list(print_scene, NULL);
    return mpm_error(MPM_EINPUT, "list '%s': expected 'solvers' or 'scenes'", argv[2]);
}

static int cmd_run(int argc, char **argv)
{
    static Args a;
    run_config_default(&a.run);
    int st = parse_args(argc, argv, 2, &a);
    if (st) return st;
    RunSummary sum;
    st = run_simulation(&a.run, &sum);
    if (st) return st;
    return MPM_OK;
}

static int cmd_bench(int argc, char **argv)
{
    static Args a;
    static const char *const targets[] = {"spmv", "assemble", "hessvec", "p2g", "g2p", "all", NULL};
    run_config_default(&a.run);
    if (argc < 3) return mpm_error(MPM_EINPUT, "bench: expected spmv, assemble, hessvec, p2g, g2p or all");
    const char *what = argv[2];
    int known = 0;
    for (int k = 0; targets[k]; ++k) known |= !strcmp(what, targets[k]);
    if (!known) return mpm_error(MPM_EINPUT, "bench '%s': expected spmv, assemble, hessvec, p2g, g2p or all", what);
    /* --transfer apic|mls is --set transfer=...; the rest are run's options */
    static char *rest[512];
    static char transfer_set[64];
    int nrest = 0;
    const char *transfer = NULL;
    for (int i = 3; i < argc && nrest < 510; ++i) {
        if (!strcmp(argv[i], "--transfer")) {
            if (i + 1 >= argc) return mpm_error(MPM_EINPUT, "--transfer: missing value");
            transfer = argv[++i];
            if (strcmp(transfer, "apic") && strcmp(transfer, "mls"))
                return mpm_error(MPM_EINPUT, "--transfer '%s': expected apic or mls", transfer);
        } else {
            rest[nrest++] = argv[i];
        }
    }
    if (transfer) {
        snprintf(transfer_set, sizeof transfer_set, "transfer=%s", transfer);
        rest[nrest++] = "--set";
        rest[nrest++] = transfer_set;
    }
    int st = parse_args(nrest, rest, 0, &a);
    if (st) return st;
    if (!a.run.scene) return mpm_error(MPM_EINPUT, "bench: --scene is required");
    return bench_run(what, &a.run);
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? MPM_EINPUT : 0;
    }
    int st = threads_check_env(); /* before OpenMP reads it at the first parallel region */
    if (st) {
    } else if (!strcmp(argv[1], "list")) st = cmd_list(argc, argv);
    else if (!strcmp(argv[1], "run")) st = cmd_run(argc, argv);
    else if (!strcmp(argv[1], "bench")) st = cmd_bench(argc, argv);
    else if (!strcmp(argv[1], "render")) st = render_command(argc, argv);
    else if (!strcmp(argv[1], "matrix")) st = matrix_command(argc, argv);
    else st = mpm_error(MPM_EINPUT, "unknown command '%s' (see: mpmbench --help)", argv[1]);
    if (st) {
        fprintf(stderr, "mpmbench: error: %s\n", mpm_last_error());
        return st == MPM_EINPUT ? 2 : 1;
    }
    return 0;
}
