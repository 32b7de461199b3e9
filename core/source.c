/* Particle sources (format and semantics in source.h). */
#include "core/source.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/mat3.h"

static atomic_ullong g_examined;

unsigned long long source_samples_examined(void) { return atomic_load(&g_examined); }

void source_free(Source *s)
{
    if (!s) return;
    collider_free(&s->pose);
    free(s->X);
    memset(s, 0, sizeof *s);
}

int source_active(const Source *s, double t0)
{
    double tol_until = 1e-9 * fmax(1.0, fabs(s->until)), tol_from = 1e-9 * fmax(1.0, fabs(s->from));
    return t0 >= s->from - tol_from && t0 < s->until - tol_until;
}

/* Rest-frame position of sample k at a displacement whose remainder modulo
 * the wrap period is Dm (in [0, period) on wrapped axes, 0 elsewhere); the
 * stored samples lie in [box_lo, box_lo + period) on wrapped axes. */
static inline void displaced(const Source *s, size_t k, const double Dm[3], double X[3])
{
    for (int d = 0; d < 3; ++d) {
        double x = s->X[3 * k + d];
        if (s->wrap[d]) {
            double r = x - s->box_lo[d] + Dm[d];
            if (r >= s->period[d]) r -= s->period[d];
            x = s->box_lo[d] + r;
        }
        X[d] = x;
    }
}

int source_emit(const Source *s, Particles *p, double t0, double dt, size_t *n_emitted)
{
    if (n_emitted) *n_emitted = 0;
    if (!source_active(s, t0) || !(dt > 0)) return MPM_OK;
    atomic_fetch_add(&g_examined, (unsigned long long)s->n);
    /* a sample at its wrapped position X0 at t0 moves to X0 + step at t1 (not
     * wrapped again: leaving the box means leaving the shape) */
    double t1 = t0 + dt, D0[3], step[3];
    for (int d = 0; d < 3; ++d) {
        D0[d] = 0.0;
        if (s->wrap[d]) {
            D0[d] = fmod(s->velocity[d] * (t0 - s->from), s->period[d]);
            if (D0[d] < 0) D0[d] += s->period[d];
            if (D0[d] >= s->period[d]) D0[d] = 0.0;
        }
        step[d] = s->velocity[d] * dt;
    }
    unsigned char *flag = malloc(s->n ? s->n : 1);
    if (!flag) return mpm_error(MPM_EINTERNAL, "out of memory emitting from source %s", s->name);
    const LevelSet *shape = &s->pose.shape;
    size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (size_t k = 0; k < s->n; ++k) {
        double X0[3], X1[3];
        displaced(s, k, D0, X0);
        for (int d = 0; d < 3; ++d) X1[d] = X0[d] + step[d];
        flag[k] = level_set_contains(shape, X0) && !level_set_contains(shape, X1);
        count += flag[k];
    }
    int st = particles_reserve(p, p->n + count);
    if (!st && count) {
        double R[9], b[3], v[3];
        collider_pose(&s->pose, t1, R, b);
        m3_mulv(R, s->velocity, v);
        const double *c = s->pose.pivot0;
        for (size_t k = 0; k < s->n && !st; ++k) {
            if (!flag[k]) continue;
            double X[3], r[3], x[3];
            displaced(s, k, D0, X);
            for (int d = 0; d < 3; ++d) r[d] = X[d] + step[d] - c[d];
            m3_mulv(R, r, x);
            for (int d = 0; d < 3; ++d) x[d] += c[d] + b[d];
            st = particles_push(p, x, v, s->mass, s->vol, s->mat);
        }
    }
    free(flag);
    if (!st && n_emitted) *n_emitted = count;
    return st;
}

int source_emit_all(const Source *src, int n_src, Particles *p, double t0, double dt)
{
    for (int k = 0; k < n_src; ++k) {
        int st = source_emit(&src[k], p, t0, dt, NULL);
        if (st) return st;
    }
    return MPM_OK;
}
