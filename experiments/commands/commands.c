/* The commands of mpmbench (commands.h): list, run and bench here; render
 * and the matrix commands beside their code. */
#include "experiments/commands/commands.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/scene_load.h"
#include "core/threads.h"
#include "core/transfer.h"
#include "experiments/bench/bench.h"
#include "experiments/cli/run_settings.h"
#include "experiments/dist/decompose_cmd.h"
#include "experiments/io/mpi_launcher.h"
#include "experiments/matrix/matrix_cmd.h"
#include "experiments/render/render_cmd.h"
#include "experiments/run/provenance.h"
#include "experiments/driver/registry.h"
#include "experiments/run/run.h"

/* ------------------------------------------------------------------ list */

static const char *const list_what[] = {"solvers", "scenes", "definitions", NULL};

typedef struct {
    const char *solver[OPT_LIST_MAX]; /* list definitions --solver SPEC: these specs instead of the presets */
    int n_solver;
    int particles;                    /* list scenes --particles: each scene's particle count */
    double scale;                     /* at this --scale (0: 1) */
} ListArgs;

static void print_scene(const char *name, const char *desc, void *ctx)
{
    const ListArgs *a = ctx;
    if (!a->particles) {
        printf("%-16s %s\n", name, desc);
        return;
    }
    /* the count is what sampling the scene gives; a scene whose meshes are
     * not installed says so instead of failing the list */
    SceneLoadOptions opt = {.scale = a->scale > 0 ? a->scale : 1.0};
    Scene s;
    if (scene_load(name, &opt, &s) != MPM_OK) {
        printf("%-20s %12s  (%s)\n", name, "-",
               strstr(mpm_last_error(), "not found in the asset directory") ? "needs its mesh files: run --asset-dir DIR"
                                                                             : mpm_last_error());
        mpm_clear_error();
        return;
    }
    char count[32];
    snprintf(count, sizeof count, "%zu", s.particles.n);
    printf("%-20s %12s%s\n", name, count, s.n_sources ? "  (at the start; its sources add more)" : "");
    scene_free(&s);
}

static const Option list_options[] = {
    {"--solver", NULL, "SPEC", OPT_LIST, 0, 0, "a solver spec", NULL, offsetof(ListArgs, solver),
     offsetof(ListArgs, n_solver), NULL, 0,
     "with definitions: the definition of this spec (a preset, PRESET:k=v,... or OUTER:INVERSE[:k=v,...]) "
     "instead of every preset's (repeatable)"},
    {"--particles", NULL, NULL, OPT_SWITCH, 0, 0, NULL, NULL, offsetof(ListArgs, particles), 0, NULL, 0,
     "with scenes: each scene's particle count at the start instead of its description (samples every scene)"},
    {"--scale", NULL, "S", OPT_REAL, 0, 0, NULL, NULL, offsetof(ListArgs, scale), 0, NULL, OPT_MIN_OPEN,
     "with scenes --particles: the counts at this --scale (default 1, the paper's)"},
    {NULL}};

static int list_run(void *args, const char *what, int *exit_code)
{
    (void)exit_code;
    const ListArgs *a = args;
    if (a->n_solver && strcmp(what, "definitions"))
        return mpm_error(MPM_EINPUT, "list %s: --solver is for 'list definitions' only", what);
    if ((a->particles || a->scale > 0) && strcmp(what, "scenes"))
        return mpm_error(MPM_EINPUT, "list %s: --particles and --scale are for 'list scenes' only", what);
    if (a->scale > 0 && !a->particles) return mpm_error(MPM_EINPUT, "list scenes --scale: needs --particles");
    if (!strcmp(what, "solvers")) {
        registry_print(stdout);
        return MPM_OK;
    }
    if (!strcmp(what, "definitions"))
        return a->n_solver ? registry_print_spec_definitions(stdout, a->solver, a->n_solver)
                           : registry_print_definitions(stdout);
    if (a->particles) printf("%-20s %12s  (at --scale %g)\n", "scene", "particles", a->scale > 0 ? a->scale : 1.0);
    return scene_list(print_scene, (void *)a);
}

static const Command list_command = {
    .name = "list",
    .operand_choices = list_what,
    .operand_missing = "'solvers', 'scenes' or 'definitions'",
    .summary = "The registered solvers (presets, outer methods, inverse approximations and their options, "
               "strategies), the built-in scenes, or each preset's resolved definition (every option with its "
               "value in effect) and its hash, which run.json records.",
    .groups = {{list_options, 0, NULL, 0, NULL, 0}},
    .n_groups = 1,
    .args_size = sizeof(ListArgs),
    .run = list_run};

/* ------------------------------------------------------------------ run */

static void run_init(void *args) { run_config_default(args); }

static int run_run(void *args, const char *operand, int *exit_code)
{
    (void)operand, (void)exit_code;
    RunSummary sum;
    return run_simulation(args, &sum);
}

static const char *const run_required[] = {"--scene", "--solver", NULL};

