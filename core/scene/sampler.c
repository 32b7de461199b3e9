/* Particle samplers (see sampler.h). */
#include "core/scene/sampler.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/rng.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

int sampling_kind_from_string(const char *s, SamplingKind *out)
{
    if (strcmp(s, "poisson") == 0)
        *out = SAMPLING_POISSON;
    else if (strcmp(s, "random") == 0)
        *out = SAMPLING_RANDOM;
    else if (strcmp(s, "lattice") == 0)
        *out = SAMPLING_LATTICE;
    else
        return 0;
    return 1;
}

const char *sampling_kind_name(SamplingKind k)
{
    return k == SAMPLING_POISSON ? "poisson" : k == SAMPLING_RANDOM ? "random" : "lattice";
}

/* ======================================================================
 * Point buffers
 * ====================================================================== */

typedef struct {
    double *x;
    size_t n, cap;
} Buf;

static int buf_push(Buf *b, const double p[3])
{
    if (b->n == b->cap) {
        size_t c = b->cap ? 2 * b->cap : 256;
        double *q = realloc(b->x, 3 * c * sizeof(double));
        if (!q) return MPM_EINTERNAL;
        b->x = q;
        b->cap = c;
    }
    memcpy(b->x + 3 * b->n++, p, 3 * sizeof(double));
    return MPM_OK;
}

static int out_reserve(SamplePoints *o, size_t extra)
{
    size_t need = o->n + extra;
    if (need <= o->cap) return MPM_OK;
    size_t c = o->cap ? o->cap : 1024;
    while (c < need) c *= 2;
    double *q = realloc(o->x, 3 * c * sizeof(double));
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory sampling %zu particles", need);
    o->x = q;
    o->cap = c;
    return MPM_OK;
}

/* Appends the task buffers to out in task order (determinism), up to
 * `limit` points in total (SIZE_MAX: all), and frees them. */
static int gather(Buf *bufs, size_t nb, SamplePoints *out, size_t limit)
{
    size_t total = 0;
    for (size_t k = 0; k < nb; ++k) total += bufs[k].n;
    int st = MPM_OK;
    if (total > limit - out->n) total = limit - out->n;
    st = out_reserve(out, total);
    for (size_t k = 0; k < nb; ++k) {
        if (!st) {
            size_t take = bufs[k].n;
            if (take > limit - out->n) take = limit - out->n;
            if (take) memcpy(out->x + 3 * out->n, bufs[k].x, 3 * take * sizeof(double));
            out->n += take;
        }
        free(bufs[k].x);
        bufs[k].x = NULL;
        bufs[k].n = bufs[k].cap = 0;
    }
    return st;
}

void sample_points_free(SamplePoints *p)
{
    free(p->x);
    memset(p, 0, sizeof *p);
}

/* ======================================================================
 * Periodic Poisson-disk tile (Bridson 2007, periodic variant)
 *
 * Background grid of G^3 cells of edge a = 1/sqrt(3), period L = G a: a
 * cell's diagonal equals the minimum distance 1, so a cell holds at most
 * one sample and a conflicting sample lies within +-2 cells. From a random
 * active sample, up to K candidates are drawn uniformly (by volume) in the
 * spherical shell of radii [1, 2]; the first one farther than 1 from every
 * sample (minimum-image periodic distance) is accepted and becomes active;
 * after K failures the sample is retired. The process ends when no sample is
 * active, giving a maximal-in-practice blue-noise set.
 * ====================================================================== */

enum { TILE_G = 96, TILE_K = 30 };

struct PoissonTile {
    double *x;
    size_t n;
    double L;
};

size_t poisson_tile_count(const PoissonTile *t) { return t->n; }
double poisson_tile_period(const PoissonTile *t) { return t->L; }
const double *poisson_tile_points(const PoissonTile *t) { return t->x; }

void poisson_tile_free(PoissonTile *t)
{
    if (!t) return;
    free(t->x);
    free(t);
}

static inline int wrapi(int i, int G) { return i < 0 ? i + G : (i >= G ? i - G : i); }

static inline double wrapd(double d, double L)
{
    if (d > 0.5 * L) return d - L;
    if (d < -0.5 * L) return d + L;
    return d;
}

