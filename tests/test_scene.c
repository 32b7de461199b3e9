/* Scenes: every built-in loads, particle counts, --set overrides, --scale,
 * initial F, and bad input (each a one-line MPM_EINPUT naming the field). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "core/sampler.h"
#include "core/scene.h"
#include "tests/testutil.h"

static double now(void) { return omp_get_wtime(); }

typedef struct {
    char names[64][64];
    int n;
} Listing;

static void on_scene(const char *name, const char *desc, void *ctx)
{
    Listing *l = ctx;
    if (l->n < 64) snprintf(l->names[l->n++], 64, "%s", name);
    (void)desc;
}

static double total_mass(const Scene *s)
{
    double m = 0;
    for (size_t k = 0; k < s->particles.n; ++k) m += s->particles.mass[k];
    return m;
}

static void test_list(void)
{
    Listing l;
    memset(&l, 0, sizeof l);
    mpm_clear_error();
    CHECK(scene_list(on_scene, &l) == 0, "scene_list: %s", mpm_last_error());
    int has_bar3 = 0, has_drop = 0, has_sb = 0, sorted = 1;
    for (int k = 0; k < l.n; ++k) {
        has_bar3 |= strcmp(l.names[k], "bar3") == 0;
        has_drop |= strcmp(l.names[k], "drop") == 0;
        has_sb |= strcmp(l.names[k], "stretched-box") == 0;
        if (k && strcmp(l.names[k - 1], l.names[k]) >= 0) sorted = 0;
    }
    CHECK(has_bar3 && has_drop && has_sb && sorted, "built-ins listed and sorted (%d)", l.n);
}

static void test_drop(void)
{
    Scene s;
    mpm_clear_error();
    double t0 = now();
    int st = scene_load("drop", NULL, &s);
    CHECK(st == 0, "drop: %s", mpm_last_error());
    if (st) return;
    printf("drop: %zu particles (%.3f s)\n", s.particles.n, now() - t0);
    double expect = SAMPLER_DENSITY * 8 * 0.008 / (0.02 * 0.02 * 0.02);
    CHECK(fabs(s.particles.n / expect - 1) < 0.05, "drop count %zu vs %g", s.particles.n, expect);
    CHECK(fabs(total_mass(&s) - 8.0) < 1e-9, "mass = density * volume: %g", total_mass(&s));
    CHECK(s.n_colliders == 7 && strcmp(s.colliders[0].name, "ground") == 0 &&
              strcmp(s.colliders[1].name, "wall_x_min") == 0,
          "ground + 6 walls");
    CHECK(s.frames == 24 && s.fps == 24 && fabs(s.max_dt - 1.0 / 24) < 1e-15 && s.cfl == 0.6 && s.apic_ratio == 1,
          "defaults");
    CHECK(s.gravity[1] == -9.8 && s.n_materials == 1 && s.materials[0].mu > 0, "gravity/material");
    double x[3] = {0.5, 0.05, 0.5};
    CHECK(collider_phi(&s.colliders[0], 0, x, NULL) < 0, "ground solid below 0.1");
    /* walls: solid outside the domain, open inside */
    double out[3] = {-0.01, 0.5, 0.5}, in[3] = {0.01, 0.5, 0.5};
    CHECK(collider_phi(&s.colliders[1], 0, out, NULL) < 0 && collider_phi(&s.colliders[1], 0, in, NULL) > 0,
          "x-min wall");
    int inside = 1;
    for (size_t k = 0; k < s.particles.n; ++k)
        for (int d = 0; d < 3; ++d) {
            double v = s.particles.x[3 * k + d];
            double lo = d == 1 ? 0.2 : 0.4, hi = d == 1 ? 0.4 : 0.6;
            if (v < lo || v > hi) inside = 0;
        }
    CHECK(inside, "particles in the box");
    CHECK(s.particles.F[0] == 1 && s.particles.F[1] == 0 && s.particles.v[1] == 0, "F = I, v = 0");
    scene_free(&s);
}

