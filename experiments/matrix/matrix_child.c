#include "experiments/matrix/matrix_child.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/error.h"
#include "core/event_log.h"
#include "experiments/io/machine_load.h"

extern char **environ;

/* wait4 is BSD/GNU; declared here so the file builds with _POSIX_C_SOURCE. */
pid_t wait4(pid_t pid, int *status, int options, struct rusage *rusage);

void matrix_sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

int matrix_is_launcher_env(const char *entry)
{
    /* OpenMPI (OMPI_, OPAL_, ORTE_, PRTE_), PMIx, MPICH/Hydra (PMI_, HYDRA_, MPIR_), Intel MPI (I_MPI_) */
    static const char *const prefixes[] = {"OMPI_", "OPAL_", "ORTE_", "PRTE_", "PMIX_", "PMI_", "HYDRA_", "MPIR_",
                                           "I_MPI_", "MPI_LOCALRANKID=", "MPI_LOCALNRANKS="};
    for (size_t i = 0; i < sizeof prefixes / sizeof prefixes[0]; ++i)
        if (!strncmp(entry, prefixes[i], strlen(prefixes[i]))) return 1;
    return 0;
}

static int open_out(const char *dir, const char *name)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
}

/* The launcher's path: the first `name` on PATH that is executable, into out. */
static int find_on_path(const char *name, char *out, size_t cap)
{
    const char *path = getenv("PATH");
    for (const char *p = path; p && *p;) {
        size_t len = strcspn(p, ":");
        int w = snprintf(out, cap, "%.*s/%s", (int)len, len ? p : ".", name);
        if (w > 0 && (size_t)w < cap && access(out, X_OK) == 0) return 1;
        p += len + (p[len] == ':');
    }
    return 0;
}

/* The variables a cell over ranks adds (Open MPI reads its own, others
 * ignore them): ranks may outnumber cores and run as root, and no rank is
 * bound to one core (a rank's threads would share it); each rank's OpenMP
 * team is the cores over the ranks unless the cell sets --threads. */
enum { LAUNCH_ENV = 5 };
static void launch_env(int ranks, char text[LAUNCH_ENV][64])
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    long per_rank = cores > ranks ? cores / ranks : 1;
    snprintf(text[0], 64, "OMPI_ALLOW_RUN_AS_ROOT=1");
    snprintf(text[1], 64, "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1");
    snprintf(text[2], 64, "OMPI_MCA_rmaps_base_oversubscribe=1");
    snprintf(text[3], 64, "OMPI_MCA_hwloc_base_binding_policy=none");
    snprintf(text[4], 64, "OMP_NUM_THREADS=%ld", per_rank);
}

