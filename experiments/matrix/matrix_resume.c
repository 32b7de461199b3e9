#include "experiments/matrix/matrix_resume.h"

#include <dirent.h>
#include <errno.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/event_log.h"
#include "experiments/io/checkpoint.h"
#include "experiments/io/machine_load.h"
#include "experiments/io/paths.h"

enum { PATH_CAP = 1400, MAX_ATTEMPTS = 1000 };

/* The frame an attempt's run started at (run.json checkpoints.first_frame); -1: unknown. */
static int first_frame(const char *dir)
{
    char path[PATH_CAP];
    snprintf(path, sizeof path, "%s/run.json", dir);
    json_t *run = json_load_file(path, 0, NULL);
    json_t *f = run ? json_object_get(json_object_get(run, "checkpoints"), "first_frame") : NULL;
    int frame = json_is_integer(f) ? (int)json_integer_value(f) : -1;
    json_decref(run);
    return frame;
}

/* The frame of a CSV row whose third field is the frame (steps.csv,
 * frames.csv); -1 for anything else (the header, a cut line). */
static int row_frame(const char *line)
{
    int field = 0, quoted = 0;
    const char *p = line;
    for (; *p && field < 2; ++p) {
        if (*p == '"') quoted = !quoted;
        else if (*p == ',' && !quoted) field++;
    }
    if (field < 2 || *p < '0' || *p > '9') return -1;
    char *end;
    long v = strtol(p, &end, 10);
    return *end == ',' && v < 1000000000L ? (int)v : -1;
}

/* Do dir's frames.csv rows cover every frame from `from` up to before `to`, each once? */
static int frames_cover(const char *dir, int from, int to)
{
    char path[PATH_CAP];
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    char *line = NULL;
    size_t cap = 0;
    int next = from;
    while (getline(&line, &cap, f) > 0 && next < to) {
        size_t n = strlen(line);
        if (!n || line[n - 1] != '\n') break; /* a row cut by the stop */
        int frame = row_frame(line);
        if (frame < 0) continue;
        if (frame != next) break;
        next++;
    }
    free(line);
    fclose(f);
    return next >= to;
}

/* The checkpoint in dir/checkpoints with the largest frame (a sampled
 * frame's or the resume one): its path into out, its frame; -1: none. */
static int newest_checkpoint(const char *dir, char *out, size_t cap)
{
    char path[PATH_CAP];
    snprintf(path, sizeof path, "%s/checkpoints", dir);
    DIR *d = opendir(path);
    if (!d) return -1;
    int best = -1;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 5, ".ckpt")) continue; /* a .part is a write the stop cut */
        char file[PATH_CAP];
        int frame, len = snprintf(file, sizeof file, "%s/%s", path, e->d_name);
        if (len < 0 || (size_t)len >= sizeof file) continue;
        if (checkpoint_frame(file, &frame) != MPM_OK) continue; /* damaged: not one to go on from */
        if (frame > best) {
            best = frame;
            snprintf(out, cap, "%s", file);
        }
    }
    closedir(d);
    return best;
}

typedef struct {
    double elapsed_s, cpu_s, others_cpu_s;
    long peak_rss_kb;
} Progress;

static int read_progress(const char *dir, Progress *p)
{
    char path[PATH_CAP];
    int len = snprintf(path, sizeof path, "%s/progress.txt", dir);
    FILE *f = len > 0 && (size_t)len < sizeof path ? fopen(path, "r") : NULL;
    if (!f) return 0;
    int got = fscanf(f, "elapsed_s %lf cpu_s %lf others_cpu_s %lf peak_rss_kb %ld", &p->elapsed_s, &p->cpu_s,
                     &p->others_cpu_s, &p->peak_rss_kb);
    fclose(f);
    return got == 4;
}