static const Command run_command = {
    .name = "run",
    .required = run_required,
    .summary = "Simulates a scene with a solver: steps.csv (one row per time step), frames.csv (one per frame), "
               "run.json (the settings in effect and the provenance), inverse_stats.csv, and iters.csv with "
               "--history, in --out.",
    .notes = "Every setting is checked before the scene is sampled or the folder made. A step that does not\n"
             "converge is not an error: its status (converged, capped, stalled, timeout, failed) is in the CSV.\n"
             "In a matrix file (mpmbench matrix run) a setting is given by its key.\n",
    .groups = {{run_settings, 0, NULL, 0, "run settings", 1}},
    .n_groups = 1,
    .args_size = sizeof(RunConfig),
    .init = run_init,
    .run = run_run};

/* ------------------------------------------------------------------ bench */

typedef struct {
    RunConfig run;
    int transfer; /* index into transfer_names (core/transfer.h); -1: the scene's */
    char transfer_set[32];
} BenchArgs;

static const Option bench_options[] = {
    {"--transfer", NULL, NULL, OPT_CHOICE, 0, 0, NULL, transfer_names, offsetof(BenchArgs, transfer), 0, NULL, 0,
     "the transfer whose P2G/G2P kernels run (the same as --set transfer=...; default: the scene's)"},
    {NULL}};

/* the run settings the kernels use: the scene as `run` loads it, and the threads */
static const char *const bench_settings[] = {"--scene", "--scale", "--threads", "--set", "--asset-dir",
                                             "--max-particles", NULL};
static const char *const bench_required[] = {"--scene", NULL};

static void bench_init(void *args)
{
    BenchArgs *a = args;
    run_config_default(&a->run);
    a->transfer = -1;
}

static int bench_cmd(void *args, const char *what, int *exit_code)
{
    (void)exit_code;
    BenchArgs *a = args;
    if (a->transfer >= 0) { /* --transfer X is --set transfer=X, given last */
        snprintf(a->transfer_set, sizeof a->transfer_set, "transfer=%s", transfer_names[a->transfer]);
        if (a->run.n_set >= RUN_MAX_LIST) return mpm_error(MPM_EINPUT, "--set: more than %d values", RUN_MAX_LIST);
        a->run.set[a->run.n_set++] = a->transfer_set;
    }
    return bench_run(what, &a->run);
}

static const Command bench_command = {
    .name = "bench",
    .operand_choices = bench_operands,
    .required = bench_required,
    .summary = "Kernel throughput on a scene's first time step against the machine's limits measured in the same "
               "process (STREAM triad, FMA peak): block-CSR SpMV, matrix-free H x, Hessian assembly, the P2G and G2P "
               "transfers; a table, then one key=value line per figure.",
    .groups = {{bench_options, 0, NULL, 0, NULL}, {run_settings, 0, bench_settings, offsetof(BenchArgs, run), "run settings"}},
    .n_groups = 2,
    .args_size = sizeof(BenchArgs),
    .init = bench_init,
    .run = bench_cmd};

/* ------------------------------------------------------------------ program */

const Command *const cli_commands[] = {&list_command,       &run_command,           &bench_command,
                                       &render_command,     &matrix_run_command,    &matrix_report_command,
                                       &matrix_schema_command, &decompose_command, NULL};

const Command *cli_command(const char *name)
{
    for (int i = 0; cli_commands[i]; ++i)
        if (!strcmp(cli_commands[i]->name, name)) return cli_commands[i];
    return NULL;
}

void cli_program_usage(FILE *f)
{
    fprintf(f, "usage: mpmbench COMMAND ...    (mpmbench COMMAND --help: its options)\n"
               "       mpmbench --help | --version\n\n"
               "Implicit MPM timesteps on benchmark scenes, every solver judged by one stopping rule.\n\n"
               "commands:\n");
    for (int i = 0; cli_commands[i]; ++i) {
        fprintf(f, "  ");
        cli_synopsis(cli_commands[i], f);
        fprintf(f, "\n      ");
        cli_wrap(f, 6, 6, cli_commands[i]->summary);
    }
    fprintf(f, "\n"
               "Options take their value as --flag VALUE or --flag=VALUE; -h or --help after any command prints\n"
               "its options.\n\n"
               "exit status:\n"
               "  0  success\n"
               "  1  internal failure (out of memory, a library error)\n"
               "  2  bad input: an unknown or malformed option, a bad scene or matrix file (one line on stderr\n"
               "     naming the option or file, the field and the value)\n"
               "  3  matrix run --check: some cell failed its check (DIR/check.csv)\n\n"
               "environment:\n"
               "  OMP_NUM_THREADS    threads when --threads is not given (1-1024)\n"
               "  OMP_WAIT_POLICY    passive on a machine shared with other jobs\n"
               "  MPM_SCENE_DIR      the folder of the built-in scenes (default: share/mpmbench/scenes, found\n"
               "                     beside the program's folder or one folder up: installed or in a build tree)\n"
               "  MPM_PYTHON         the Python of `matrix report` (default: the first of python3 on PATH and\n"
               "                     /usr/bin/python3 that can import matplotlib)\n"
               "  MPM_SCRIPT_DIR     the folder of matrix_report.py (default: share/mpmbench/scripts, found\n"
               "                     as the scenes are)\n");
}

