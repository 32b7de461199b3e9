/* floor: scene */
/* The scene options of the stress suite (core/scene/scene_load.h): initial_F "diagonal"
 * and "inverted_fraction", per-object "stiffness_variation" (checkerboard and
 * random), their validation, and particle ids (core/particles.h) surviving
 * the locality sort. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "core/grid.h"
#include "core/scene/scene_load.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

/* A 0.3 m box of soft material, dx 0.02 (about 3.4k particles). */
static const char *const k_box =
    "{\"name\": \"box\", \"dx\": 0.02, \"fps\": 24, \"frames\": 1, \"gravity\": [0, 0, 0],"
    " \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
    " \"materials\": {\"soft\": {\"E\": 1e5, \"nu\": 0.3, \"density\": 1000}},"
    " \"objects\": [{\"material\": \"soft\", \"ppc\": 8, \"sampling\": \"lattice\","
    " \"shape\": {\"type\": \"box\", \"min\": [0.35, 0.35, 0.35], \"max\": [0.65, 0.65, 0.65]}}]}";

static double det_diag(const double *F) { return F[0] * F[4] * F[8]; }

static int load(const char *key, const char *value, Scene *sc)
{
    const char *set[2] = {key, value};
    return test_scene_from_text(k_box, 1.0, set, key ? 1 : 0, sc);
}

static void test_initial_F(void)
{
    Scene sc;
    int st = load("objects.0.initial_F", "{\"type\": \"diagonal\", \"values\": [1, 1, 1e-4]}", &sc);
    CHECK(st == MPM_OK, "diagonal: %s", mpm_last_error());
    int exact = sc.particles.n > 0;
    for (size_t k = 0; k < sc.particles.n && exact; ++k) {
        const double *F = sc.particles.F + 9 * k;
        exact = F[0] == 1.0 && F[4] == 1.0 && F[8] == 1e-4 && F[1] == 0.0 && F[3] == 0.0;
    }
    CHECK(exact, "every particle starts at diag(1, 1, 1e-4)");
    scene_free(&sc);

    /* a share f of the particles inverted, each independently: within 4 sigma of f n */
    st = load("objects.0.initial_F",
              "{\"type\": \"random_diagonal\", \"min\": 0.5, \"max\": 1.5, \"inverted_fraction\": 0.3, \"seed\": 3}", &sc);
    CHECK(st == MPM_OK, "inverted_fraction: %s", mpm_last_error());
    size_t n = sc.particles.n, inverted = 0;
    int in_range = 1;
    for (size_t k = 0; k < n; ++k) {
        const double *F = sc.particles.F + 9 * k;
        inverted += det_diag(F) < 0.0;
        for (int d = 0; d < 3; ++d) in_range &= fabs(F[4 * d]) >= 0.5 && fabs(F[4 * d]) <= 1.5;
        in_range &= F[4] > 0.0 && F[8] > 0.0; /* only d0 is negated */
    }
    double sigma = sqrt(0.3 * 0.7 * (double)n);
    CHECK(fabs((double)inverted - 0.3 * (double)n) < 4.0 * sigma, "%zu of %zu inverted, expected about %.0f", inverted, n,
          0.3 * (double)n);
    CHECK(in_range, "|d_k| in [0.5, 1.5], only d0 negative");
    scene_free(&sc);

    /* one F for the whole object: the inversion is still per particle, the magnitudes shared */
    st = load("objects.0.initial_F", "{\"type\": \"random_diagonal\", \"min\": 0.5, \"max\": 1.5, \"per_particle\": false,"
                                     " \"inverted_fraction\": 0.5}", &sc);
    CHECK(st == MPM_OK, "per_particle false: %s", mpm_last_error());
    int shared = 1, neg = 0, pos = 0;
    for (size_t k = 1; k < sc.particles.n; ++k) {
        const double *F = sc.particles.F + 9 * k, *F0 = sc.particles.F;
        shared &= fabs(F[0]) == fabs(F0[0]) && F[4] == F0[4] && F[8] == F0[8];
        neg |= F[0] < 0;
        pos |= F[0] > 0;
    }
    CHECK(shared && neg && pos, "shared magnitudes (%d), both signs of d0 (%d %d)", shared, neg, pos);
    scene_free(&sc);

    /* without the option nothing is inverted */
    st = load("objects.0.initial_F", "{\"type\": \"random_diagonal\", \"min\": 0.1, \"max\": 10}", &sc);
    inverted = 0;
    for (size_t k = 0; k < sc.particles.n; ++k) inverted += det_diag(sc.particles.F + 9 * k) < 0.0;
    CHECK(st == MPM_OK && inverted == 0, "no inversion by default (%zu)", inverted);
    scene_free(&sc);
}

