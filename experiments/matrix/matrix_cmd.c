/* `mpmbench matrix run|report` (matrix_cmd.h). */
#include "experiments/matrix/matrix_cmd.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "core/scene/data_dir.h"
#include "core/threads.h"
#include "experiments/matrix/matrix_resume.h"
#include "experiments/matrix/matrix_run.h"
#include "experiments/matrix/matrix_schema.h"

#define O(field) offsetof(MatrixRunOptions, field)

static const Option matrix_run_options[] = {
    {"--out", NULL, "DIR", OPT_TEXT, 0, 0, "a directory name", NULL, O(out_dir), 0, NULL, 0,
     "results folder: DIR/cells.csv, DIR/cells/ID/ (default out/matrix-NAME); cells already in DIR/cells.csv are "
     "not run again"},
    {"--only", NULL, "GLOB", OPT_LIST, 0, 0, "a glob", NULL, O(only), O(n_only), NULL, 0,
     "run only the cells whose id or scene/solver matches (repeatable; their reference runs too)"},
    {"--dry-run", NULL, NULL, OPT_SWITCH, 0, 0, NULL, NULL, O(dry_run), 0, NULL, 0,
     "check the matrix and list its cells with their ids, done or todo; write nothing"},
    {"--jobs", NULL, "N", OPT_INT, 1, 1024, NULL, NULL, O(jobs), 0, NULL, 0,
     "cells at a time per process (default 1: a cell uses its own threads)"},
    {"--threads", NULL, "T", OPT_INT, 1, MPM_MAX_THREADS, "an integer number of threads", NULL, O(threads), 0, NULL, 0,
     "threads of every cell, replacing defaults.threads (refused when the matrix has a threads axis)"},
    {"--asset-dir", NULL, "DIR", OPT_TEXT, 0, 0, "a directory name", NULL, O(asset_dir), 0, NULL, 0,
     "where the scenes' mesh files are, relative to the working directory (replaces defaults.asset_dir)"},
    {"--checkpoint-every-s", NULL, "S", OPT_REAL, 0, 1e9, "seconds", NULL, O(checkpoint_every_s), 0, NULL,
     OPT_MIN_OPEN,
     "seconds between the resume checkpoints of a reference run that writes checkpoints (sample_frames; default "
     OPT_SPELLED(MATRIX_RESUME_EVERY_S) "): stopped midway, it goes on from the newest at the next matrix run"},
    {"--check", NULL, NULL, OPT_SWITCH, 0, 0, NULL, NULL, O(check), 0, NULL, 0,
     "afterwards judge every cell (stable, converged, no energy rise): DIR/check.csv; exit 3 when one failed"},
    {NULL}};

static void matrix_run_init(void *args)
{
    MatrixRunOptions *o = args;
    o->jobs = 1;
}

/* FILE as given, or when it names no file and is a bare name (no '/', no
 * ".json"), the built-in matrix of that name in share/mpmbench/matrices
 * (found as the scenes are, core/scene/data_dir.h), so an installed program
 * runs `matrix run smoke` from any folder. */
static const char *matrix_file_path(const char *file, char *buf, size_t cap)
{
    size_t n = strlen(file);
    struct stat st;
    if (strchr(file, '/') || (n >= 5 && !strcmp(file + n - 5, ".json")) || stat(file, &st) == 0) return file;
    char dir[4096];
    if (data_dir_find("matrices", NULL, dir, sizeof dir)) return file;
    if (snprintf(buf, cap, "%s/%s.json", dir, file) >= (int)cap || stat(buf, &st) != 0) return file;
    return buf;
}

static int matrix_run_cmd(void *args, const char *file, int *exit_code)
{
    int failed = 0;
    char builtin[4200];
    int st = matrix_run(matrix_file_path(file, builtin, sizeof builtin), args, &failed);
    if (!st && failed) *exit_code = CLI_EXIT_CHECK_FAILED;
    return st;
}

const Command matrix_run_command = {
    .name = "matrix run",
    .operand = "FILE",
    .operand_missing = "a matrix file",
    .summary = "Runs every cell of an experiment matrix (experiments/matrices/*.json) in a child process and appends "
               "one row per finished cell to DIR/cells.csv; a rerun resumes.",
    .notes = "FILE may be the name of a built-in matrix (share/mpmbench/matrices/NAME.json beside the program).\n"
             "Under mpirun -np K the cells spread over the K ranks. Exit status 0 when the matrix ran, whatever the\n"
             "cells' statuses (they are in cells.csv); 2 for a bad matrix file or option; with --check, 3 when a\n"
             "cell failed its check.\n",
    .groups = {{matrix_run_options, 0, NULL, 0, NULL}},
    .n_groups = 1,
    .args_size = sizeof(MatrixRunOptions),
    .init = matrix_run_init,
    .run = matrix_run_cmd};

