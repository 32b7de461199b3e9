/* floor: scene */
/* Samplers: Poisson minimum distance (tile and cut, across tile seams),
 * realised density 0.868 ppc per dx^3 within 5%, determinism for a seed,
 * random and lattice counts, surface points (on the surface, spread by
 * area), bad input, and the speed of a ~1e6 cut. */
#include <jansson.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/sampler.h"
#include "core/scene/shape.h"
#include "tests/common/testutil.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static Shape *make(const char *json)
{
    json_error_t e;
    json_t *j = json_loads(json, 0, &e);
    Shape *s = NULL;
    mpm_clear_error();
    if (!j || shape_parse(j, "t.json", "shape", NULL, 0.05, &s)) fprintf(stderr, "shape: %s\n", mpm_last_error());
    json_decref(j);
    return s;
}

/* Smallest pairwise distance by brute force. */
static double min_pair(const SamplePoints *p)
{
    double m2 = HUGE_VAL;
    for (size_t a = 0; a < p->n; ++a)
        for (size_t b = a + 1; b < p->n; ++b) {
            double d0 = p->x[3 * a] - p->x[3 * b], d1 = p->x[3 * a + 1] - p->x[3 * b + 1],
                   d2 = p->x[3 * a + 2] - p->x[3 * b + 2];
            double d = d0 * d0 + d1 * d1 + d2 * d2;
            if (d < m2) m2 = d;
        }
    return sqrt(m2);
}

static void test_tile(const PoissonTile *t)
{
    /* periodic minimum distance over the whole tile, via a unit-cell hash */
    size_t n = poisson_tile_count(t);
    double L = poisson_tile_period(t);
    const double *x = poisson_tile_points(t);
    int G = (int)floor(L); /* cells of edge L/G >= 1 */
    double a = L / G;
    int *head = malloc(sizeof(int) * (size_t)G * G * G), *next = malloc(sizeof(int) * n);
    for (int k = 0; k < G * G * G; ++k) head[k] = -1;
    int bad_range = 0;
    for (size_t k = 0; k < n; ++k) {
        int c[3];
        for (int d = 0; d < 3; ++d) {
            if (!(x[3 * k + d] >= 0 && x[3 * k + d] < L)) bad_range++;
            c[d] = (int)(x[3 * k + d] / a) % G;
        }
        int id = (c[2] * G + c[1]) * G + c[0];
        next[k] = head[id];
        head[id] = (int)k;
    }
    double m2 = HUGE_VAL;
    for (size_t k = 0; k < n; ++k) {
        int c[3];
        for (int d = 0; d < 3; ++d) c[d] = (int)(x[3 * k + d] / a) % G;
        for (int i = -1; i <= 1; ++i)
            for (int j = -1; j <= 1; ++j)
                for (int l = -1; l <= 1; ++l) {
                    int id = (((c[2] + l + G) % G) * G + (c[1] + j + G) % G) * G + (c[0] + i + G) % G;
                    for (int q = head[id]; q >= 0; q = next[q]) {
                        if ((size_t)q == k) continue;
                        double d2 = 0;
                        for (int d = 0; d < 3; ++d) {
                            double e = x[3 * k + d] - x[3 * (size_t)q + d];
                            e -= L * round(e / L);
                            d2 += e * e;
                        }
                        if (d2 < m2) m2 = d2;
                    }
                }
    }
    free(head);
    free(next);
    double density = (double)n / (L * L * L);
    printf("tile: %zu points, period %.3f, density %.4f per unit^3, periodic min distance %.6f\n", n, L, density,
           sqrt(m2));
    CHECK(bad_range == 0, "points inside the period");
    CHECK(sqrt(m2) >= 1.0 - 1e-12, "tile min distance %g", sqrt(m2));
    /* Bridson in 3D gives about 0.58 samples per unit^3; far lower would mean gaps */
    CHECK(density > 0.5 && density < 0.7, "tile density %g", density);
}