static void test_bar3(void)
{
    Scene s;
    mpm_clear_error();
    double t0 = now();
    int st = scene_load("bar3", NULL, &s);
    CHECK(st == 0, "bar3: %s", mpm_last_error());
    if (st) return;
    double t1 = now();
    size_t n1 = s.particles.n;
    double expect = SAMPLER_DENSITY * 12 * (0.12 * 0.12 * 0.9) / pow(0.0075, 3);
    printf("bar3: %zu particles (expected ~%.0f), load %.3f s\n", n1, expect, t1 - t0);
    CHECK(fabs(n1 / expect - 1) < 0.05, "bar3 count %zu vs %g", n1, expect);
    CHECK(s.n_materials == 2 && strcmp(s.materials[1].name, "middle") == 0 && s.materials[1].E == 1e9 &&
              s.materials[0].E == 1e5,
          "materials");
    CHECK(s.n_objects == 3 && s.object_offsets[3] == n1, "objects");
    int mats_ok = 1;
    for (size_t k = s.object_offsets[1]; k < s.object_offsets[2]; ++k)
        if (s.particles.mat[k] != 1 || s.particles.x[3 * k + 1] < 3.1 || s.particles.x[3 * k + 1] > 3.4) mats_ok = 0;
    CHECK(mats_ok, "middle segment particles");
    CHECK(s.n_colliders == 8 && strcmp(s.colliders[1].name, "top_cap") == 0, "2 caps + 6 walls");
    CHECK(s.frames == 48 && s.fps == 48 && fabs(s.max_dt - 1.0 / 48) < 1e-15 && s.gravity[1] == 0, "timing");
    CHECK(fabs(total_mass(&s) - 2000 * 0.01296) < 1e-9, "mass %g", total_mass(&s));
    scene_free(&s);

    /* --set: the middle stiffness (the Fig. 20 sweep), and a nested array path */
    SceneOverride ov[3] = {{"materials.middle.E", "1e7"},
                           {"colliders.1.motion.0.angular_velocity_deg.1", "180"},
                           {"materials.ends.E", "1e9"}};
    SceneLoadOptions opt = {.scale = 2.0, .overrides = ov, .n_overrides = 3};
    mpm_clear_error();
    st = scene_load("bar3", &opt, &s);
    CHECK(st == 0, "bar3 --set --scale 2: %s", mpm_last_error());
    if (st) return;
    CHECK(s.materials[1].E == 1e7 && s.materials[0].E == 1e9, "--set E took effect");
    double R[9], b[3];
    collider_pose(&s.colliders[1], 1.0, R, b);
    CHECK(fabs(R[0] + 1) < 1e-12, "--set angular velocity: 180 deg after 1 s");
    CHECK(fabs(s.dx - 0.015) < 1e-15, "scaled dx");
    size_t n2 = s.particles.n;
    printf("bar3 --scale 2: %zu particles (ratio %.3f)\n", n2, (double)n1 / n2);
    CHECK(fabs((double)n1 / n2 / 8.0 - 1) < 0.05, "scale 2 gives ~1/8 particles: %zu vs %zu", n2, n1);
    CHECK(fabs(total_mass(&s) - 2000 * 0.01296) < 1e-9, "mass independent of scale");
    scene_free(&s);
}

