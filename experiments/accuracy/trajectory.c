/* Trajectory files and the trajectory error (trajectory.h). */
#include "experiments/accuracy/trajectory.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

typedef struct {
    uint32_t frame, pad;
    double t;
    uint64_t n;
} RecordHead; /* 24 bytes, no padding */

_Static_assert(sizeof(RecordHead) == 24, "trajectory record header is 24 bytes");

static int grow(double **buf, size_t *cap, size_t n)
{
    if (6 * n <= *cap) return MPM_OK;
    size_t c = 6 * n + 6 * 1024;
    double *q = realloc(*buf, sizeof(double) * c);
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: trajectory frame of %zu particles", n);
    *buf = q;
    *cap = c;
    return MPM_OK;
}

int trajectory_writer_open(TrajectoryWriter *w, const char *dir, const char *scene, double dx, size_t particles)
{
    memset(w, 0, sizeof *w);
    snprintf(w->path, sizeof w->path, "%s/%s", dir, TRAJECTORY_FILE);
    if (!(w->f = fopen(w->path, "wb"))) return mpm_error(MPM_EINPUT, "%s: cannot write", w->path);
    unsigned char h[TRAJECTORY_HEADER_BYTES];
    memset(h, 0, sizeof h);
    uint32_t version = 1, bytes = TRAJECTORY_HEADER_BYTES;
    uint64_t np = particles;
    memcpy(h, TRAJECTORY_MAGIC, 8);
    memcpy(h + 8, &version, 4);
    memcpy(h + 12, &bytes, 4);
    snprintf((char *)h + 16, 64, "%s", scene);
    memcpy(h + 80, &dx, 8);
    memcpy(h + 88, &np, 8);
    if (fwrite(h, 1, sizeof h, w->f) != sizeof h) return mpm_error(MPM_EINPUT, "%s: cannot write", w->path);
    return MPM_OK;
}

/* The particles' positions and velocities scattered into id order. */
static int gather(const Particles *p, double *buf, const char *what)
{
    size_t n = p->n;
    for (size_t k = 0; k < n; ++k) {
        size_t id = p->id[k];
        if (id >= n) return mpm_error(MPM_EINTERNAL, "%s: particle id %zu out of range (%zu particles)", what, id, n);
        memcpy(buf + 3 * id, p->x + 3 * k, 3 * sizeof(double));
        memcpy(buf + 3 * (n + id), p->v + 3 * k, 3 * sizeof(double));
    }
    return MPM_OK;
}

int trajectory_write_frame(TrajectoryWriter *w, int frame, double t, const Particles *p)
{
    int st = grow(&w->buf, &w->cap, p->n);
    if (!st) st = gather(p, w->buf, w->path);
    if (st) return st;
    RecordHead rh = {(uint32_t)frame, 0, t, (uint64_t)p->n};
    if (fwrite(&rh, sizeof rh, 1, w->f) != 1 || fwrite(w->buf, sizeof(double), 6 * p->n, w->f) != 6 * p->n ||
        fflush(w->f) != 0)
        return mpm_error(MPM_EINPUT, "%s: cannot write frame %d", w->path, frame);
    return MPM_OK;
}

void trajectory_writer_close(TrajectoryWriter *w)
{
    if (w->f) fclose(w->f);
    free(w->buf);
    memset(w, 0, sizeof *w);
}