static void test_poisson(const PoissonTile *t)
{
    /* a box straddling the world origin crosses tile seams on every axis */
    Shape *box = make("{\"type\":\"box\",\"min\":[-0.15,-0.15,-0.15],\"max\":[0.15,0.15,0.15]}");
    const double dx = 0.05, ppc = 8;
    SamplePoints p;
    memset(&p, 0, sizeof p);
    int st = sampler_sample(box, SAMPLING_POISSON, dx, ppc, 1, t, &p);
    CHECK(st == 0, "poisson sample");
    double r = sampler_poisson_min_distance(t, dx, ppc), rref = cbrt(13.0 / 18.0 * dx * dx * dx / ppc);
    double mind = min_pair(&p);
    printf("poisson: r = %.6f dx (HOT formula %.6f dx, ratio %.4f), measured min %.6f dx\n", r / dx, rref / dx,
           r / rref, mind / dx);
    CHECK(fabs(p.min_dist - r) < 1e-15, "reported min distance");
    CHECK(mind >= r * (1 - 1e-9), "min distance %g < %g", mind, r);
    CHECK(r > 0.9 * rref && r < 1.1 * rref, "radius near the HOT formula");
    double expect = SAMPLER_DENSITY * ppc * 0.027 / (dx * dx * dx);
    CHECK(fabs(p.n / expect - 1) < 0.05, "box density: %zu vs %g", p.n, expect);
    int outside = 0;
    for (size_t k = 0; k < p.n; ++k)
        if (shape_sdf(box, p.x + 3 * k) > 0) ++outside;
    CHECK(outside == 0, "all inside");

    /* determinism: same tile seed -> same points; other seed -> other points */
    SamplePoints q;
    memset(&q, 0, sizeof q);
    sampler_sample(box, SAMPLING_POISSON, dx, ppc, 1, NULL, &q); /* fresh tile from seed 1 */
    CHECK(q.n == p.n && memcmp(q.x, p.x, 3 * p.n * sizeof(double)) == 0, "same seed, same samples");
    sample_points_free(&q);
    sampler_sample(box, SAMPLING_POISSON, dx, ppc, 2, NULL, &q);
    CHECK(!(q.n == p.n && memcmp(q.x, p.x, 3 * p.n * sizeof(double)) == 0), "other seed, other samples");
    CHECK(fabs(q.n / expect - 1) < 0.05, "seed 2 density: %zu vs %g", q.n, expect);
    sample_points_free(&q);
    sample_points_free(&p);

    /* density in a larger box and a sphere, several ppc */
    Shape *big = make("{\"type\":\"box\",\"min\":[0.3,0.7,-0.2],\"max\":[0.8,1.2,0.3]}");
    Shape *sph = make("{\"type\":\"sphere\",\"center\":[1,2,3],\"radius\":0.3}");
    double ppcs[3] = {8, 12, 16};
    for (int k = 0; k < 3; ++k) {
        memset(&p, 0, sizeof p);
        sampler_sample(big, SAMPLING_POISSON, dx, ppcs[k], 1, t, &p);
        double e = SAMPLER_DENSITY * ppcs[k] * 0.125 / (dx * dx * dx);
        printf("poisson box ppc %g: %zu samples, %.4f ppc per dx^3 (target %.4f)\n", ppcs[k], p.n,
               p.n / (0.125 / (dx * dx * dx)) / ppcs[k], SAMPLER_DENSITY);
        CHECK(fabs(p.n / e - 1) < 0.05, "ppc %g box: %zu vs %g", ppcs[k], p.n, e);
        sample_points_free(&p);
        memset(&p, 0, sizeof p);
        sampler_sample(sph, SAMPLING_POISSON, dx, ppcs[k], 1, t, &p);
        e = SAMPLER_DENSITY * ppcs[k] * (4.0 / 3.0 * M_PI * 0.027) / (dx * dx * dx);
        CHECK(fabs(p.n / e - 1) < 0.05, "ppc %g sphere: %zu vs %g", ppcs[k], p.n, e);
        sample_points_free(&p);
    }
    shape_free(big);
    shape_free(sph);
    shape_free(box);
}

