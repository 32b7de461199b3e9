#include "core/particles.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

static int grow(void **ptr, size_t elem, size_t cap)
{
    void *q = realloc(*ptr, elem * cap);
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory growing particles to %zu", cap);
    *ptr = q;
    return MPM_OK;
}

int particles_reserve(Particles *p, size_t cap)
{
    if (cap <= p->cap) return MPM_OK;
    size_t c = p->cap ? p->cap : 1024;
    while (c < cap) c *= 2;
    int st = 0;
    st |= grow((void **)&p->x, 3 * sizeof(double), c);
    st |= grow((void **)&p->v, 3 * sizeof(double), c);
    st |= grow((void **)&p->C, 9 * sizeof(double), c);
    st |= grow((void **)&p->F, 9 * sizeof(double), c);
    st |= grow((void **)&p->mass, sizeof(double), c);
    st |= grow((void **)&p->vol, sizeof(double), c);
    st |= grow((void **)&p->mat, sizeof(int), c);
    if (p->Jp) st |= grow((void **)&p->Jp, sizeof(double), c);
    st |= grow((void **)&p->id, sizeof(size_t), c);
    if (st) return MPM_EINTERNAL;
    /* defined values for particles filled without particles_push (multigrid levels) */
    memset(p->id + p->cap, 0, sizeof(size_t) * (c - p->cap));
    p->cap = c;
    return MPM_OK;
}

int particles_push(Particles *p, const double x[3], const double v[3], double mass, double vol, int mat)
{
    int st = particles_reserve(p, p->n + 1);
    if (st) return st;
    size_t k = p->n++;
    memcpy(p->x + 3 * k, x, 3 * sizeof(double));
    memcpy(p->v + 3 * k, v, 3 * sizeof(double));
    memset(p->C + 9 * k, 0, 9 * sizeof(double));
    double *F = p->F + 9 * k;
    memset(F, 0, 9 * sizeof(double));
    F[0] = F[4] = F[8] = 1.0;
    p->mass[k] = mass;
    p->vol[k] = vol;
    p->mat[k] = mat;
    if (p->Jp) p->Jp[k] = 1.0;
    p->id[k] = k;
    return MPM_OK;
}

int particles_copy(Particles *dst, const Particles *src)
{
    int st = particles_reserve(dst, src->n);
    if (st) return st;
    if (src->Jp && (st = particles_enable_plastic_state(dst))) return st;
    size_t n = src->n;
    dst->n = n;
    if (n == 0) return MPM_OK; /* a scene that starts empty (sources only): no arrays yet */
    memcpy(dst->x, src->x, sizeof(double) * 3 * n);
    memcpy(dst->v, src->v, sizeof(double) * 3 * n);
    memcpy(dst->C, src->C, sizeof(double) * 9 * n);
    memcpy(dst->F, src->F, sizeof(double) * 9 * n);
    memcpy(dst->mass, src->mass, sizeof(double) * n);
    memcpy(dst->vol, src->vol, sizeof(double) * n);
    memcpy(dst->mat, src->mat, sizeof(int) * n);
    if (src->Jp) memcpy(dst->Jp, src->Jp, sizeof(double) * n);
    memcpy(dst->id, src->id, sizeof(size_t) * n);
    return MPM_OK;
}

int particles_enable_plastic_state(Particles *p)
{
    if (p->Jp) return MPM_OK;
    p->Jp = malloc(sizeof(double) * (p->cap ? p->cap : 1));
    if (!p->Jp) return mpm_error(MPM_EINTERNAL, "out of memory allocating plastic state");
    for (size_t k = 0; k < p->n; ++k) p->Jp[k] = 1.0;
    return MPM_OK;
}

static void permute_field(double *f, size_t width, size_t n, const size_t *perm, double *scratch)
{
    for (size_t k = 0; k < n; ++k) memcpy(scratch + width * k, f + width * perm[k], width * sizeof(double));
    memcpy(f, scratch, width * n * sizeof(double));
}

void particles_permute(Particles *p, const size_t *perm, double *scratch)
{
    size_t n = p->n;
    if (n == 0) return;
    permute_field(p->x, 3, n, perm, scratch);
    permute_field(p->v, 3, n, perm, scratch);
    permute_field(p->C, 9, n, perm, scratch);
    permute_field(p->F, 9, n, perm, scratch);
    permute_field(p->mass, 1, n, perm, scratch);
    permute_field(p->vol, 1, n, perm, scratch);
    if (p->Jp) permute_field(p->Jp, 1, n, perm, scratch);
    int *mi = (int *)scratch;
    for (size_t k = 0; k < n; ++k) mi[k] = p->mat[perm[k]];
    memcpy(p->mat, mi, n * sizeof(int));
    if (!p->id) return;
    size_t *ids = (size_t *)scratch;
    for (size_t k = 0; k < n; ++k) ids[k] = p->id[perm[k]];
    memcpy(p->id, ids, n * sizeof(size_t));
}

void particles_free(Particles *p)
{
    free(p->x);
    free(p->v);
    free(p->C);
    free(p->F);
    free(p->mass);
    free(p->vol);
    free(p->mat);
    free(p->Jp);
    free(p->id);
    memset(p, 0, sizeof *p);
}
