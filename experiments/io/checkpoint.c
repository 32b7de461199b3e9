/* Checkpoint files (checkpoint.h). */
#include "experiments/io/checkpoint.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#define MAGIC "MPMBENCH-CHECKPOINT\n"
#define MAGIC_LEN 20
#define FORMAT_VERSION 1u
#define BYTE_ORDER_MARK 0x01020304u

uint64_t checkpoint_hash(uint64_t h, const void *bytes, size_t n)
{
    const unsigned char *b = bytes;
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ULL;
    return h;
}

/* ---------------------------------------------------------------- writing */

typedef struct {
    FILE *f;
    uint64_t hash;
    int failed;
} Writer;

static void put(Writer *w, const void *p, size_t n)
{
    if (w->failed || n == 0) return;
    if (fwrite(p, 1, n, w->f) != n) w->failed = 1;
    w->hash = checkpoint_hash(w->hash, p, n);
}

int checkpoint_write(const char *path, const Simulation *sim, uint64_t scene_fingerprint)
{
    /* written beside its name and renamed into place, so a run stopped while
     * it writes leaves the previous file or none, never a partial one (a
     * resumed matrix reference continues from the newest it finds) */
    char part[1200];
    int len = snprintf(part, sizeof part, "%s.part", path);
    if (len < 0 || (size_t)len >= sizeof part) return mpm_error(MPM_EINPUT, "%s: path too long for a checkpoint", path);
    Writer w = {fopen(part, "wb"), CHECKPOINT_FNV_BASIS, 0};
    if (!w.f) return mpm_error(MPM_EINPUT, "%s: cannot write the checkpoint", path);
    const Particles *p = &sim->p;
    uint32_t version = FORMAT_VERSION, order = BYTE_ORDER_MARK, has_jp = p->Jp != NULL, pad = 0;
    int32_t frame = sim->frame, volumes_done = sim->volumes_done;
    uint64_t n = p->n;
    put(&w, MAGIC, MAGIC_LEN);
    put(&w, &version, sizeof version);
    put(&w, &order, sizeof order);
    put(&w, &scene_fingerprint, sizeof scene_fingerprint);
    put(&w, &frame, sizeof frame);
    put(&w, &volumes_done, sizeof volumes_done);
    const double clock[4] = {sim->t, sim->t_in_frame, sim->dt, sim->dt_next};
    put(&w, clock, sizeof clock);
    put(&w, &n, sizeof n);
    put(&w, &has_jp, sizeof has_jp);
    put(&w, &pad, sizeof pad);
    put(&w, p->x, sizeof(double) * 3 * p->n);
    put(&w, p->v, sizeof(double) * 3 * p->n);
    put(&w, p->C, sizeof(double) * 9 * p->n);
    put(&w, p->F, sizeof(double) * 9 * p->n);
    put(&w, p->mass, sizeof(double) * p->n);
    put(&w, p->vol, sizeof(double) * p->n);
    put(&w, p->mat, sizeof(int) * p->n);
    if (has_jp) put(&w, p->Jp, sizeof(double) * p->n);
    put(&w, p->id, sizeof(size_t) * p->n);
    uint64_t hash = w.hash;
    if (!w.failed && fwrite(&hash, sizeof hash, 1, w.f) != 1) w.failed = 1;
    if (fclose(w.f) != 0) w.failed = 1;
    if (!w.failed && rename(part, path) != 0) w.failed = 1;
    if (w.failed) {
        remove(part);
        return mpm_error(MPM_EINPUT, "%s: cannot write the checkpoint (disk full?)", path);
    }
    return MPM_OK;
}

/* ---------------------------------------------------------------- reading */

typedef struct {
    const char *path;
    const unsigned char *data;
    size_t len, at;
} Reader;

static int take(Reader *r, void *out, size_t n, const char *what)
{
    if (n > r->len - r->at)
        return mpm_error(MPM_EINPUT, "%s: not a complete checkpoint (it ends inside %s)", r->path, what);
    if (n) memcpy(out, r->data + r->at, n);
    r->at += n;
    return MPM_OK;
}

typedef struct {
    uint64_t fingerprint;
    int32_t frame, volumes_done;
    double clock[4];
    uint64_t n;
    uint32_t has_jp;
} Header;

/* Reads the file, checks the magic, version, byte order and the trailing
 * hash, and the header; r->at is then at the arrays. data is the caller's
 * to free. */