static void test_random_lattice(void)
{
    Shape *sph = make("{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":0.2}");
    const double dx = 0.02;
    SamplePoints p, q;
    memset(&p, 0, sizeof p);
    memset(&q, 0, sizeof q);
    CHECK(sampler_sample(sph, SAMPLING_RANDOM, dx, 8, 42, NULL, &p) == 0, "random");
    size_t N = (size_t)llround(SAMPLER_DENSITY * 8 * (4.0 / 3.0 * M_PI * 0.008) / (dx * dx * dx));
    CHECK(p.n == N, "random count %zu vs %zu", p.n, N);
    int outside = 0;
    for (size_t k = 0; k < p.n; ++k)
        if (shape_sdf(sph, p.x + 3 * k) > 0) ++outside;
    CHECK(outside == 0, "random inside");
    /* uniformity: fraction in the inner half-radius ball ~ 1/8 */
    size_t inner = 0;
    for (size_t k = 0; k < p.n; ++k)
        if (p.x[3 * k] * p.x[3 * k] + p.x[3 * k + 1] * p.x[3 * k + 1] + p.x[3 * k + 2] * p.x[3 * k + 2] < 0.01)
            ++inner;
    CHECK(fabs((double)inner / p.n - 0.125) < 0.01, "random uniform: inner fraction %g", (double)inner / p.n);
    CHECK(sampler_sample(sph, SAMPLING_RANDOM, dx, 8, 42, NULL, &q) == 0 && q.n == p.n &&
              memcmp(p.x, q.x, 3 * p.n * sizeof(double)) == 0,
          "random deterministic");
    sample_points_free(&q);
    sample_points_free(&p);

    /* lattice: a grid-aligned box holds exactly ppc per cell */
    Shape *box = make("{\"type\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.1,0.3]}");
    memset(&p, 0, sizeof p);
    CHECK(sampler_sample(box, SAMPLING_LATTICE, 0.01, 8, 0, NULL, &p) == 0, "lattice");
    CHECK(p.n == 20 * 10 * 30 * 8, "lattice count %zu", p.n);
    CHECK(fabs(p.x[0] - 0.0025) < 1e-15 && fabs(p.min_dist - 0.005) < 1e-15, "cell-centred sub-lattice");
    sample_points_free(&p);
    memset(&p, 0, sizeof p);
    CHECK(sampler_sample(sph, SAMPLING_LATTICE, dx, 27, 0, NULL, &p) == 0, "lattice sphere");
    double e = 27 * (4.0 / 3.0 * M_PI * 0.008) / (dx * dx * dx);
    CHECK(fabs(p.n / e - 1) < 0.02, "lattice sphere count %zu vs %g", p.n, e);
    sample_points_free(&p);

    /* bad input */
    memset(&p, 0, sizeof p);
    mpm_clear_error();
    CHECK(sampler_sample(box, SAMPLING_LATTICE, 0.01, 10, 0, NULL, &p) == MPM_EINPUT &&
              strstr(mpm_last_error(), "k^3"),
          "lattice needs a cube ppc");
    Shape *hs = make("{\"type\":\"half_space\",\"point\":[0,0,0],\"normal\":[0,1,0]}");
    mpm_clear_error();
    CHECK(sampler_sample(hs, SAMPLING_POISSON, 0.01, 8, 0, NULL, &p) == MPM_EINPUT, "unbounded");
    mpm_clear_error();
    CHECK(sampler_sample(box, SAMPLING_RANDOM, 0.01, -1, 0, NULL, &p) == MPM_EINPUT, "negative ppc");
    sample_points_free(&p);
    shape_free(hs);
    shape_free(box);
    shape_free(sph);
}

static void test_speed(const PoissonTile *t)
{
    /* ~1.1e6 samples: a 0.5 m cube at dx 0.01, ppc 10 */
    Shape *box = make("{\"type\":\"box\",\"min\":[0,0,0],\"max\":[0.5,0.5,0.5]}");
    SamplePoints p;
    memset(&p, 0, sizeof p);
    double t0 = omp_get_wtime();
    sampler_sample(box, SAMPLING_POISSON, 0.01, 10, 1, t, &p);
    double t1 = omp_get_wtime();
    /* timing is printed for information only (no wall-time assertion: benchmarks measure speed) */
    printf("poisson cut: %zu samples in %.3f s (%d threads)\n", p.n, t1 - t0, omp_get_max_threads());
    CHECK(fabs(p.n / (SAMPLER_DENSITY * 10 * 125000) - 1) < 0.05, "density of the large cut");
    sample_points_free(&p);
    shape_free(box);
}

/* Surface points: on the surface, spread by area (sphere octants, box
 * faces), deterministic, CSG interior surfaces excluded. */