static void test_stretched_box(void)
{
    Scene s, s2;
    mpm_clear_error();
    /* scale 2 (dx 0.02) and the per-particle variant of the initial F */
    SceneOverride per = {"objects.0.initial_F.per_particle", "true"};
    SceneLoadOptions lo = {.scale = 2.0, .overrides = &per, .n_overrides = 1};
    int st = scene_load("stretched-box", &lo, &s);
    CHECK(st == 0, "stretched-box: %s", mpm_last_error());
    if (st) return;
    printf("stretched-box: %zu particles\n", s.particles.n);
    double expect = SAMPLER_DENSITY * 8 * 0.027 / (0.02 * 0.02 * 0.02);
    CHECK(fabs(s.particles.n / expect - 1) < 0.05, "count");
    int ok = 1, distinct = 0;
    double mn = 9, mx = 0;
    for (size_t k = 0; k < s.particles.n; ++k) {
        const double *F = s.particles.F + 9 * k;
        for (int e = 0; e < 9; ++e)
            if (e % 4 != 0 && F[e] != 0) ok = 0;
        for (int d = 0; d < 3; ++d) mn = fmin(mn, F[4 * d]), mx = fmax(mx, F[4 * d]);
        if (k && F[0] != s.particles.F[9 * (k - 1)]) ++distinct;
    }
    CHECK(ok && mn >= 0.7 && mx <= 1.3 && mn < 0.72 && mx > 1.28, "diagonal F in [0.7, 1.3]: %g %g", mn, mx);
    CHECK(distinct > (int)s.particles.n / 2, "per-particle F");
    CHECK(s.frames == 1 && s.gravity[1] == 0, "one frame, no gravity");
    st = scene_load("stretched-box", &lo, &s2);
    CHECK(st == 0 && s2.particles.n == s.particles.n &&
              memcmp(s2.particles.F, s.particles.F, 9 * s.particles.n * sizeof(double)) == 0 &&
              memcmp(s2.particles.x, s.particles.x, 3 * s.particles.n * sizeof(double)) == 0,
          "deterministic");
    scene_free(&s2);
    scene_free(&s);
}

/* ---------------------------------------------------------------------- */

static const char *k_base =
    "{\n"
    "  \"name\": \"t\",\n"
    "  \"dx\": 0.05,\n"
    "  \"fps\": 24,\n"
    "  \"frames\": 2,\n"
    "  \"gravity\": [0, -9.8, 0],\n"
    "  \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},\n"
    "  \"materials\": {\"soft\": {\"E\": 1e5, \"nu\": 0.3, \"density\": 1000}},\n"
    "  \"objects\": [{\"material\": \"soft\", \"ppc\": 8,\n"
    "                \"shape\": {\"type\": \"box\", \"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]}}]\n"
    "}\n";

static int g_file_counter;

/* Writes `text` with `from` replaced by `to` to a temp file; returns its path. */
static const char *write_variant(const char *from, const char *to, char *path, size_t n)
{
    const char *at = from ? strstr(k_base, from) : NULL;
    if (from && !at) {
        fprintf(stderr, "test bug: '%s' not in base scene\n", from);
        return NULL;
    }
    snprintf(path, n, "/tmp/mpm_test_scene_%d_%d.json", (int)getpid(), g_file_counter++);
    FILE *f = fopen(path, "w");
    if (!f) return NULL;
    if (at) {
        fwrite(k_base, 1, (size_t)(at - k_base), f);
        fputs(to, f);
        fputs(at + strlen(from), f);
    } else {
        fputs(k_base, f);
    }
    fclose(f);
    return path;
}

static void expect_bad(const char *what, const char *from, const char *to, const SceneLoadOptions *opt,
                       const char *needle1, const char *needle2)
{
    char path[256];
    if (!write_variant(from, to, path, sizeof path)) {
        CHECK(0, "%s: could not write temp scene", what);
        return;
    }
    Scene s;
    mpm_clear_error();
    int st = scene_load(path, opt, &s);
    const char *msg = mpm_last_error();
    CHECK(st == MPM_EINPUT, "%s: status %d (%s)", what, st, msg);
    CHECK(strstr(msg, path) != NULL, "%s: message names the file: %s", what, msg);
    CHECK(strstr(msg, needle1) != NULL, "%s: '%s' lacks '%s'", what, msg, needle1);
    if (needle2) CHECK(strstr(msg, needle2) != NULL, "%s: '%s' lacks '%s'", what, msg, needle2);
    CHECK(strchr(msg, '\n') == NULL, "%s: one line", what);
    CHECK(s.particles.n == 0 && s.materials == NULL, "%s: nothing left allocated", what);
    printf("  %-22s -> %s\n", what, msg);
    if (st == 0) scene_free(&s);
    remove(path);
}