int matrix_resume_prepare(const char *dir, char *from, size_t cap, int *attempts)
{
    *attempts = 0;
    char path[PATH_CAP], ckpt[PATH_CAP];
    Progress cost;
    if (!read_progress(dir, &cost)) return MPM_OK; /* never started, or by a runner that did not record its cost */
    int start = first_frame(dir), frame = newest_checkpoint(dir, ckpt, sizeof ckpt);
    if (start < 0 || frame <= start || !frames_cover(dir, start, frame)) return MPM_OK;
    int n = 1;
    for (; n < MAX_ATTEMPTS; ++n) {
        snprintf(path, sizeof path, "%s/attempts/%d", dir, n);
        if (access(path, F_OK) != 0) break;
    }
    if (n == MAX_ATTEMPTS) return MPM_OK;
    char to[PATH_CAP];
    snprintf(to, sizeof to, "%s/attempts/%d", dir, n);
    int st = paths_mkdir_p(to);
    if (st) return st;
    /* the attempt's own files; its checkpoints stay (the sampled frames' are
     * outputs), but the resume one moves with it, as the next attempt writes its own */
    DIR *d = opendir(dir);
    if (!d) return mpm_error(MPM_EINTERNAL, "%s: cannot list the cell's folder to resume it", dir);
    struct dirent *e;
    while (!st && (e = readdir(d))) {
        const char *name = e->d_name;
        if (!strcmp(name, ".") || !strcmp(name, "..") || !strcmp(name, "attempts") || !strcmp(name, "checkpoints"))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, name);
        char dest[PATH_CAP + 300];
        snprintf(dest, sizeof dest, "%s/%s", to, name);
        if (rename(path, dest) != 0) st = mpm_error(MPM_EINTERNAL, "%s: cannot move it to %s: %s", path, to, strerror(errno));
    }
    closedir(d);
    if (st) return st;
    snprintf(path, sizeof path, "%s/checkpoints/resume.ckpt", dir);
    if (!strcmp(ckpt, path)) {
        int len = snprintf(ckpt, sizeof ckpt, "%s/resume.ckpt", to);
        if (len < 0 || (size_t)len >= sizeof ckpt || rename(path, ckpt) != 0)
            return mpm_error(MPM_EINTERNAL, "%s: cannot move it to %s: %s", path, to, strerror(errno));
    }
    if (strlen(ckpt) >= cap) return mpm_error(MPM_EINTERNAL, "%s: path too long", ckpt);
    snprintf(from, cap, "%s", ckpt);
    *attempts = n;
    return MPM_OK;
}

/* user + system CPU seconds of process pid and its reaped children (/proc/PID/stat); -1: unknown. */
static double process_tree_cpu(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f) return -1.0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    const char *p = strrchr(buf, ')'); /* the command name may hold spaces */
    unsigned long long v[4];
    long tick = sysconf(_SC_CLK_TCK);
    /* after the name: state, then fields 4-13, then utime stime cutime cstime (fields 14-17) */
    if (!p || tick <= 0 ||
        sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3]) != 4)
        return -1.0;
    return (double)(v[0] + v[1] + v[2] + v[3]) / (double)tick;
}

/* Peak resident memory of process pid in kB (/proc/PID/status VmHWM); 0: unknown. */
static long process_peak_kb(pid_t pid)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE *f = fopen(path, "r");
    long kb = 0;
    if (!f) return 0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld", &kb) == 1) break;
    fclose(f);
    return kb;
}

void matrix_resume_record(const char *dir, const CellChild *c)
{
    if (!c->pid) return;
    double elapsed = event_clock() - c->t_start, cpu = process_tree_cpu(c->pid), busy = machine_busy_seconds();
    double others = cpu >= 0 && busy >= 0 && c->busy0 >= 0 ? busy - c->busy0 - cpu : -1.0;
    if (cpu >= 0 && others < 0 && busy >= 0 && c->busy0 >= 0) others = 0.0;
    char path[PATH_CAP], part[PATH_CAP + 8];
    snprintf(path, sizeof path, "%s/progress.txt", dir);
    snprintf(part, sizeof part, "%s.part", path);
    FILE *f = fopen(part, "w");
    if (!f) return; /* a record missed is one less to resume from; the cell goes on */
    int bad = fprintf(f, "elapsed_s %.3f\ncpu_s %.3f\nothers_cpu_s %.3f\npeak_rss_kb %ld\n", elapsed, cpu, others,
                      process_peak_kb(c->pid)) < 0;
    if (fclose(f) != 0 || bad || rename(part, path) != 0) remove(part);
}

/* dir/name from the attempts' rows (attempt i's up to before start[i + 1])
 * and the last run's, under the last run's header. */
