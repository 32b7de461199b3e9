/* floor: scene */
/* The scene loader's behaviour on scene text written by the test itself
 * (fields kept, defaults, particle counts, masses, --set, --scale, initial
 * F), the listing of built-ins, and bad input (each a one-line MPM_EINPUT
 * naming the field). Whether every built-in scene loads and runs is
 * test_scenes_suite's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "core/scene/sampler.h"
#include "core/scene/scene_load.h"
#include "tests/common/testutil.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

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

/* Loads a variant of k_base (see write_variant); 0 on success. */
static int load_variant(const char *from, const char *to, const SceneLoadOptions *opt, Scene *s)
{
    char path[256];
    memset(s, 0, sizeof *s);
    if (!write_variant(from, to, path, sizeof path)) return -1;
    mpm_clear_error();
    int st = scene_load(path, opt, s);
    remove(path);
    return st;
}

static double object_mass(const Scene *s, int obj)
{
    double m = 0;
    for (size_t k = s->object_offsets[obj]; k < s->object_offsets[obj + 1]; ++k) m += s->particles.mass[k];
    return m;
}

/* What the loader does with the fields of a file (the test's own text):
 * given values kept, omitted optional ones defaulted, particle count from
 * the sampling density, mass = density x volume, per-object material. */
static void test_fields_and_defaults(void)
{
    Scene s;
    int st = load_variant(NULL, NULL, NULL, &s);
    CHECK(st == 0, "base: %s", mpm_last_error());
    if (st) return;
    CHECK(s.dx == 0.05 && s.fps == 24 && s.frames == 2 && s.gravity[1] == -9.8, "given fields kept");
    CHECK(s.cfl == 0.6 && s.max_dt == 1.0 / 24 && s.min_dt == 1e-6 && s.apic_ratio == 1 &&
              s.cfl_rule == CFL_RULE_PAPER && !s.domain_walls && s.n_colliders == 0 && s.seed == 1,
          "defaults: cfl %g max_dt %g min_dt %g apic %g rule %d walls %d", s.cfl, s.max_dt, s.min_dt, s.apic_ratio,
          (int)s.cfl_rule, s.domain_walls);
    double expect = SAMPLER_DENSITY * 8 * 0.008 / (0.05 * 0.05 * 0.05);
    CHECK(fabs(s.particles.n / expect - 1) < 0.1, "count %zu vs %g", s.particles.n, expect);
    CHECK(fabs(total_mass(&s) - 1000 * 0.008) < 1e-12, "mass = density x volume: %g", total_mass(&s));
    int in_box = 1;
    for (size_t k = 0; k < s.particles.n; ++k)
        for (int d = 0; d < 3; ++d) in_box &= s.particles.x[3 * k + d] >= 0.4 && s.particles.x[3 * k + d] <= 0.6;
    CHECK(in_box, "particles inside their box");
    CHECK(s.particles.F[0] == 1 && s.particles.F[1] == 0 && s.particles.v[1] == 0, "F = I, v = 0");
    scene_free(&s);

    /* given optional fields, two objects of two materials, walls */
    st = load_variant("\"frames\": 2,",
                      "\"frames\": 2, \"cfl\": 0.3, \"max_dt\": 0.01, \"min_dt\": 1e-5, \"apic_ratio\": 0, "
                      "\"cfl_rule\": \"reference\", \"domain_walls\": true, \"seed\": 7,",
                      NULL, &s);
    CHECK(st == 0 && s.cfl == 0.3 && s.max_dt == 0.01 && s.min_dt == 1e-5 && s.apic_ratio == 0 &&
              s.cfl_rule == CFL_RULE_REFERENCE && s.domain_walls && s.seed == 7,
          "optional fields: %s", mpm_last_error());
    if (!st) {
        CHECK(s.n_colliders == 6 && strcmp(s.colliders[0].name, "wall_x_min") == 0, "six walls");
        double out[3] = {-0.01, 0.5, 0.5}, in[3] = {0.01, 0.5, 0.5};
        CHECK(collider_phi(&s.colliders[0], 0, out, NULL) < 0 && collider_phi(&s.colliders[0], 0, in, NULL) > 0,
              "x-min wall solid outside the domain only");
    }
    scene_free(&s);
    st = load_variant("\"materials\": {\"soft\": {\"E\": 1e5, \"nu\": 0.3, \"density\": 1000}},",
                      "\"materials\": {\"soft\": {\"E\": 1e5, \"nu\": 0.3, \"density\": 1000},"
                      " \"hard\": {\"E\": 1e7, \"nu\": 0.2, \"density\": 3000}},"
                      " \"colliders\": [{\"name\": \"floor\", \"shape\": {\"type\": \"half_space\", \"point\": [0, 0.1, 0],"
                      " \"normal\": [0, 1, 0]}}],",
                      NULL, &s);
    CHECK(st == 0 && s.n_materials == 2 && strcmp(s.materials[1].name, "hard") == 0 && s.materials[1].density == 3000 &&
              s.materials[1].mu > s.materials[0].mu && s.n_colliders == 1 && strcmp(s.colliders[0].name, "floor") == 0,
          "materials in declaration order, named collider: %s", mpm_last_error());
    scene_free(&s);
    st = load_variant("\"shape\": {\"type\": \"box\", \"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]}}]",
                      "\"shape\": {\"type\": \"box\", \"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]}},"
                      " {\"material\": \"soft\", \"ppc\": 27, \"sampling\": \"lattice\","
                      "  \"shape\": {\"type\": \"sphere\", \"center\": [0.3, 0.8, 0.3], \"radius\": 0.1}}]",
                      NULL, &s);
    CHECK(st == 0 && s.n_objects == 2, "two objects: %s", mpm_last_error());
    if (!st) {
        double sphere = 4.0 / 3.0 * M_PI * 1e-3;
        CHECK(fabs(object_mass(&s, 0) - 8.0) < 1e-12 && fabs(object_mass(&s, 1) - 1000 * sphere) < 1e-12,
              "per-object mass = density x own volume: %g %g", object_mass(&s, 0), object_mass(&s, 1));
        size_t n1 = s.object_offsets[2] - s.object_offsets[1];
        double want = 27 * sphere / (0.05 * 0.05 * 0.05);
        CHECK(fabs(n1 / want - 1) < 0.15, "lattice count %zu vs %g (27 per cell)", n1, want);
    }
    scene_free(&s);
}