int poisson_tile_create(uint64_t seed, PoissonTile **out)
{
    *out = NULL;
    const int G = TILE_G;
    const double a = 1.0 / sqrt(3.0), L = G * a;
    size_t ncell = (size_t)G * G * G;
    /* cell -> coordinates of its sample (x = NAN when empty) */
    double *cell = malloc(3 * ncell * sizeof(double));
    /* Upper bound on the count: spheres of radius 1/2 packed at density
     * pi/sqrt(18) -> 0.74 / (pi/6) = 1.414 per unit volume. */
    size_t cap = (size_t)(1.5 * L * L * L) + 16;
    double *x = malloc(3 * cap * sizeof(double));
    size_t *active = malloc(cap * sizeof(size_t));
    PoissonTile *t = malloc(sizeof *t);
    if (!cell || !x || !active || !t) {
        free(cell), free(x), free(active), free(t);
        return mpm_error(MPM_EINTERNAL, "out of memory generating the Poisson tile");
    }
    for (size_t k = 0; k < 3 * ncell; ++k) cell[k] = NAN; /* all three coordinates: no uninitialised reads */

    /* neighbour cell offsets that can hold a conflicting sample, near first */
    int off[125][3], noff = 0;
    long loff[125];
    for (int pass = 0; pass <= 2; ++pass)
        for (int i = -2; i <= 2; ++i)
            for (int j = -2; j <= 2; ++j)
                for (int k = -2; k <= 2; ++k) {
                    int gi = abs(i) > 0 ? abs(i) - 1 : 0, gj = abs(j) > 0 ? abs(j) - 1 : 0,
                        gk = abs(k) > 0 ? abs(k) - 1 : 0;
                    int g2 = gi * gi + gj * gj + gk * gk; /* (min gap / a)^2 */
                    if (g2 != pass) continue;             /* g2 >= 3: gap >= 1, never conflicts */
                    off[noff][0] = i, off[noff][1] = j, off[noff][2] = k;
                    loff[noff] = ((long)k * G + j) * G + i;
                    ++noff;
                }

    Rng rng;
    rng_seed(&rng, rng_mix(seed, 0x7011E5EEDull));
    size_t n = 0, nactive = 0;
    {
        double p[3] = {rng_uniform(&rng, 0, L), rng_uniform(&rng, 0, L), rng_uniform(&rng, 0, L)};
        int c[3];
        for (int d = 0; d < 3; ++d) {
            c[d] = (int)(p[d] / a);
            if (c[d] >= G) c[d] = G - 1;
        }
        memcpy(x, p, sizeof p);
        memcpy(cell + 3 * (((size_t)c[2] * G + (size_t)c[1]) * G + (size_t)c[0]), p, sizeof p);
        active[nactive++] = 0;
        n = 1;
    }
    while (nactive > 0) {
        size_t ai = (size_t)rng_below(&rng, nactive);
        double base[3];
        memcpy(base, x + 3 * active[ai], sizeof base);
        int placed = 0;
        for (int attempt = 0; attempt < TILE_K && !placed; ++attempt) {
            /* uniform (by volume) in the shell 1 <= |d| <= 2: rejection from
             * the cube [-2, 2]^3 (acceptance 7/6 pi / 8 = 46%) */
            double e[3], e2;
            do {
                for (int d = 0; d < 3; ++d) e[d] = rng_uniform(&rng, -2.0, 2.0);
                e2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
            } while (e2 < 1.0 || e2 > 4.0);
            double p[3] = {base[0] + e[0], base[1] + e[1], base[2] + e[2]};
            int c[3], interior = 1;
            for (int d = 0; d < 3; ++d) {
                if (p[d] < 0) p[d] += L;
                if (p[d] >= L) p[d] -= L;
                if (p[d] >= L || p[d] < 0) p[d] = 0.0; /* round-off guard */
                c[d] = (int)(p[d] / a);
                if (c[d] >= G) c[d] = G - 1;
                if (c[d] < 2 || c[d] >= G - 2) interior = 0;
            }
            size_t home = ((size_t)c[2] * G + (size_t)c[1]) * G + (size_t)c[0];
            if (!isnan(cell[3 * home])) continue; /* same cell: closer than 1 */
            int ok = 1;
            if (interior) {
                for (int q = 0; q < noff; ++q) {
                    const double *o = cell + 3 * (size_t)((long)home + loff[q]);
                    double d0 = p[0] - o[0], d1 = p[1] - o[1], d2 = p[2] - o[2];
                    if (d0 * d0 + d1 * d1 + d2 * d2 < 1.0) { /* false for NAN (empty) */
                        ok = 0;
                        break;
                    }
                }
            } else {
                for (int q = 0; q < noff; ++q) {
                    size_t id = ((size_t)wrapi(c[2] + off[q][2], G) * G + (size_t)wrapi(c[1] + off[q][1], G)) * G +
                                (size_t)wrapi(c[0] + off[q][0], G);
                    const double *o = cell + 3 * id;
                    if (isnan(o[0])) continue;
                    double d0 = wrapd(p[0] - o[0], L), d1 = wrapd(p[1] - o[1], L), d2 = wrapd(p[2] - o[2], L);
                    if (d0 * d0 + d1 * d1 + d2 * d2 < 1.0) {
                        ok = 0;
                        break;
                    }
                }
            }
            if (!ok || n >= cap) continue;
            memcpy(x + 3 * n, p, sizeof p);
            memcpy(cell + 3 * home, p, sizeof p);
            active[nactive++] = n;
            ++n;
            placed = 1;
        }
        if (!placed) active[ai] = active[--nactive];
    }
    free(cell);
    free(active);
    t->x = x;
    t->n = n;
    t->L = L;
    *out = t;
    return MPM_OK;
}