/* mpmbench GROUP --help ("matrix"): the group's commands, each with its synopsis and summary. */
static void group_usage(const char *group, FILE *f)
{
    size_t len = strlen(group);
    fprintf(f, "usage: mpmbench %s COMMAND ...    (mpmbench %s COMMAND --help: its options)\n\ncommands:\n", group,
            group);
    for (int i = 0; cli_commands[i]; ++i)
        if (!strncmp(cli_commands[i]->name, group, len) && cli_commands[i]->name[len] == ' ') {
            fprintf(f, "  ");
            cli_synopsis(cli_commands[i], f);
            fprintf(f, "\n      ");
            cli_wrap(f, 6, 6, cli_commands[i]->summary);
        }
}

/* Is word the first word of two-word commands ("matrix")? */
static int is_group(const char *word)
{
    size_t len = strlen(word);
    for (int i = 0; cli_commands[i]; ++i)
        if (!strncmp(cli_commands[i]->name, word, len) && cli_commands[i]->name[len] == ' ') return 1;
    return 0;
}

static int help_wanted(const char *a) { return !strcmp(a, "--help") || !strcmp(a, "-h") || !strcmp(a, "help"); }

/* The command argv names from argv[1] on ("matrix run" takes two words); *words how many. */
static const Command *find_command(int argc, char **argv, int *words, int *status)
{
    *status = MPM_OK;
    if (argc > 2) {
        char two[128];
        snprintf(two, sizeof two, "%s %s", argv[1], argv[2]);
        const Command *c = cli_command(two);
        if (c) {
            *words = 2;
            return c;
        }
    }
    const Command *c = cli_command(argv[1]);
    if (c) {
        *words = 1;
        return c;
    }
    /* a group of commands ("matrix"): which of its words was meant */
    char group[64], choices[256] = "";
    snprintf(group, sizeof group, "%s ", argv[1]);
    size_t len = 0;
    int n = 0, count = 0;
    for (int i = 0; cli_commands[i]; ++i) count += !strncmp(cli_commands[i]->name, group, strlen(group));
    for (int i = 0; cli_commands[i]; ++i)
        if (!strncmp(cli_commands[i]->name, group, strlen(group)) && len < sizeof choices) {
            const char *sep = n == 0 ? "" : n + 1 == count ? " or " : ", ";
            len += (size_t)snprintf(choices + len, sizeof choices - len, "%s'%s'", sep, cli_commands[i]->name + strlen(group));
            ++n;
        }
    if (n && argc > 2 && help_wanted(argv[2])) return NULL; /* mpmbench matrix --help: the group's usage */
    if (!n) *status = mpm_error(MPM_EINPUT, "unknown command '%s' (see: mpmbench --help)", argv[1]);
    else if (argc < 3) *status = mpm_error(MPM_EINPUT, "%s: expected %s (see: mpmbench %s --help)", argv[1], choices, argv[1]);
    else *status = mpm_error(MPM_EINPUT, "%s '%s': expected %s", argv[1], argv[2], choices);
    return NULL;
}

int cli_main(int argc, char **argv)
{
    under_mpi_launcher(); /* read before anything starts MPI (mpi_launcher.h) */
    if (argc < 2) {
        cli_program_usage(stderr);
        return CLI_EXIT_INPUT;
    }
    if (help_wanted(argv[1]) && argc == 2) {
        cli_program_usage(stdout);
        return CLI_EXIT_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        char v[256];
        provenance_version(v, sizeof v);
        printf("%s\n", v);
        return CLI_EXIT_OK;
    }
    int help_first = help_wanted(argv[1]); /* mpmbench help COMMAND */
    if (help_first && argc == 3 && is_group(argv[2])) {
        group_usage(argv[2], stdout); /* mpmbench help matrix */
        return CLI_EXIT_OK;
    }
    int first = help_first ? 2 : 1, words = 0, exit_code = CLI_EXIT_OK;
    int st = threads_check_env(); /* before OpenMP reads it at the first parallel region */
    const Command *cmd = st ? NULL : find_command(argc - first + 1, argv + first - 1, &words, &st);
    if (cmd && help_first) {
        cli_usage(cmd, stdout);
        return CLI_EXIT_OK;
    }
    if (cmd) {
        void *args = cmd->args_size ? calloc(1, cmd->args_size) : NULL;
        const char *operand;
        int help = 0;
        if (cmd->args_size && !args) st = mpm_error(MPM_EINTERNAL, "out of memory");
        else st = cli_parse(cmd, argc, argv, first + words, args, &operand, &help);
        if (!st && help) cli_usage(cmd, stdout);
        else if (!st) st = cmd->run(args, operand, &exit_code);
        free(args);
    } else if (!st && argc > first + 1 && help_wanted(argv[first + 1])) {
        group_usage(argv[first], stdout); /* mpmbench matrix --help */
        return CLI_EXIT_OK;
    }
    if (st) {
        fprintf(stderr, "mpmbench: error: %s\n", mpm_last_error());
        return st == MPM_EINPUT ? CLI_EXIT_INPUT : CLI_EXIT_INTERNAL;
    }
    return exit_code;
}