/* --scale multiplies dx, divides the count by scale^3, keeps the mass;
 * --set changes a field before validation. */
static void test_scale_and_set(void)
{
    Scene a, b;
    int st = load_variant(NULL, NULL, NULL, &a);
    SceneOverride ov[2] = {{"materials.soft.E", "3e6"}, {"objects.0.velocity", "[0, 1, 0]"}};
    SceneLoadOptions opt = {.scale = 0.5, .overrides = ov, .n_overrides = 2};
    if (!st) st = load_variant(NULL, NULL, &opt, &b);
    CHECK(st == 0, "scale/set: %s", mpm_last_error());
    if (st) {
        scene_free(&a);
        return;
    }
    CHECK(b.dx == 0.025, "dx times scale: %g", b.dx);
    CHECK(fabs((double)b.particles.n / a.particles.n / 8.0 - 1) < 0.1, "scale 0.5: 8x the particles (%zu vs %zu)",
          b.particles.n, a.particles.n);
    CHECK(fabs(total_mass(&b) - total_mass(&a)) < 1e-12, "mass independent of scale");
    CHECK(b.materials[0].E == 3e6 && a.materials[0].E == 1e5, "--set E");
    CHECK(b.particles.v[1] == 1 && b.particles.v[3 * (b.particles.n - 1) + 1] == 1, "--set velocity");
    scene_free(&a);
    scene_free(&b);
}

/* initial_F: diagonal, within [min, max], per particle or per object,
 * deterministic from the seed. */
