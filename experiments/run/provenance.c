#include "experiments/run/provenance.h"

#include <dlfcn.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include "experiments/driver/registry.h"
#include "mpm_build_info.h" /* generated at build time: MPM_GIT_COMMIT, MPM_GIT_DIRTY */

#ifndef MPM_BUILD_FLAGS
#define MPM_BUILD_FLAGS "unknown"
#endif
#ifndef MPM_COMPILER
#define MPM_COMPILER "unknown"
#endif
#ifndef MPM_BUILD_TYPE
#define MPM_BUILD_TYPE "unknown"
#endif
#ifndef MPM_VERSION
#define MPM_VERSION "unknown"
#endif

void provenance_version(char *out, size_t n)
{
    snprintf(out, n, "mpmbench %s (git %s%s)", MPM_VERSION, MPM_GIT_COMMIT, MPM_GIT_DIRTY > 0 ? ", modified" : "");
}

/* CPU model and physical core count from /proc/cpuinfo (Linux). */
static void cpu_info(char *model, size_t n, int *physical)
{
    snprintf(model, n, "unknown");
    *physical = 0;
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f) return;
    char line[512];
    int have_model = 0, phys = -1;
    int seen[1024][2], n_seen = 0;
    while (fgets(line, sizeof line, f)) {
        char *colon = strchr(line, ':');
        if (!colon) continue;
        char *val = colon + 1;
        while (*val == ' ') ++val;
        val[strcspn(val, "\n")] = '\0';
        if (!have_model && !strncmp(line, "model name", 10)) {
            snprintf(model, n, "%s", val);
            have_model = 1;
        } else if (!strncmp(line, "physical id", 11)) {
            phys = atoi(val);
        } else if (!strncmp(line, "core id", 7)) {
            int core = atoi(val), dup = 0;
            for (int i = 0; i < n_seen && !dup; ++i) dup = seen[i][0] == phys && seen[i][1] == core;
            if (!dup && n_seen < 1024) {
                seen[n_seen][0] = phys;
                seen[n_seen][1] = core;
                n_seen++;
            }
        }
    }
    fclose(f);
    *physical = n_seen;
}

/* The first line of a command's output ("" on failure). */
static void command_line(const char *cmd, char *out, size_t n)
{
    out[0] = '\0';
    FILE *p = popen(cmd, "r");
    if (!p) return;
    if (!fgets(out, (int)n, p)) out[0] = '\0';
    out[strcspn(out, "\n")] = '\0';
    pclose(p);
}

/* The git state of the checkout the program runs in (the working
 * directory's): a study runs from the tree whose matrix file it reads, and a
 * commit here other than build.git_commit shows a stale binary. No path is
 * compiled in: an installed binary has no source tree of its own. */
static json_t *checkout_json(void)
{
    char cwd[1024], top[1024], commit[128], dirty[16];
    if (!getcwd(cwd, sizeof cwd)) snprintf(cwd, sizeof cwd, ".");
    command_line("git rev-parse --show-toplevel 2>/dev/null", top, sizeof top);
    command_line("git rev-parse HEAD 2>/dev/null", commit, sizeof commit);
    if (!top[0] || !commit[0]) return json_pack("{s:s, s:s}", "path", cwd, "commit", "unknown (not a git checkout)");
    command_line("git status --porcelain --untracked-files=no 2>/dev/null | wc -l", dirty, sizeof dirty);
    return json_pack("{s:s, s:s, s:b}", "path", top, "commit", commit, "dirty", atoi(dirty) > 0);
}

static const char *env_or_empty(const char *name)
{
    const char *v = getenv(name);
    return v ? v : "";
}

json_t *provenance_json(int threads, int with_checkout)
{
    char host[256] = "unknown", model[256], mpi[MPI_MAX_LIBRARY_VERSION_STRING] = "", when[64];
    gethostname(host, sizeof host);
    host[sizeof host - 1] = '\0';
    int physical;
    cpu_info(model, sizeof model, &physical);
    int len = 0;
    MPI_Get_library_version(mpi, &len); /* allowed before MPI_Init */
    mpi[strcspn(mpi, "\n,")] = '\0';
    /* OpenBLAS, when it is the BLAS the process loaded */
    const char *openblas = "not loaded";
    void *self = dlopen(NULL, RTLD_LAZY);
    if (self) {
        void *sym = dlsym(self, "openblas_get_config");
        if (sym) {
            char *(*config)(void);
            memcpy(&config, &sym, sizeof config); /* object pointer to function pointer, without a cast warning */
            openblas = config();
        }
    }
    time_t now = time(NULL);
    struct tm utc;
    gmtime_r(&now, &utc);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
    struct utsname un;
    char os[300] = "unknown";
    if (uname(&un) == 0) snprintf(os, sizeof os, "%s %s %s", un.sysname, un.release, un.machine);
    char jansson[32];
    snprintf(jansson, sizeof jansson, "%s", JANSSON_VERSION);
    json_t *build = json_pack("{s:s, s:s, s:o, s:s, s:s, s:s}", "version", MPM_VERSION, "git_commit", MPM_GIT_COMMIT,
                              "git_dirty",
                              MPM_GIT_DIRTY < 0 ? json_null() : json_boolean(MPM_GIT_DIRTY > 0),
                              "compiler", MPM_COMPILER, "flags", MPM_BUILD_FLAGS, "build_type",
                              MPM_BUILD_TYPE);
    json_t *libs = json_object();
    for (int i = 0; libs && i < registry_adapter_count(); ++i) { /* "not built" when the build left one out */
        const char *key, *version;
        registry_adapter_library(i, &key, &version);
        json_object_set_new(libs, key, json_string(version));
    }
    if (libs) json_object_set_new(libs, "openblas", json_string(openblas));
    if (libs) json_object_set_new(libs, "mpi", json_string(mpi));
    if (libs) json_object_set_new(libs, "jansson", json_string(jansson));
    json_t *envs = json_pack("{s:s, s:s, s:s, s:s, s:s}", "OMP_WAIT_POLICY", env_or_empty("OMP_WAIT_POLICY"),
                             "GOMP_SPINCOUNT", env_or_empty("GOMP_SPINCOUNT"), "OMP_NUM_THREADS",
                             env_or_empty("OMP_NUM_THREADS"), "OMP_PROC_BIND", env_or_empty("OMP_PROC_BIND"),
                             "OMP_PLACES", env_or_empty("OMP_PLACES"));
    if (self) dlclose(self);
    json_t *p = json_pack("{s:o, s:s, s:s, s:s, s:i, s:i, s:i, s:o, s:o, s:s}", "build", build, "host", host, "os", os,
                          "cpu_model", model, "cores_online", (int)sysconf(_SC_NPROCESSORS_ONLN), "physical_cores",
                          physical, "omp_max_threads", omp_get_max_threads(), "environment", envs, "libraries", libs,
                          "start_time", when);
    if (p && threads > 0) json_object_set_new(p, "threads", json_integer(threads));
    if (p && with_checkout) json_object_set_new(p, "checkout", checkout_json());
    return p;
}