static void test_stiffness_variation(void)
{
    Scene sc;
    int st = load("objects.0.stiffness_variation", "{\"pattern\": \"checkerboard\", \"factor\": 1e6}", &sc);
    CHECK(st == MPM_OK, "checkerboard: %s", mpm_last_error());
    CHECK(sc.n_materials == 2 && !strcmp(sc.materials[1].name, "soft*1e+06"), "twin material (%d: %s)", sc.n_materials,
          sc.n_materials > 1 ? sc.materials[1].name : "-");
    if (sc.n_materials == 2) {
        CHECK(sc.materials[1].E == 1e5 * 1e6 && sc.materials[1].nu == 0.3 && sc.materials[1].density == 1000,
              "twin: E x 1e6, the rest copied");
        CHECK(rel_diff(sc.materials[1].mu, 1e6 * sc.materials[0].mu, 0) < 1e-12, "twin: mu derived from the new E");
    }
    /* the checkerboard of dx cubes: a particle's material is the parity of its cell */
    int parity_ok = 1;
    size_t stiff = 0;
    for (size_t k = 0; k < sc.particles.n; ++k) {
        long long c = 0;
        for (int d = 0; d < 3; ++d) c += (long long)floor(sc.particles.x[3 * k + d] / 0.02);
        parity_ok &= sc.particles.mat[k] == (int)(c & 1);
        stiff += sc.particles.mat[k] == 1;
    }
    CHECK(parity_ok, "material = parity of the dx cell");
    CHECK(stiff > sc.particles.n / 3 && stiff < 2 * sc.particles.n / 3, "%zu of %zu stiff", stiff, sc.particles.n);
    scene_free(&sc);

    st = load("objects.0.stiffness_variation", "{\"pattern\": \"random\", \"factor\": 1e-3, \"seed\": 4}", &sc);
    CHECK(st == MPM_OK, "random: %s", mpm_last_error());
    stiff = 0;
    for (size_t k = 0; k < sc.particles.n; ++k) stiff += sc.particles.mat[k] == 1;
    double n = (double)sc.particles.n;
    CHECK(fabs((double)stiff - 0.5 * n) < 4.0 * sqrt(0.25 * n), "random: %zu of %.0f twins", stiff, n);
    CHECK(sc.n_materials == 2 && sc.materials[1].E == 1e5 * 1e-3, "a softer twin");
    scene_free(&sc);

    static const char *const bad[][2] = {
        {"{\"pattern\": \"zebra\", \"factor\": 10}", "pattern"},
        {"{\"pattern\": \"random\", \"factor\": 0}", "factor"},
        {"{\"pattern\": \"random\", \"factor\": 10, \"cell\": 0.1}", "cell"},
        {"{\"pattern\": \"checkerboard\", \"factor\": 10, \"seed\": 2}", "seed"},
        {"{\"pattern\": \"checkerboard\", \"factor\": 10, \"cell\": -1}", "cell"},
        {"{\"pattern\": \"checkerboard\", \"factor\": 1e305}", "factor"},
        {"{\"factor\": 10}", "pattern"},
        {"{\"pattern\": \"random\", \"factor\": 10, \"amplitude\": 1}", "amplitude"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        mpm_clear_error();
        st = load("objects.0.stiffness_variation", bad[i][0], &sc);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), bad[i][1]), "%s refused naming %s: %s", bad[i][0], bad[i][1],
              mpm_last_error());
        scene_free(&sc);
    }
    static const char *const bad_F[][2] = {
        {"{\"type\": \"diagonal\", \"values\": [1, 0, 1]}", "values"},
        {"{\"type\": \"diagonal\", \"values\": [1, 1]}", "values"},
        {"{\"type\": \"diagonal\", \"values\": [1, 1, 1], \"min\": 1}", "min"},
        {"{\"type\": \"random_diagonal\", \"min\": 1, \"max\": 2, \"values\": [1, 1, 1]}", "values"},
        {"{\"type\": \"random_diagonal\", \"min\": 1, \"max\": 2, \"inverted_fraction\": 1.5}", "inverted_fraction"},
        {"{\"type\": \"random_diagonal\", \"min\": 1, \"max\": 2, \"inverted_fraction\": -0.1}", "inverted_fraction"},
        {"{\"type\": \"rotation\"}", "type"},
    };
    for (size_t i = 0; i < sizeof bad_F / sizeof bad_F[0]; ++i) {
        mpm_clear_error();
        st = load("objects.0.initial_F", bad_F[i][0], &sc);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), bad_F[i][1]), "%s refused naming %s: %s", bad_F[i][0],
              bad_F[i][1], mpm_last_error());
        scene_free(&sc);
    }
    mpm_clear_error();
}

/* ids are the push order and follow the particles through the sort */
static void test_ids(void)
{
    Scene sc;
    int st = load(NULL, NULL, &sc);
    CHECK(st == MPM_OK, "box: %s", mpm_last_error());
    Particles p = {0};
    CHECK(particles_copy(&p, &sc.particles) == MPM_OK, "copy");
    int ids = 1;
    for (size_t k = 0; k < p.n; ++k) ids &= p.id[k] == k;
    CHECK(ids, "ids 0..n-1 in push order");
    /* scramble: move every particle by a per-particle offset, so the sort reorders them */
    for (size_t k = 0; k < p.n; ++k) p.x[3 * k] = 0.2 + 0.6 * (double)((k * 7919) % p.n) / (double)p.n;
    Grid g = {0};
    Stencils stn = {0};
    CHECK(grid_build(&g, &stn, &p, 0.02) == MPM_OK, "grid");
    int moved = 0, follow = 1;
    for (size_t k = 0; k < p.n; ++k) {
        size_t id = p.id[k];
        moved |= id != k;
        follow &= p.x[3 * k] == 0.2 + 0.6 * (double)((id * 7919) % p.n) / (double)p.n &&
                  p.x[3 * k + 1] == sc.particles.x[3 * id + 1] && p.F[9 * k] == sc.particles.F[9 * id];
    }
    CHECK(moved, "the sort reordered the particles");
    CHECK(follow, "each id still names its particle");
    grid_free(&g);
    stencils_free(&stn);
    particles_free(&p);
    scene_free(&sc);
}

int main(void)
{
    test_initial_F();
    test_stiffness_variation();
    test_ids();
    return test_summary("test_scene_stress_options");
}