static void test_initial_F(void)
{
    const char *per = "\"ppc\": 8, \"initial_F\": {\"type\": \"random_diagonal\", \"min\": 0.7, \"max\": 1.3}";
    const char *one = "\"ppc\": 8, \"initial_F\": {\"type\": \"random_diagonal\", \"min\": 0.7, \"max\": 1.3, "
                      "\"per_particle\": false}";
    Scene s, s2, s3;
    int st = load_variant("\"ppc\": 8", per, NULL, &s);
    if (!st) st = load_variant("\"ppc\": 8", per, NULL, &s2);
    if (!st) st = load_variant("\"ppc\": 8", one, NULL, &s3);
    CHECK(st == 0, "initial_F: %s", mpm_last_error());
    if (st) return;
    int diag = 1, distinct = 0, same = 1;
    double mn = 9, mx = 0;
    for (size_t k = 0; k < s.particles.n; ++k) {
        const double *F = s.particles.F + 9 * k;
        for (int e = 0; e < 9; ++e)
            if (e % 4 != 0 && F[e] != 0) diag = 0;
        for (int d = 0; d < 3; ++d) mn = fmin(mn, F[4 * d]), mx = fmax(mx, F[4 * d]);
        if (k && F[0] != s.particles.F[9 * (k - 1)]) ++distinct;
        if (memcmp(s3.particles.F + 9 * k, s3.particles.F, 9 * sizeof(double))) same = 0;
    }
    CHECK(diag && mn >= 0.7 && mx <= 1.3 && mn < 0.75 && mx > 1.25, "diagonal F in [0.7, 1.3]: %g %g", mn, mx);
    CHECK(distinct > (int)s.particles.n / 2, "per particle: %d distinct of %zu", distinct, s.particles.n);
    CHECK(same && s3.particles.F[0] != 1.0, "per object: one F for all");
    CHECK(s2.particles.n == s.particles.n && memcmp(s2.particles.F, s.particles.F, 9 * s.particles.n * sizeof(double)) == 0,
          "deterministic");
    scene_free(&s);
    scene_free(&s2);
    scene_free(&s3);
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
    expect_bad("typo field", "\"fps\": 24,", "\"fps\": 24, \"fsp\": 3,", NULL, "fsp: unknown key", NULL);
    expect_bad("typo in material", "\"density\": 1000", "\"density\": 1000, \"denisty\": 3", NULL,
               "materials.soft.denisty: unknown key", NULL);
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

    /* time steps against the frame length (issue 12 item 4), messages naming the real field (item 10) */
    expect_bad("fps tiny", "\"fps\": 24", "\"fps\": 1e-310", NULL, "fps: expected a frame rate", "1e-310");
    expect_bad("fps huge", "\"fps\": 24", "\"fps\": 1e9", NULL, "fps: expected at most 1/min_dt", NULL);
    expect_bad("max_dt below floor", "\"fps\": 24,", "\"fps\": 24, \"max_dt\": 1e-12,", NULL,
               "max_dt: expected at least min_dt", "1e-12");
    expect_bad("min_dt above frame", "\"fps\": 24,", "\"fps\": 24, \"min_dt\": 0.5,", NULL,
               "min_dt: expected at most the frame length", NULL);
    expect_bad("min_dt tiny", "\"fps\": 24,", "\"fps\": 24, \"min_dt\": 1e-300,", NULL,
               "min_dt: expected at least the frame length", NULL);
    expect_bad("bad cfl_rule", "\"fps\": 24,", "\"fps\": 24, \"cfl_rule\": \"hot\",", NULL, "cfl_rule",
               "\"hot\"");
    expect_bad("dx above domain", "\"dx\": 0.05", "\"dx\": 1e308", NULL, "dx: expected at most the domain", NULL);
    expect_bad("dx too fine", "\"dx\": 0.05", "\"dx\": 1e-300", NULL, "dx: expected at least", NULL);
    expect_bad("density 1e-300", "\"density\": 1000", "\"density\": 1e-300", NULL, "materials.soft.density",
               "1e-300");
    expect_bad("collider spin 1e308", "\"gravity\": [0, -9.8, 0],",
               "\"gravity\": [0, -9.8, 0], \"colliders\": [{\"shape\": {\"type\": \"sphere\", \"center\": [0.5, "
               "0.9, 0.5], \"radius\": 0.05}, \"motion\": [{\"angular_velocity_deg\": [0, 1e308, 0]}]}],",
               NULL, "colliders.0.motion.0", "non-finite speed");
    /* particle budget (item 5): refused before sampling, naming the object */
    expect_bad("ppc over budget", "\"ppc\": 8", "\"ppc\": 1e10", NULL, "objects.0: ppc 1e+10",
               "particle budget");
    SceneLoadOptions small = {.max_particles = 100};
    expect_bad("--max-particles", NULL, NULL, &small, "objects.0: ppc 8", "particle budget 100");
    SceneLoadOptions fine = {.scale = 0.01};
    expect_bad("--scale 0.01", NULL, NULL, &fine, "dx times --scale 0.01", "particle budget");

    SceneOverride o1[1] = {{"materials.sof.E", "1e9"}};
    SceneLoadOptions opt1 = {.overrides = o1, .n_overrides = 1};
    expect_bad("--set missing path", NULL, NULL, &opt1, "materials.sof does not exist", "(there: soft");
    SceneOverride o2[1] = {{"materials.soft.E", "-3"}};
    SceneLoadOptions opt2 = {.overrides = o2, .n_overrides = 1};
    expect_bad("--set bad value", NULL, NULL, &opt2, "materials.soft.E: expected a positive number", "-3");
    SceneOverride o3[1] = {{"dx", "1e400"}};
    SceneLoadOptions opt3 = {.overrides = o3, .n_overrides = 1};
    expect_bad("--set overflow", NULL, NULL, &opt3, "dx: expected a number", "1e400");
    SceneOverride o4[1] = {{"objects.3.ppc", "4"}};
    SceneLoadOptions opt4 = {.overrides = o4, .n_overrides = 1};
    expect_bad("--set index range", NULL, NULL, &opt4, "objects.3 does not exist", "(indices 0..");
    SceneOverride o5[1] = {{"materials.soft.Young", "4"}};
    SceneLoadOptions opt5 = {.overrides = o5, .n_overrides = 1};
    expect_bad("--set unknown leaf", NULL, NULL, &opt5, "materials.soft.Young does not exist (there: ", "; may be added: ");
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
              strstr(mpm_last_error(), "missing.json") && strstr(mpm_last_error(), "not found"),
          "missing file: %s", mpm_last_error());
    /* a directory, a device and an empty file are not "not found" (item 10) */
    const char *dir = "/tmp", *dev = "/dev/null";
    mpm_clear_error();
    CHECK(scene_load(dir, NULL, &s) == MPM_EINPUT && strstr(mpm_last_error(), "is a directory"), "directory: %s",
          mpm_last_error());
    mpm_clear_error();
    CHECK(scene_load(dev, NULL, &s) == MPM_EINPUT && strstr(mpm_last_error(), "not a regular file"), "device: %s",
          mpm_last_error());
    snprintf(path, sizeof path, "/tmp/mpm_test_scene_%d_empty.json", (int)getpid());
    FILE *f = fopen(path, "w");
    if (f) fclose(f);
    mpm_clear_error();
    CHECK(scene_load(path, NULL, &s) == MPM_EINPUT && strstr(mpm_last_error(), "empty file"), "empty: %s",
          mpm_last_error());
    remove(path);
}