static int open_checked(const char *path, Reader *r, unsigned char **data, Header *h)
{
    *data = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot read the checkpoint", path);
    long len = -1;
    if (fseek(f, 0, SEEK_END) == 0) len = ftell(f);
    if (len < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return mpm_error(MPM_EINPUT, "%s: cannot read the checkpoint", path);
    }
    *data = malloc(len > 0 ? (size_t)len : 1);
    if (!*data) {
        fclose(f);
        return mpm_error(MPM_EINTERNAL, "out of memory reading %s (%ld bytes)", path, len);
    }
    size_t got = fread(*data, 1, (size_t)len, f);
    fclose(f);
    if (got != (size_t)len) return mpm_error(MPM_EINPUT, "%s: cannot read the checkpoint", path);
    *r = (Reader){path, *data, (size_t)len, 0};
    char magic[MAGIC_LEN];
    uint32_t version = 0, order = 0, pad = 0;
    int st = take(r, magic, MAGIC_LEN, "its header");
    if (!st && memcmp(magic, MAGIC, MAGIC_LEN) != 0)
        return mpm_error(MPM_EINPUT, "%s: not an mpmbench checkpoint", path);
    if (!st) st = take(r, &version, sizeof version, "its header");
    if (!st) st = take(r, &order, sizeof order, "its header");
    if (st) return st;
    if (order != BYTE_ORDER_MARK)
        return mpm_error(MPM_EINPUT, "%s: written on a machine of another byte order", path);
    if (version != FORMAT_VERSION)
        return mpm_error(MPM_EINPUT, "%s: checkpoint format version %u, this build reads version %u", path,
                         (unsigned)version, FORMAT_VERSION);
    uint64_t stored;
    if (r->len < r->at + sizeof stored)
        return mpm_error(MPM_EINPUT, "%s: not a complete checkpoint (it ends inside its header)", path);
    memcpy(&stored, r->data + r->len - sizeof stored, sizeof stored);
    if (checkpoint_hash(CHECKPOINT_FNV_BASIS, r->data, r->len - sizeof stored) != stored)
        return mpm_error(MPM_EINPUT, "%s: the checkpoint is damaged or truncated (its hash does not match)", path);
    r->len -= sizeof stored;
    if ((st = take(r, &h->fingerprint, sizeof h->fingerprint, "its header")) ||
        (st = take(r, &h->frame, sizeof h->frame, "its header")) ||
        (st = take(r, &h->volumes_done, sizeof h->volumes_done, "its header")) ||
        (st = take(r, h->clock, sizeof h->clock, "its header")) || (st = take(r, &h->n, sizeof h->n, "its header")) ||
        (st = take(r, &h->has_jp, sizeof h->has_jp, "its header")) || (st = take(r, &pad, sizeof pad, "its header")))
        return st;
    return MPM_OK;
}

int checkpoint_frame(const char *path, int *frame)
{
    Reader r;
    unsigned char *data;
    Header h;
    int st = open_checked(path, &r, &data, &h);
    if (!st) *frame = h.frame;
    free(data);
    return st;
}

int checkpoint_read(const char *path, Simulation *sim, uint64_t scene_fingerprint)
{
    Reader r;
    unsigned char *data;
    Header h;
    int st = open_checked(path, &r, &data, &h);
    if (st) goto done;
    if (h.fingerprint != scene_fingerprint) {
        st = mpm_error(MPM_EINPUT,
                       "%s: written for another scene (a different scene file, scale or --set; fingerprint "
                       "%016llx, this run's %016llx)",
                       path, (unsigned long long)h.fingerprint, (unsigned long long)scene_fingerprint);
        goto done;
    }
    size_t n = (size_t)h.n;
    size_t per_particle = sizeof(double) * (3 + 3 + 9 + 9 + 1 + 1) + sizeof(int) + (h.has_jp ? sizeof(double) : 0) +
                          sizeof(size_t);
    if (h.frame < 0 || (h.n && (r.len - r.at) / h.n != per_particle) || (!h.n && r.len != r.at)) {
        st = mpm_error(MPM_EINPUT, "%s: the checkpoint's particle arrays do not match its count (%llu)", path,
                       (unsigned long long)h.n);
        goto done;
    }
    Particles p = {0};
    if ((st = particles_reserve(&p, n > 0 ? n : 1))) goto done;
    if (h.has_jp && (st = particles_enable_plastic_state(&p))) {
        particles_free(&p);
        goto done;
    }
    p.n = n;
    (void)(take(&r, p.x, sizeof(double) * 3 * n, "x") || take(&r, p.v, sizeof(double) * 3 * n, "v") ||
           take(&r, p.C, sizeof(double) * 9 * n, "C") || take(&r, p.F, sizeof(double) * 9 * n, "F") ||
           take(&r, p.mass, sizeof(double) * n, "mass") || take(&r, p.vol, sizeof(double) * n, "vol") ||
           take(&r, p.mat, sizeof(int) * n, "mat") || (h.has_jp && take(&r, p.Jp, sizeof(double) * n, "Jp")) ||
           take(&r, p.id, sizeof(size_t) * n, "id")); /* sizes checked above: cannot fail */
    for (size_t k = 0; k < n; ++k)
        if (p.mat[k] < 0 || p.mat[k] >= sim->scene->n_materials) {
            st = mpm_error(MPM_EINPUT, "%s: particle %zu has material %d; the scene has %d", path, k, p.mat[k],
                           sim->scene->n_materials);
            particles_free(&p);
            goto done;
        }
    particles_free(&sim->p);
    sim->p = p;
    sim->frame = h.frame;
    sim->volumes_done = h.volumes_done;
    sim->t = h.clock[0];
    sim->t_in_frame = h.clock[1];
    sim->dt = h.clock[2];
    sim->dt_next = h.clock[3];
done:
    free(data);
    return st;
}