int cell_child_start(char *const *args, int argc, const char *dir, double timeout_s, int ranks, CellChild *c)
{
    memset(c, 0, sizeof *c);
    /* everything the child needs is prepared before fork: after it, only
     * async-signal-safe calls until execve */
    const int launched = ranks > 1;
    char launcher[1024] = "/proc/self/exe", self[1024] = "", np[16] = "", added[LAUNCH_ENV][64];
    if (launched) {
        ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
        if (len <= 0 || (size_t)len >= sizeof self - 1)
            return mpm_error(MPM_EINTERNAL, "%s: cannot find this program's path for mpirun", dir);
        self[len] = '\0';
        if (!find_on_path("mpirun", launcher, sizeof launcher))
            return mpm_error(MPM_EINPUT, "%s: ranks %d: no mpirun on PATH (Debian package openmpi-bin)", dir, ranks);
        snprintf(np, sizeof np, "%d", ranks);
        launch_env(ranks, added);
    }
    size_t n_env = 0;
    while (environ[n_env]) n_env++;
    char **env = malloc(sizeof *env * (n_env + 2 + LAUNCH_ENV));
    char **argv = malloc(sizeof *argv * (size_t)(argc + 5));
    int out = open_out(dir, "stdout.txt"), err = open_out(dir, "stderr.txt");
    int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
    long max_fd = sysconf(_SC_OPEN_MAX);
    if (max_fd < 0 || max_fd > 65536) max_fd = 65536;
    int st = MPM_OK;
    if (!env || !argv) st = mpm_error(MPM_EINTERNAL, "out of memory starting a cell");
    else if (out < 0 || err < 0 || in < 0) st = mpm_error(MPM_EINTERNAL, "%s: cannot create the cell's output files", dir);
    pid_t parent = getpid();
    pid_t pid = -1;
    double load0 = machine_load1(), busy0 = machine_busy_seconds();
    if (!st) {
        size_t k = 0;
        for (size_t i = 0; i < n_env; ++i)
            if (!matrix_is_launcher_env(environ[i]) && strncmp(environ[i], "MPM_MATRIX_CELL=", 16) &&
                !(launched && !strncmp(environ[i], "OMP_NUM_THREADS=", 16)))
                env[k++] = environ[i];
        env[k++] = "MPM_MATRIX_CELL=1"; /* run leaves the machine's load to the runner (cells.csv) */
        for (int i = 0; launched && i < LAUNCH_ENV; ++i) env[k++] = added[i];
        env[k] = NULL;
        int a = 0;
        if (launched) {
            argv[a++] = "mpirun";
            argv[a++] = "-np";
            argv[a++] = np;
            argv[a++] = self;
        } else {
            argv[a++] = "mpmbench";
        }
        for (int i = 0; i < argc; ++i) argv[a++] = args[i];
        argv[a] = NULL;
        pid = fork();
        if (pid < 0) st = mpm_error(MPM_EINTERNAL, "fork failed starting a cell in %s", dir);
    }
    if (pid == 0) {
        setpgid(0, 0);
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) _exit(127); /* the runner died before prctl */
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        signal(SIGPIPE, SIG_DFL);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        dup2(in, 0);
        dup2(out, 1);
        dup2(err, 2);
        for (long fd = 3; fd < max_fd; ++fd) close((int)fd);
        execve(launcher, argv, env);
        _exit(127);
    }
    if (pid > 0) {
        setpgid(pid, pid); /* also here: no race with a kill of the group */
        c->pid = pid;
        c->t_start = event_clock();
        c->timeout_s = timeout_s;
        c->ranks = ranks;
        c->busy0 = busy0;
        c->load0 = load0;
    }
    if (out >= 0) close(out);
    if (err >= 0) close(err);
    if (in >= 0) close(in);
    free(env);
    free(argv);
    return st;
}

void cell_child_kill(CellChild *c)
{
    if (!c->pid) return;
    kill(-c->pid, SIGKILL);
    while (waitpid(c->pid, NULL, 0) < 0 && errno == EINTR) {
    }
    c->pid = 0;
}

int cell_child_poll(CellChild *c, CellOutcome *out)
{
    if (!c->pid) return 0;
    double now = event_clock();
    if (!c->timed_out && c->timeout_s > 0 && now - c->t_start > c->timeout_s) {
        kill(-c->pid, SIGKILL);
        c->timed_out = 1;
    }
    int status = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    pid_t r = wait4(c->pid, &status, WNOHANG, &ru);
    if (r == 0) return 0;
    if (r < 0 && errno == EINTR) return 0;
    if (r < 0) status = 0x7f00; /* lost (ECHILD): reported as a failed exit 127 */
    double busy1 = machine_busy_seconds();
    *out = cell_outcome(status, c->timed_out, now - c->t_start, ru.ru_maxrss);
    out->cpu_s = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
                 1e-6 * (double)ru.ru_stime.tv_usec;
    /* the machine's busy time is counted in clock ticks (10 ms): a tick or so
     * of difference is no load */
    /* a killed mpirun never reaped its ranks: their CPU time is not in
     * cpu_s, so the others' time is unknown */
    const int ranks_lost = c->timed_out && c->ranks > 1;
    out->others_cpu_s = -1.0;
    if (busy1 >= 0 && c->busy0 >= 0 && !ranks_lost) {
        out->others_cpu_s = busy1 - c->busy0 - out->cpu_s;
        if (out->others_cpu_s < 0) out->others_cpu_s = 0.0;
    }
    out->load_start = c->load0;
    c->pid = 0;
    return 1;
}