enum { TILE_CACHE = 8 };
static struct {
    uint64_t seed;
    PoissonTile *tile;
} g_tile_cache[TILE_CACHE];

const PoissonTile *poisson_tile_shared(uint64_t seed)
{
    const PoissonTile *found = NULL;
#pragma omp critical(mpm_poisson_tile_cache)
    {
        int k = 0;
        for (; k < TILE_CACHE && g_tile_cache[k].tile; ++k)
            if (g_tile_cache[k].seed == seed) {
                found = g_tile_cache[k].tile;
                break;
            }
        if (!found && k < TILE_CACHE) {
            PoissonTile *t = NULL;
            if (poisson_tile_create(seed, &t) == MPM_OK) {
                g_tile_cache[k].seed = seed;
                g_tile_cache[k].tile = t;
                found = t;
            }
        }
    }
    return found;
}

double sampler_poisson_min_distance(const PoissonTile *t, double dx, double ppc)
{
    double density = (double)t->n / (t->L * t->L * t->L); /* samples per unit^3 */
    return cbrt(density * dx * dx * dx / (SAMPLER_DENSITY * ppc));
}

/* ======================================================================
 * Samplers
 * ====================================================================== */

static int inside(const Shape *s, const double lo[3], const double hi[3], const double p[3])
{
    for (int d = 0; d < 3; ++d)
        if (p[d] < lo[d] || p[d] > hi[d]) return 0;
    return shape_contains(s, p);
}

enum { CHUNK = 4096 };

static int sample_poisson(const Shape *s, const double lo[3], const double hi[3], double dx, double ppc,
                          const PoissonTile *t, SamplePoints *out)
{
    double sc = sampler_poisson_min_distance(t, dx, ppc), P = t->L * sc;
    long c0[3], nc[3];
    double ncopies = 1.0;
    for (int d = 0; d < 3; ++d) {
        double f0 = floor(lo[d] / P), f1 = floor(hi[d] / P);
        if (!(fabs(f0) < 1e15 && fabs(f1) < 1e15))
            return mpm_error(MPM_EINPUT, "shape bounds too far from the origin to sample");
        c0[d] = (long)f0;
        nc[d] = (long)f1 - (long)f0 + 1;
        ncopies *= (double)nc[d];
    }
    size_t nchunk = (t->n + CHUNK - 1) / CHUNK;
    if (ncopies * (double)nchunk > 1e6)
        return mpm_error(MPM_EINPUT, "shape too large to sample at dx %g (%.3g tile copies)", dx, ncopies);
    size_t ntask = (size_t)ncopies * nchunk;
    Buf *bufs = calloc(ntask, sizeof(Buf));
    if (!bufs) return mpm_error(MPM_EINTERNAL, "out of memory sampling");
    int fail = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(| : fail)
    for (size_t task = 0; task < ntask; ++task) {
        size_t copy = task / nchunk, chunk = task % nchunk;
        long ci = c0[0] + (long)(copy % (size_t)nc[0]);
        long cj = c0[1] + (long)((copy / (size_t)nc[0]) % (size_t)nc[1]);
        long ck = c0[2] + (long)(copy / ((size_t)nc[0] * (size_t)nc[1]));
        double org[3] = {(double)ci * P, (double)cj * P, (double)ck * P};
        size_t end = (chunk + 1) * CHUNK < t->n ? (chunk + 1) * CHUNK : t->n;
        for (size_t k = chunk * CHUNK; k < end; ++k) {
            const double *u = t->x + 3 * k;
            double p[3] = {org[0] + u[0] * sc, org[1] + u[1] * sc, org[2] + u[2] * sc};
            if (inside(s, lo, hi, p) && buf_push(&bufs[task], p)) fail = 1;
        }
    }
    int st = fail ? mpm_error(MPM_EINTERNAL, "out of memory sampling") : MPM_OK;
    int st2 = gather(bufs, ntask, out, (size_t)-1);
    free(bufs);
    if (!st) st = st2;
    out->min_dist = sc;
    return st;
}

