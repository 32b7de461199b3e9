/* `mpmbench decompose` (decompose_cmd.h). */
#include "experiments/dist/decompose_cmd.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist/decomposition.h"
#include "core/dist/halo_census.h"
#include "core/error.h"
#include "core/step.h"
#include "experiments/cli/run_settings.h"
#include "experiments/io/checkpoint.h"
#include "experiments/run/run.h"

#define MAX_RANK_COUNTS 32
#define MAX_RANKS 4096

typedef struct {
    RunConfig run;
    const char *ranks; /* comma-separated rank counts */
    const char *out;   /* CSV file; NULL: standard output */
} DecomposeArgs;

/* --ranks: up to MAX_RANK_COUNTS integers in [1, MAX_RANKS] separated by commas. */
static int parse_ranks(const char *text, int *ranks, int *n)
{
    *n = 0;
    const char *c = text;
    while (*c) {
        char *end;
        long r = strtol(c, &end, 10);
        if (end == c || (*end && *end != ',') || r < 1 || r > MAX_RANKS || *n == MAX_RANK_COUNTS)
            return mpm_error(MPM_EINPUT, "--ranks '%s': expected at most %d rank counts in 1..%d separated by commas",
                             text, MAX_RANK_COUNTS, MAX_RANKS);
        ranks[(*n)++] = (int)r;
        c = *end ? end + 1 : end;
        if (*end && !*c) return mpm_error(MPM_EINPUT, "--ranks '%s': a comma at the end", text);
    }
    if (!*n) return mpm_error(MPM_EINPUT, "--ranks '': expected rank counts");
    return MPM_OK;
}

static int check_ranks(const char *text)
{
    int r[MAX_RANK_COUNTS], n;
    return parse_ranks(text, r, &n);
}

static const Option decompose_options[] = {
    {"--ranks", NULL, "R1,R2,...", OPT_TEXT, 0, 0, "rank counts", NULL, offsetof(DecomposeArgs, ranks), 0,
     check_ranks, 0, "the rank counts to split the grid for (default 1,2,4,8,16)"},
    {"--out", NULL, "FILE.csv", OPT_TEXT, 0, 0, "a file name", NULL, offsetof(DecomposeArgs, out), 0, NULL, 0,
     "the table (default: standard output)"},
    {NULL}};

static const char *const decompose_settings[] = {"--scene", "--scale",         "--set",  "--asset-dir",
                                                 "--threads", "--max-particles", "--from", NULL};
static const char *const decompose_required[] = {"--scene", NULL};

static void decompose_init(void *args)
{
    DecomposeArgs *a = args;
    run_config_default(&a->run);
    a->ranks = "1,2,4,8,16";
}

static int write_rows(FILE *f, const DecomposeArgs *a, const Simulation *sim, int ranks)
{
    Decomposition d;
    int status = decomposition_balance(sim->st.base, sim->st.n, ranks, &d);
    if (status) return status;
    RankCensus *c = malloc(sizeof(RankCensus) * (size_t)ranks);
    if (!c) status = mpm_error(MPM_EINTERNAL, "out of memory: census of %d ranks", ranks);
    else status = halo_census(&d, &sim->grid, &sim->st, c);
    for (int r = 0; !status && r < ranks; ++r)
        fprintf(f, "%s,%.17g,%d,%zu,%d,%d,%d,%zu,%d,%d,%d,%d,%d,%d,%ld,%ld\n", sim->scene->name, a->run.scale,
                sim->frame, sim->st.n, sim->grid.n, ranks, r, c[r].particles, c[r].owned_nodes, c[r].touched_nodes,
                c[r].ghost_nodes, c[r].owned_untouched, c[r].send_ranks, c[r].receive_ranks, c[r].owned_row_blocks,
                c[r].ghost_row_blocks);
    free(c);
    decomposition_free(&d);
    return status;
}

static int decompose_run(void *args, const char *operand, int *exit_code)
{
    (void)operand, (void)exit_code;
    DecomposeArgs *a = args;
    int ranks[MAX_RANK_COUNTS], n_ranks;
    int status = parse_ranks(a->ranks, ranks, &n_ranks);
    if (status) return status;
    const char *solver_opts[RUN_MAX_LIST + 1];
    SessionConfig sc;
    run_session_config(&a->run, &sc, solver_opts);
    sc.solver = NULL; /* the grid, not a solve */
    Session ses;
    if ((status = session_open(&sc, &ses))) return status;
    uint64_t fingerprint;
    if (a->run.from && ((status = run_scene_fingerprint(&a->run, &ses.scene, &fingerprint)) ||
                        (status = checkpoint_read(a->run.from, &ses.sim, fingerprint))))
        goto done;
    if ((status = step_begin(&ses.sim))) goto done;
    FILE *f = a->out ? fopen(a->out, "w") : stdout;
    if (!f) {
        status = mpm_error(MPM_EINPUT, "--out %s: cannot write the file", a->out);
        goto done;
    }
    fprintf(f, "scene,scale,frame,particles,nodes,ranks,rank,owned_particles,owned_nodes,touched_nodes,ghost_nodes,"
               "owned_untouched,send_ranks,receive_ranks,owned_row_blocks,ghost_row_blocks\n");
    for (int i = 0; !status && i < n_ranks; ++i) status = write_rows(f, a, &ses.sim, ranks[i]);
    if (f != stdout && fclose(f) && !status) status = mpm_error(MPM_EINPUT, "--out %s: cannot write the file", a->out);
done:
    session_close(&ses);
    return status;
}

const Command decompose_command = {
    .name = "decompose",
    .required = decompose_required,
    .summary = "Splits a scene's grid over R ranks (4x4x4 node blocks along a Morton curve, cut by particle "
               "count) and counts, per rank, the particles and nodes it owns, its ghost nodes (the halo every "
               "exchange carries), the ranks it talks to and the Hessian blocks it adds to others' rows: one CSV "
               "row per rank, counted on one process, nothing timed.",
    .notes = "The state counted is the scene's first step, or the first step from a checkpoint (--from).\n"
             "More ranks than node blocks holding particles is an error.\n",
    .groups = {{decompose_options, 0, NULL, 0, NULL},
               {run_settings, 0, decompose_settings, offsetof(DecomposeArgs, run), "run settings"}},
    .n_groups = 2,
    .args_size = sizeof(DecomposeArgs),
    .init = decompose_init,
    .run = decompose_run};