static void test_bad_input(void)
{
    /* the base scene itself is fine */
    char path[256];
    write_variant(NULL, NULL, path, sizeof path);
    Scene s;
    mpm_clear_error();
    CHECK(scene_load(path, NULL, &s) == 0, "base scene: %s", mpm_last_error());
    scene_free(&s);
    remove(path);

    printf("bad input messages:\n");
    expect_bad("malformed JSON", "\"fps\": 24,", "\"fps\": 24", NULL, ":5:", "frames");
    expect_bad("missing field", "\"dx\": 0.05,", "", NULL, "dx: missing required field", NULL);
    expect_bad("E <= 0", "\"E\": 1e5", "\"E\": -5", NULL, "materials.soft.E: expected a positive number", "-5");
    expect_bad("E = 0", "\"E\": 1e5", "\"E\": 0", NULL, "materials.soft.E", NULL);
    expect_bad("nu >= 0.5", "\"nu\": 0.3", "\"nu\": 0.5", NULL, "materials.soft.nu", "0.5");
    expect_bad("density <= 0", "\"density\": 1000", "\"density\": 0", NULL, "materials.soft.density", NULL);
    expect_bad("string for number", "\"dx\": 0.05", "\"dx\": \"abc\"", NULL, "dx: expected a number", "\"abc\"");
    expect_bad("1e400 overflow", "\"dx\": 0.05", "\"dx\": 1e400", NULL, "overflow", "dx");
    expect_bad("non-finite Lame", "\"E\": 1e5, \"nu\": 0.3", "\"E\": 1e308, \"nu\": 0.4999999999", NULL,
               "materials.soft.E", "non-finite");
    expect_bad("dx <= 0", "\"dx\": 0.05", "\"dx\": -0.05", NULL, "dx: expected a positive number", NULL);
    expect_bad("frames < 1", "\"frames\": 2", "\"frames\": 0", NULL, "frames", NULL);
    expect_bad("fractional frames", "\"frames\": 2", "\"frames\": 2.5", NULL, "frames: expected an integer", NULL);
    expect_bad("ppc <= 0", "\"ppc\": 8", "\"ppc\": 0", NULL, "objects.0.ppc", NULL);
    expect_bad("unknown material", "\"material\": \"soft\"", "\"material\": \"sofft\"", NULL,
               "objects.0.material: unknown material \"sofft\"", "soft");
    expect_bad("unknown shape type", "\"type\": \"box\"", "\"type\": \"boxx\"", NULL, "objects.0.shape.type",
               "\"boxx\"");
    expect_bad("particle outside", "\"max\": [0.6, 0.6, 0.6]", "\"max\": [0.6, 1.3, 0.6]", NULL,
               "objects.0.shape: particle at", "outside the domain");
    expect_bad("object outside", "\"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]",
               "\"min\": [2.4, 0.4, 0.4], \"max\": [2.6, 0.6, 0.6]", NULL, "objects.0.shape", "outside the domain");
    expect_bad("typo field", "\"fps\": 24,", "\"fps\": 24, \"fsp\": 3,", NULL, "fsp: unknown field", NULL);
    expect_bad("typo in material", "\"density\": 1000", "\"density\": 1000, \"denisty\": 3", NULL,
               "materials.soft.denisty: unknown field", NULL);
    expect_bad("gravity not vec3", "[0, -9.8, 0]", "[0, -9.8]", NULL, "gravity", NULL);
    expect_bad("bad plasticity", "\"density\": 1000", "\"density\": 1000, \"plasticity\": {\"type\": \"vm\"}", NULL,
               "materials.soft.plasticity.type", "\"vm\"");
    expect_bad("bad sampling", "\"ppc\": 8", "\"ppc\": 8, \"sampling\": \"grid\"", NULL, "objects.0.sampling", NULL);
    expect_bad("lattice ppc", "\"ppc\": 8", "\"ppc\": 9, \"sampling\": \"lattice\"", NULL, "objects.0.ppc", NULL);
    expect_bad("bad initial_F", "\"ppc\": 8",
               "\"ppc\": 8, \"initial_F\": {\"type\": \"random_diagonal\", \"min\": 1.3, \"max\": 0.7}", NULL,
               "objects.0.initial_F.max", NULL);
    expect_bad("bad collider", "\"gravity\": [0, -9.8, 0],",
               "\"gravity\": [0, -9.8, 0], \"colliders\": [{\"shape\": {\"type\": \"half_space\", "
               "\"point\": [0, 0, 0], \"normal\": [0, 0, 0]}}],",
               NULL, "colliders.0.shape.normal", NULL);

    SceneOverride o1[1] = {{"materials.sof.E", "1e9"}};
    SceneLoadOptions opt1 = {.overrides = o1, .n_overrides = 1};
    expect_bad("--set missing path", NULL, NULL, &opt1, "materials.sof", "does not exist");
    SceneOverride o2[1] = {{"materials.soft.E", "-3"}};
    SceneLoadOptions opt2 = {.overrides = o2, .n_overrides = 1};
    expect_bad("--set bad value", NULL, NULL, &opt2, "materials.soft.E: expected a positive number", "-3");
    SceneOverride o3[1] = {{"dx", "1e400"}};
    SceneLoadOptions opt3 = {.overrides = o3, .n_overrides = 1};
    expect_bad("--set overflow", NULL, NULL, &opt3, "dx: expected a number", "1e400");
    SceneOverride o4[1] = {{"objects.3.ppc", "4"}};
    SceneLoadOptions opt4 = {.overrides = o4, .n_overrides = 1};
    expect_bad("--set index range", NULL, NULL, &opt4, "objects.3", "does not exist");
    SceneOverride o5[1] = {{"materials.soft.Young", "4"}};
    SceneLoadOptions opt5 = {.overrides = o5, .n_overrides = 1};
    expect_bad("--set unknown leaf", NULL, NULL, &opt5, "materials.soft.Young", "does not exist");
    SceneLoadOptions opt6 = {.scale = -1};
    expect_bad("negative scale", NULL, NULL, &opt6, "scale", NULL);

    /* --set may create a known optional field */
    SceneOverride o7[2] = {{"cfl", "0.3"}, {"domain_walls", "true"}};
    SceneLoadOptions opt7 = {.overrides = o7, .n_overrides = 2};
    write_variant(NULL, NULL, path, sizeof path);
    mpm_clear_error();
    CHECK(scene_load(path, &opt7, &s) == 0 && s.cfl == 0.3 && s.n_colliders == 6, "--set creates cfl: %s",
          mpm_last_error());
    scene_free(&s);
    remove(path);

    /* unknown built-in name lists the available ones */
    mpm_clear_error();
    CHECK(scene_load("no-such-scene", NULL, &s) == MPM_EINPUT, "unknown built-in");
    CHECK(strstr(mpm_last_error(), "no-such-scene") && strstr(mpm_last_error(), "bar3") &&
              strstr(mpm_last_error(), "drop"),
          "lists built-ins: %s", mpm_last_error());
    printf("  %-22s -> %s\n", "unknown built-in", mpm_last_error());
    mpm_clear_error();
    CHECK(scene_load("/tmp/definitely/missing.json", NULL, &s) == MPM_EINPUT &&
              strstr(mpm_last_error(), "missing.json"),
          "missing file");
}

int main(void)
{
    test_list();
    test_drop();
    test_stretched_box();
    test_bar3();
    test_bad_input();
    return test_summary("test_scene");
}