static int join_rows(const char *dir, int attempts, const int *start, const char *name)
{
    char path[PATH_CAP], part[PATH_CAP + 8];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    snprintf(part, sizeof part, "%s.part", path);
    FILE *last = fopen(path, "r");
    if (!last) return mpm_error(MPM_EINTERNAL, "%s: missing after the resumed run", path);
    FILE *out = fopen(part, "w");
    if (!out) {
        fclose(last);
        return mpm_error(MPM_EINTERNAL, "%s: cannot write", part);
    }
    char *line = NULL;
    size_t cap = 0;
    int bad = getline(&line, &cap, last) <= 0 || fputs(line, out) < 0; /* the header */
    for (int i = 1; i <= attempts && !bad; ++i) {
        char from[PATH_CAP];
        snprintf(from, sizeof from, "%s/attempts/%d/%s", dir, i, name);
        FILE *f = fopen(from, "r");
        if (!f) {
            bad = 1;
            break;
        }
        while (!bad && getline(&line, &cap, f) > 0) {
            size_t n = strlen(line);
            int frame = row_frame(line);
            if (n && line[n - 1] == '\n' && frame >= start[i] && frame < start[i + 1]) bad = fputs(line, out) < 0;
        }
        fclose(f);
    }
    while (!bad && getline(&line, &cap, last) > 0) bad = fputs(line, out) < 0;
    free(line);
    fclose(last);
    if (fclose(out) != 0 || bad || rename(part, path) != 0) {
        remove(part);
        return mpm_error(MPM_EINTERNAL, "%s: cannot join the rows of its %d earlier attempt%s", path, attempts,
                         attempts == 1 ? "" : "s");
    }
    return MPM_OK;
}

int matrix_resume_finish(const char *dir, int attempts, CellOutcome *o)
{
    char path[PATH_CAP];
    int st = MPM_OK;
    if (attempts > 0) {
        int *start = malloc(sizeof(int) * (size_t)(attempts + 2));
        if (!start) return mpm_error(MPM_EINTERNAL, "out of memory");
        for (int i = 1; i <= attempts; ++i) {
            snprintf(path, sizeof path, "%s/attempts/%d", dir, i);
            start[i] = first_frame(path);
        }
        start[attempts + 1] = first_frame(dir);
        for (int i = 1; i <= attempts + 1 && !st; ++i)
            if (start[i] < 0 || (i > 1 && start[i] <= start[i - 1]))
                st = mpm_error(MPM_EINTERNAL, "%s: attempt %d's run.json does not say where it started", dir, i);
        if (!st) st = join_rows(dir, attempts, start, "steps.csv");
        if (!st) st = join_rows(dir, attempts, start, "frames.csv");
        snprintf(path, sizeof path, "%s/attempts.csv", dir);
        FILE *log = st ? NULL : fopen(path, "w");
        if (!st && !log) st = mpm_error(MPM_EINTERNAL, "%s: cannot write", path);
        if (log) fprintf(log, "attempt,first_frame,elapsed_s,cpu_s,others_cpu_s\n");
        const CellOutcome last = *o;
        for (int i = 1; i <= attempts && !st; ++i) { /* the cell's cost: every attempt's */
            Progress p;
            snprintf(path, sizeof path, "%s/attempts/%d", dir, i);
            if (!read_progress(path, &p)) {
                o->others_cpu_s = -1.0;
                continue;
            }
            if (log) fprintf(log, "%d,%d,%.3f,%.3f,%.3f\n", i, start[i], p.elapsed_s, p.cpu_s, p.others_cpu_s);
            o->elapsed_s += p.elapsed_s;
            o->cpu_s += p.cpu_s > 0 ? p.cpu_s : 0.0;
            o->others_cpu_s = o->others_cpu_s < 0 || p.others_cpu_s < 0 ? -1.0 : o->others_cpu_s + p.others_cpu_s;
            if (p.peak_rss_kb > o->peak_rss_kb) o->peak_rss_kb = p.peak_rss_kb;
            snprintf(path, sizeof path, "%s/attempts/%d/resume.ckpt", dir, i);
            remove(path);
        }
        if (log) fprintf(log, "%d,%d,%.3f,%.3f,%.3f\n", attempts + 1, start[attempts + 1], last.elapsed_s, last.cpu_s,
                         last.others_cpu_s);
        if (log && fclose(log) != 0 && !st)
            st = mpm_error(MPM_EINTERNAL, "%s/attempts.csv: cannot write", dir);
        free(start);
    }
    snprintf(path, sizeof path, "%s/checkpoints/resume.ckpt", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/progress.txt", dir);
    remove(path);
    return st;
}