static void test_surface(void)
{
    Shape *sph = make("{\"type\":\"sphere\",\"center\":[0.3,0.2,0.1],\"radius\":0.25}");
    Shape *box = make("{\"type\":\"box\",\"min\":[0,0,0],\"max\":[0.4,0.2,0.1]}");
    Shape *uni = make("{\"type\":\"union\",\"shapes\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":0.2},"
                      "{\"type\":\"sphere\",\"center\":[0.2,0,0],\"radius\":0.2}]}");
    if (!sph || !box || !uni) {
        CHECK(0, "surface test shapes");
        shape_free(sph), shape_free(box), shape_free(uni);
        return;
    }
    const size_t N = 40000;
    SamplePoints a = {0}, b = {0};
    double h = 0.01;
    mpm_clear_error();
    CHECK(sampler_surface(sph, N, h, 5, &a) == 0 && a.n == N, "sphere: %zu points (%s)", a.n, mpm_last_error());
    double worst = 0;
    size_t oct[8] = {0};
    for (size_t k = 0; k < a.n; ++k) {
        double d[3] = {a.x[3 * k] - 0.3, a.x[3 * k + 1] - 0.2, a.x[3 * k + 2] - 0.1};
        worst = fmax(worst, fabs(sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - 0.25));
        oct[(d[0] > 0) + 2 * (d[1] > 0) + 4 * (d[2] > 0)]++;
    }
    CHECK(worst < 1e-3 * h, "sphere points on the surface (max |r - R| %.2e)", worst);
    int oct_ok = 1;
    for (int o = 0; o < 8; ++o)
        if (fabs((double)oct[o] / (N / 8.0) - 1) > 0.05) oct_ok = 0;
    CHECK(oct_ok, "sphere octants equal within 5%%: %zu %zu %zu %zu %zu %zu %zu %zu", oct[0], oct[1], oct[2], oct[3],
          oct[4], oct[5], oct[6], oct[7]);
    CHECK(sampler_surface(sph, N, h, 5, &b) == 0 && b.n == a.n && memcmp(a.x, b.x, 3 * a.n * sizeof(double)) == 0,
          "deterministic for a seed");
    sample_points_free(&a);
    sample_points_free(&b);

    /* box: faces get points in proportion to their areas (0.08, 0.04, 0.02 m^2
     * pairs), up to the edges' share ~ h edge length / area */
    memset(&a, 0, sizeof a);
    CHECK(sampler_surface(box, N, 0.002, 9, &a) == 0 && a.n == N, "box points");
    size_t face[3] = {0, 0, 0}, off = 0;
    const double ext[3] = {0.4, 0.2, 0.1};
    for (size_t k = 0; k < a.n; ++k) {
        int hit = -1;
        for (int d = 0; d < 3; ++d) {
            double x = a.x[3 * k + d];
            if (fabs(x) < 1e-6 || fabs(x - ext[d]) < 1e-6) hit = d;
        }
        if (hit < 0) ++off;
        else ++face[hit];
    }
    double area[3] = {2 * 0.2 * 0.1, 2 * 0.4 * 0.1, 2 * 0.4 * 0.2}, tot = area[0] + area[1] + area[2];
    CHECK(off == 0, "box points on faces (%zu off)", off);
    for (int d = 0; d < 3; ++d)
        CHECK(fabs(face[d] / (N * area[d] / tot) - 1) < 0.05, "box face pair %d: %zu points, expected %.0f", d, face[d],
              N * area[d] / tot);
    sample_points_free(&a);

    /* union of two spheres: nothing on the hidden inner caps */
    memset(&a, 0, sizeof a);
    CHECK(sampler_surface(uni, 5000, h, 3, &a) == 0 && a.n == 5000, "union points");
    size_t hidden = 0;
    for (size_t k = 0; k < a.n; ++k) {
        const double *x = a.x + 3 * k;
        double r0 = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        double r1 = sqrt((x[0] - 0.2) * (x[0] - 0.2) + x[1] * x[1] + x[2] * x[2]);
        if (r0 < 0.2 - 1e-4 || r1 < 0.2 - 1e-4) ++hidden;
    }
    CHECK(hidden == 0, "union: %zu points inside the other sphere", hidden);
    sample_points_free(&a);

    /* bad input */
    memset(&a, 0, sizeof a);
    mpm_clear_error();
    CHECK(sampler_surface(sph, 10, 0.0, 1, &a) == MPM_EINPUT, "h = 0 rejected");
    shape_free(sph);
    shape_free(box);
    shape_free(uni);
}

int main(void)
{
    double t0 = omp_get_wtime();
    PoissonTile *t = NULL;
    CHECK(poisson_tile_create(1, &t) == 0, "tile");
    printf("tile generation: %.3f s\n", omp_get_wtime() - t0);
    if (!t) return test_summary("test_sampler");
    test_tile(t);
    test_poisson(t);
    test_random_lattice();
    test_surface();
    test_speed(t);
    poisson_tile_free(t);
    return test_summary("test_sampler");
}