static int sample_random(const Shape *s, const double lo[3], const double hi[3], double dx, double ppc,
                         uint64_t seed, SamplePoints *out)
{
    double vol = shape_volume(s);
    double want = SAMPLER_DENSITY * ppc * vol / (dx * dx * dx);
    if (!(want < 1e10)) return mpm_error(MPM_EINPUT, "random sampling: %.3g particles requested", want);
    size_t N = (size_t)llround(want);
    double box = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    /* Candidates are generated in fixed blocks with their own streams, in
     * batches evaluated in parallel and accepted in block order. */
    const size_t block = CHUNK, batch = 64;
    size_t target = out->n + N, blk = 0;
    double max_candidates = 200.0 * (double)N * fmax(1.0, box / fmax(vol, 1e-300)) + 1e6;
    Buf bufs[64];
    memset(bufs, 0, sizeof bufs);
    while (out->n < target) {
        if ((double)(blk * block) > max_candidates)
            return mpm_error(MPM_EINPUT, "random sampling: shape fills too little of its bounds");
        int fail = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(| : fail)
        for (size_t b = 0; b < batch; ++b) {
            Rng r;
            rng_seed(&r, rng_mix(seed, blk + b));
            for (size_t k = 0; k < block; ++k) {
                double p[3] = {rng_uniform(&r, lo[0], hi[0]), rng_uniform(&r, lo[1], hi[1]),
                               rng_uniform(&r, lo[2], hi[2])};
                if (shape_contains(s, p) && buf_push(&bufs[b], p)) fail = 1;
            }
        }
        blk += batch;
        int st = gather(bufs, batch, out, target);
        if (fail) return mpm_error(MPM_EINTERNAL, "out of memory sampling");
        if (st) return st;
    }
    out->min_dist = 0.0;
    return MPM_OK;
}

static int sample_lattice(const Shape *s, const double lo[3], const double hi[3], double dx, double ppc,
                          SamplePoints *out)
{
    double kr = cbrt(ppc);
    int k = (int)llround(kr);
    if (k < 1 || fabs((double)k * k * k - ppc) > 1e-9 * ppc)
        return mpm_error(MPM_EINPUT, "lattice sampling needs ppc = k^3 (1, 8, 27, ...), got %g", ppc);
    long i0[3], n[3];
    double cells = 1.0;
    for (int d = 0; d < 3; ++d) {
        i0[d] = (long)floor(lo[d] / dx);
        n[d] = (long)floor(hi[d] / dx) - i0[d] + 1;
        cells *= (double)n[d];
    }
    if (cells * ppc > 1e10) return mpm_error(MPM_EINPUT, "lattice sampling: %.3g candidates", cells * ppc);
    size_t nslab = (size_t)n[2] * (size_t)k; /* one task per sub-lattice z plane */
    Buf *bufs = calloc(nslab, sizeof(Buf));
    if (!bufs) return mpm_error(MPM_EINTERNAL, "out of memory sampling");
    int fail = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(| : fail)
    for (size_t slab = 0; slab < nslab; ++slab) {
        double z = ((double)(i0[2] + (long)(slab / (size_t)k)) + ((double)(slab % (size_t)k) + 0.5) / k) * dx;
        for (long j = 0; j < n[1] * k; ++j) {
            double y = ((double)(i0[1] + j / k) + ((double)(j % k) + 0.5) / k) * dx;
            for (long i = 0; i < n[0] * k; ++i) {
                double x = ((double)(i0[0] + i / k) + ((double)(i % k) + 0.5) / k) * dx;
                double p[3] = {x, y, z};
                if (inside(s, lo, hi, p) && buf_push(&bufs[slab], p)) fail = 1;
            }
        }
    }
    int st = gather(bufs, nslab, out, (size_t)-1);
    free(bufs);
    if (fail) return mpm_error(MPM_EINTERNAL, "out of memory sampling");
    out->min_dist = dx / k;
    return st;
}

/* Surface points: candidates uniform in the bounds (grown by h) in fixed
 * blocks with their own random streams, kept when |phi| < h, projected onto
 * phi = 0 along the (central-difference) gradient. A shell of constant
 * half-width h around a smooth surface has volume 2 h area, and projecting
 * its points along the normal spreads them uniformly by area up to
 * O((h curvature)^2), because the shell is symmetric about the surface. */
