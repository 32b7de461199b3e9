#include "experiments/matrix/matrix_cmd.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "experiments/matrix/matrix_run.h"

#ifndef MPM_SOURCE_DIR
#define MPM_SOURCE_DIR "."
#endif

#define MAX_ONLY 64

static int parse_count(const char *flag, const char *s, int *out)
{
    char *end = NULL;
    long v = strtol(s, &end, 10);
    if (!s[0] || *end || v < 1 || v > 1024) return mpm_error(MPM_EINPUT, "%s '%s': expected an integer 1..1024", flag, s);
    *out = (int)v;
    return MPM_OK;
}

static int cmd_run(int argc, char **argv)
{
    if (argc < 4 || argv[3][0] == '-') return mpm_error(MPM_EINPUT, "matrix run: expected a matrix file (see: mpmbench --help)");
    static const char *only[MAX_ONLY];
    MatrixRunOptions o = {NULL, only, 0, 0, 1, NULL, 0, 0};
    for (int i = 4; i < argc; ++i) {
        const char *f = argv[i];
        int has_val = i + 1 < argc;
        if (!strcmp(f, "--dry-run")) {
            o.dry_run = 1;
            continue;
        }
        if (!strcmp(f, "--check")) {
            o.check = 1;
            continue;
        }
        if (strcmp(f, "--out") && strcmp(f, "--only") && strcmp(f, "--jobs") && strcmp(f, "--asset-dir") &&
            strcmp(f, "--threads"))
            return mpm_error(MPM_EINPUT, "matrix run: unknown option '%s' (see: mpmbench --help)", f);
        if (!has_val) return mpm_error(MPM_EINPUT, "%s: missing value", f);
        const char *v = argv[++i];
        int st = MPM_OK;
        if (!strcmp(f, "--out")) o.out_dir = v;
        else if (!strcmp(f, "--asset-dir")) o.asset_dir = v;
        else if (!strcmp(f, "--jobs")) st = parse_count(f, v, &o.jobs);
        else if (!strcmp(f, "--threads")) st = parse_count(f, v, &o.threads);
        else if (o.n_only >= MAX_ONLY) st = mpm_error(MPM_EINPUT, "--only: more than %d patterns", MAX_ONLY);
        else only[o.n_only++] = v;
        if (st) return st;
    }
    return matrix_run(argv[3], &o);
}

/* Replaces this process by the report script (its exit status and messages are the command's). */
static int cmd_report(int argc, char **argv)
{
    if (argc < 4 || argv[3][0] == '-') return mpm_error(MPM_EINPUT, "matrix report: expected a result directory (see: mpmbench --help)");
    const char *python = getenv("MPM_PYTHON");
    if (!python || !python[0]) python = "/usr/bin/python3";
    const char *dir = getenv("MPM_SCRIPT_DIR");
    char script[1200];
    snprintf(script, sizeof script, "%s/matrix_report.py", dir && dir[0] ? dir : MPM_SOURCE_DIR "/scripts");
    struct stat st;
    if (stat(script, &st) != 0) return mpm_error(MPM_EINPUT, "matrix report: %s not found (set MPM_SCRIPT_DIR)", script);
    if (access(python, X_OK) != 0)
        return mpm_error(MPM_EINPUT, "matrix report: no %s (install python3 and python3-matplotlib: scripts/setup.sh)", python);
    char **args = calloc((size_t)argc, sizeof *args);
    if (!args) return mpm_error(MPM_EINTERNAL, "out of memory");
    args[0] = (char *)python;
    args[1] = script;
    for (int i = 3; i < argc; ++i) args[i - 1] = argv[i];
    fflush(stdout);
    fflush(stderr);
    execv(python, args);
    free(args);
    return mpm_error(MPM_EINTERNAL, "matrix report: cannot run %s", python);
}

int matrix_command(int argc, char **argv)
{
    if (argc < 3) return mpm_error(MPM_EINPUT, "matrix: expected 'run' or 'report' (see: mpmbench --help)");
    if (!strcmp(argv[2], "run")) return cmd_run(argc, argv);
    if (!strcmp(argv[2], "report")) return cmd_report(argc, argv);
    return mpm_error(MPM_EINPUT, "matrix '%s': expected 'run' or 'report'", argv[2]);
}