int trajectory_reader_open(TrajectoryReader *r, const char *run_dir, const char *scene, size_t particles,
                           int frames)
{
    memset(r, 0, sizeof *r);
    snprintf(r->path, sizeof r->path, "%s/%s", run_dir, TRAJECTORY_FILE);
    if (!(r->f = fopen(r->path, "rb")))
        return mpm_error(MPM_EINPUT, "--trajectory-ref %s: no %s (run the reference with --trajectory)", run_dir,
                         r->path);
    unsigned char h[TRAJECTORY_HEADER_BYTES];
    uint32_t version = 0, bytes = 0;
    if (fread(h, 1, sizeof h, r->f) != sizeof h || memcmp(h, TRAJECTORY_MAGIC, 8) != 0)
        return mpm_error(MPM_EINPUT, "--trajectory-ref %s: %s is not a trajectory file (no %s header)", run_dir,
                         r->path, TRAJECTORY_MAGIC);
    memcpy(&version, h + 8, 4);
    memcpy(&bytes, h + 12, 4);
    if (version != 1 || bytes != TRAJECTORY_HEADER_BYTES)
        return mpm_error(MPM_EINPUT, "--trajectory-ref %s: %s: version %u (header %u bytes), expected 1 (%d)", run_dir,
                         r->path, version, bytes, TRAJECTORY_HEADER_BYTES);
    memcpy(r->scene, h + 16, 63);
    memcpy(&r->dx, h + 80, 8);
    memcpy(&r->particles, h + 88, 8);
    if (strcmp(r->scene, scene) != 0)
        return mpm_error(MPM_EINPUT, "--trajectory-ref %s: the reference is scene \"%s\", this run is scene \"%s\"",
                         run_dir, r->scene, scene);
    if (r->particles != (uint64_t)particles)
        return mpm_error(MPM_EINPUT,
                         "--trajectory-ref %s: the reference starts with %llu particles, this run with %zu (another "
                         "--scale or --set?)",
                         run_dir, (unsigned long long)r->particles, particles);
    /* count the records: a reference cut short cannot serve a longer run */
    RecordHead rh;
    while (fread(&rh, sizeof rh, 1, r->f) == 1) {
        if (rh.n > ((uint64_t)1 << 40) || fseek(r->f, (long)(48 * rh.n), SEEK_CUR) != 0) break;
        r->frames++;
    }
    if (r->frames < frames)
        return mpm_error(MPM_EINPUT, "--trajectory-ref %s: the reference has %d frames, this run asks for %d", run_dir,
                         r->frames, frames);
    if (fseek(r->f, TRAJECTORY_HEADER_BYTES, SEEK_SET) != 0)
        return mpm_error(MPM_EINPUT, "%s: cannot rewind", r->path);
    return MPM_OK;
}

int trajectory_compare_frame(TrajectoryReader *r, int frame, const Particles *p, double dx, TrajectoryError *e)
{
    RecordHead rh;
    e->pos_rms = e->pos_max = e->vel_rms = NAN;
    if (fread(&rh, sizeof rh, 1, r->f) != 1)
        return mpm_error(MPM_EINPUT, "--trajectory-ref: %s ends before frame %d", r->path, frame);
    if ((int)rh.frame != frame || rh.n != (uint64_t)p->n)
        return mpm_error(MPM_EINPUT,
                         "--trajectory-ref: %s: the record is frame %u with %llu particles, this run is at frame %d "
                         "with %zu",
                         r->path, rh.frame, (unsigned long long)rh.n, frame, p->n);
    size_t n = p->n;
    int st = grow(&r->ref, &r->cap, n);
    if (st) return st;
    if (fread(r->ref, sizeof(double), 6 * n, r->f) != 6 * n)
        return mpm_error(MPM_EINPUT, "--trajectory-ref: %s: frame %d is cut short", r->path, frame);
    double sx = 0.0, mx = 0.0, sv = 0.0, sref = 0.0;
    for (size_t k = 0; k < n; ++k) {
        size_t id = p->id[k];
        if (id >= n) return mpm_error(MPM_EINTERNAL, "particle id %zu out of range (%zu particles)", id, n);
        const double *xr = r->ref + 3 * id, *vr = r->ref + 3 * (n + id), *x = p->x + 3 * k, *v = p->v + 3 * k;
        double dx2 = 0.0, dv2 = 0.0, v2 = 0.0;
        for (int d = 0; d < 3; ++d) {
            dx2 += (x[d] - xr[d]) * (x[d] - xr[d]);
            dv2 += (v[d] - vr[d]) * (v[d] - vr[d]);
            v2 += vr[d] * vr[d];
        }
        sx += dx2;
        if (dx2 > mx) mx = dx2;
        sv += dv2;
        sref += v2;
    }
    if (n > 0) {
        e->pos_rms = sqrt(sx / (double)n) / dx;
        e->pos_max = sqrt(mx) / dx;
        e->vel_rms = sv == 0.0 ? 0.0 : sref > 0.0 ? sqrt(sv / sref) : NAN;
    }
    return MPM_OK;
}

void trajectory_reader_close(TrajectoryReader *r)
{
    if (r->f) fclose(r->f);
    free(r->ref);
    memset(r, 0, sizeof *r);
}