static int project_to_surface(const Shape *s, double h, double p[3])
{
    double phi = shape_sdf(s, p), e = 1e-3 * h;
    for (int it = 0; it < 8; ++it) {
        if (fabs(phi) <= 1e-6 * h) return 1;
        double g[3], n2 = 0.0;
        for (int d = 0; d < 3; ++d) {
            double a[3] = {p[0], p[1], p[2]}, b[3] = {p[0], p[1], p[2]};
            a[d] += e;
            b[d] -= e;
            g[d] = (shape_sdf(s, a) - shape_sdf(s, b)) / (2.0 * e);
            n2 += g[d] * g[d];
        }
        if (!(n2 > 1e-12) || !isfinite(n2)) return 0;
        for (int d = 0; d < 3; ++d) p[d] -= phi * g[d] / n2;
        phi = shape_sdf(s, p);
    }
    return fabs(phi) <= 1e-3 * h;
}

int sampler_surface(const Shape *shape, size_t n, double h, uint64_t seed, SamplePoints *out)
{
    if (!(h > 0) || !isfinite(h)) return mpm_error(MPM_EINPUT, "surface sampling: h must be positive, got %g", h);
    if (!shape_is_bounded(shape))
        return mpm_error(MPM_EINPUT, "cannot sample the surface of an unbounded shape (%s)", shape_type_name(shape));
    if (n == 0) return MPM_OK;
    double lo[3], hi[3];
    shape_bounds(shape, lo, hi);
    for (int d = 0; d < 3; ++d) {
        if (!(hi[d] >= lo[d])) return mpm_error(MPM_EINPUT, "surface sampling: empty shape");
        lo[d] -= h;
        hi[d] += h;
    }
    const size_t block = CHUNK, batch = 64;
    size_t target = out->n + n, blk = 0;
    double max_candidates = 1e5 * (double)n + 1e7;
    Buf bufs[64];
    memset(bufs, 0, sizeof bufs);
    while (out->n < target) {
        if ((double)(blk * block) > max_candidates)
            return mpm_error(MPM_EINPUT, "surface sampling: too few candidates reach the surface (h = %g)", h);
        int fail = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(| : fail)
        for (size_t b = 0; b < batch; ++b) {
            Rng r;
            rng_seed(&r, rng_mix(seed, blk + b));
            for (size_t k = 0; k < block; ++k) {
                double p[3] = {rng_uniform(&r, lo[0], hi[0]), rng_uniform(&r, lo[1], hi[1]),
                               rng_uniform(&r, lo[2], hi[2])};
                if (fabs(shape_sdf(shape, p)) >= h) continue;
                if (project_to_surface(shape, h, p) && buf_push(&bufs[b], p)) fail = 1;
            }
        }
        blk += batch;
        int st = gather(bufs, batch, out, target);
        if (fail) return mpm_error(MPM_EINTERNAL, "out of memory sampling");
        if (st) return st;
    }
    return MPM_OK;
}

int sampler_sample(const Shape *shape, SamplingKind kind, double dx, double ppc, uint64_t seed,
                   const PoissonTile *tile, SamplePoints *out)
{
    if (!(dx > 0) || !isfinite(dx)) return mpm_error(MPM_EINPUT, "sampling: dx must be positive, got %g", dx);
    if (!(ppc > 0) || !isfinite(ppc)) return mpm_error(MPM_EINPUT, "sampling: ppc must be positive, got %g", ppc);
    if (!shape_is_bounded(shape))
        return mpm_error(MPM_EINPUT, "cannot sample an unbounded shape (%s)", shape_type_name(shape));
    double lo[3], hi[3];
    shape_bounds(shape, lo, hi);
    for (int d = 0; d < 3; ++d)
        if (!(hi[d] >= lo[d])) return MPM_OK; /* empty (e.g. disjoint intersection) */
    switch (kind) {
    case SAMPLING_POISSON: {
        if (!tile) tile = poisson_tile_shared(seed);
        if (tile) return sample_poisson(shape, lo, hi, dx, ppc, tile, out);
        PoissonTile *t = NULL;
        int st = poisson_tile_create(seed, &t);
        if (st) return st;
        st = sample_poisson(shape, lo, hi, dx, ppc, t, out);
        poisson_tile_free(t);
        return st;
    }
    case SAMPLING_RANDOM: return sample_random(shape, lo, hi, dx, ppc, seed, out);
    case SAMPLING_LATTICE: return sample_lattice(shape, lo, hi, dx, ppc, out);
    }
    return mpm_error(MPM_EINTERNAL, "sampler: unknown kind %d", (int)kind);
}