/* A mesh loader failure reaches the user as "scene: field: mesh file:line:
 * value": the loader's own message, prefixed on the way up by
 * mpm_error_context (no clear-and-reissue, issue 12 item 12). */
static void test_error_context(void)
{
    char obj[256];
    snprintf(obj, sizeof obj, "/tmp/mpm_test_scene_%d_bad.obj", (int)getpid());
    FILE *f = fopen(obj, "w");
    if (!f) return;
    fprintf(f, "v 0 0 0\nv 1 0 0\nv 1e308 0.2 0.4\nf 1 2 3\n");
    fclose(f);
    char shape[400];
    snprintf(shape, sizeof shape, "\"shape\": {\"type\": \"mesh\", \"file\": \"%s\"}}]", obj);
    char path[256];
    write_variant("\"shape\": {\"type\": \"box\", \"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]}}]", shape, path,
                  sizeof path);
    Scene s;
    mpm_clear_error();
    int st = scene_load(path, NULL, &s);
    char want[700];
    snprintf(want, sizeof want, "%s: objects.0.shape.file: %s:3: vertex coordinate '1e308' is out of range", path, obj);
    CHECK(st == MPM_EINPUT, "status %d", st);
    CHECK(strncmp(mpm_last_error(), want, strlen(want)) == 0, "context chain:\n  got  %s\n  want %s...",
          mpm_last_error(), want);
    printf("  %-22s -> %s\n", "mesh vertex 1e308", mpm_last_error());
    remove(path);
    remove(obj);
}

int main(void)
{
    test_list();
    test_fields_and_defaults();
    test_scale_and_set();
    test_initial_F();
    test_bad_input();
    test_error_context();
    return test_summary("test_scene");
}