/* The program to run: a path as given, a name looked up on PATH. */
static int find_program(const char *name, char *out, size_t n)
{
    if (strchr(name, '/')) {
        snprintf(out, n, "%s", name);
        return access(out, X_OK) == 0;
    }
    const char *path = getenv("PATH");
    if (!path) path = "/usr/local/bin:/usr/bin:/bin";
    while (*path) {
        size_t len = strcspn(path, ":");
        snprintf(out, n, "%.*s/%s", (int)len, len ? path : ".", name);
        struct stat st;
        if (stat(out, &st) == 0 && S_ISREG(st.st_mode) && access(out, X_OK) == 0) return 1;
        path += len + (path[len] == ':');
    }
    return 0;
}

/* 1 when `program -c "import matplotlib"` exits 0 (its output discarded). */
static int imports_matplotlib(const char *program)
{
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0) return 0;
    if (pid == 0) {
        int null = open("/dev/null", O_RDWR);
        if (null >= 0) {
            dup2(null, STDIN_FILENO);
            dup2(null, STDOUT_FILENO);
            dup2(null, STDERR_FILENO);
        }
        char *argv[] = {(char *)program, "-c", "import matplotlib", NULL};
        execv(program, argv);
        _exit(127);
    }
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return 0;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/* Replaces this process by the report script run with the first Python that can import
 * matplotlib of: MPM_PYTHON (a name looked up on PATH or a path), the python3 on PATH, the
 * system's /usr/bin/python3 (the script's exit status and messages are the command's). None: one
 * line naming what was tried, status 2. */
static int matrix_report_cmd(void *args, const char *dir_arg, int *exit_code)
{
    (void)args, (void)exit_code;
    char dir[4096], script[4200];
    data_dir_find("scripts", "MPM_SCRIPT_DIR", dir, sizeof dir); /* beside the binary, or $MPM_SCRIPT_DIR */
    snprintf(script, sizeof script, "%s/matrix_report.py", dir);
    struct stat st;
    if (stat(script, &st) != 0) return mpm_error(MPM_EINPUT, "matrix report: %s not found (set MPM_SCRIPT_DIR)", script);
    const char *env = getenv("MPM_PYTHON");
    const char *candidates[] = {env && env[0] ? env : NULL, "python3", "/usr/bin/python3"};
    char program[4096], tried[3][4096 + 64], found[3][4096];
    int n_tried = 0;
    for (int i = 0; i < 3; i++) {
        if (!candidates[i]) continue;
        int exists = find_program(candidates[i], program, sizeof program);
        int seen = 0;
        for (int k = 0; k < n_tried; k++) seen |= exists && strcmp(found[k], program) == 0;
        if (seen) continue;
        snprintf(found[n_tried], sizeof found[n_tried], "%s", exists ? program : "");
        const char *what = i == 0 ? "MPM_PYTHON=" : "";
        if (!exists)
            snprintf(tried[n_tried++], sizeof tried[0], "%s%s (%s)", what, candidates[i],
                     strchr(candidates[i], '/') ? "not found" : "not on PATH");
        else if (!imports_matplotlib(program))
            snprintf(tried[n_tried++], sizeof tried[0], "%s%s (no matplotlib)", what,
                     strcmp(candidates[i], program) ? program : candidates[i]);
        else {
            if (i > 0 && env && env[0]) fprintf(stderr, "mpmbench: note: %s; using %s\n", tried[0], program);
            char *argv[4] = {program, script, (char *)dir_arg, NULL};
            fflush(stdout);
            fflush(stderr);
            execv(program, argv);
            return mpm_error(MPM_EINTERNAL, "matrix report: cannot run %s", program);
        }
    }
    char list[3 * (4096 + 64) + 16] = "";
    for (int k = 0; k < n_tried; k++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", tried[k]);
    return mpm_error(MPM_EINPUT,
                     "matrix report: no Python that can import matplotlib (tried %s); install it (Debian: apt-get "
                     "install python3-matplotlib; or pip install matplotlib) or set MPM_PYTHON to a python3 that has it",
                     list);
}

const Command matrix_report_command = {
    .name = "matrix report",
    .operand = "DIR",
    .operand_missing = "a result directory",
    .summary = "Writes DIR/report.md with its tables and figures from a matrix run's results.",
    .notes = "Runs matrix_report.py (share/mpmbench/scripts, found from the program's folder) with the first Python\n"
             "that can import matplotlib of MPM_PYTHON (a program name or path), the python3 on PATH (a virtual\n"
             "environment with matplotlib works) and /usr/bin/python3; MPM_SCRIPT_DIR replaces the scripts folder.\n"
             "Exit status 0; 2 for a folder without cells.csv or matrix.json, or when no Python with matplotlib is\n"
             "found (one line naming what was tried).\n",
    .run = matrix_report_cmd};

static int matrix_schema_cmd(void *args, const char *operand, int *exit_code)
{
    (void)args, (void)operand, (void)exit_code;
    return matrix_schema_write(stdout);
}

const Command matrix_schema_command = {
    .name = "matrix schema",
    .summary = "Prints the JSON Schema of matrix files (docs/matrix.schema.json), generated from the run settings "
               "table and the matrix file's own keys.",
    .notes = "scripts/check_matrices.py validates files against the committed copy, which a test keeps equal\n"
             "to this output: after changing a run setting or a matrix key, run\n"
             "  mpmbench matrix schema > docs/matrix.schema.json\n",
    .run = matrix_schema_cmd};
