/* floor: scene */
/* Core robustness (issue 12): the error module (first message wins,
 * context prefixes, per-thread messages, messages from OpenMP workers),
 * sums independent of the thread count, thread-count parsing, the box tree
 * of large unions against brute force, and step-level numerical failures
 * (MPM_ENUMERIC) with particles held at domain walls. */
#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/scene/box_tree.h"
#include "core/error.h"
#include "core/reduce.h"
#include "core/scene/scene_load.h"
#include "core/step.h"
#include "core/threads.h"
#include "core/vec.h"
#include "tests/common/testutil.h"

/* ---------------------------------------------------------------- errors */

static void *other_thread(void *arg)
{
    char *seen = arg;
    mpm_clear_error();
    snprintf(seen, 256, "%s", mpm_last_error()); /* empty: the main thread's message is not ours */
    mpm_error(MPM_EINPUT, "thread message");
    snprintf(seen + 128, 128, "%s", mpm_last_error());
    return NULL;
}

static void test_errors(void)
{
    mpm_clear_error();
    CHECK(strcmp(mpm_last_error(), "") == 0, "cleared");
    CHECK(mpm_error(MPM_EINPUT, "%s:%d: value %g", "mesh.obj", 3, 1e308) == MPM_EINPUT, "returns its status");
    mpm_error(MPM_EINTERNAL, "a later, less precise message");
    CHECK(strcmp(mpm_last_error(), "mesh.obj:3: value 1e+308") == 0, "first message wins: %s", mpm_last_error());
    CHECK(mpm_error_context(MPM_EINPUT, "%s", "objects.2.shape.file") == MPM_EINPUT, "context keeps the status");
    mpm_error_context(MPM_EINPUT, "%s", "scene.json");
    CHECK(strcmp(mpm_last_error(), "scene.json: objects.2.shape.file: mesh.obj:3: value 1e+308") == 0,
          "file, then field, then value: %s", mpm_last_error());
    CHECK(mpm_error_context(MPM_OK, "ignored") == MPM_OK &&
              strncmp(mpm_last_error(), "scene.json: objects", 19) == 0,
          "context on success changes nothing");
    mpm_clear_error();
    mpm_error_context(MPM_EINPUT, "only context");
    CHECK(strcmp(mpm_last_error(), "only context") == 0, "context without a message: %s", mpm_last_error());
    /* one line whatever the input held (fuzz_matrix: a JSON key with an escaped newline) */
    mpm_clear_error();
    mpm_error(MPM_EINPUT, "%s: unknown key", "ref\nere\tnce");
    mpm_error_context(MPM_EINPUT, "%s", "m\r.json");
    CHECK(strcmp(mpm_last_error(), "m?.json: ref?ere?nce: unknown key") == 0, "control characters replaced: %s",
          mpm_last_error());

    /* another thread has its own message */
    mpm_clear_error();
    mpm_error(MPM_EINPUT, "main message");
    char seen[256] = "x";
    pthread_t th;
    CHECK(pthread_create(&th, NULL, other_thread, seen) == 0, "pthread_create");
    pthread_join(th, NULL);
    CHECK(seen[0] == '\0' && strcmp(seen + 128, "thread message") == 0, "thread sees only its own: '%s' '%s'", seen,
          seen + 128);
    CHECK(strcmp(mpm_last_error(), "main message") == 0, "main keeps its own: %s", mpm_last_error());

    /* a message recorded by an OpenMP worker reaches the encountering thread,
     * and concurrent reports from every worker leave one intact message */
    mpm_clear_error();
    int nt = 0;
#pragma omp parallel num_threads(4)
    {
#pragma omp single
        nt = omp_get_num_threads();
        if (omp_get_thread_num() == nt - 1 && nt > 1) mpm_error(MPM_ENUMERIC, "worker %d failed", nt - 1);
    }
    char want[64];
    snprintf(want, sizeof want, "worker %d failed", nt - 1);
    CHECK(nt < 2 || strcmp(mpm_last_error(), want) == 0, "worker message visible after the region: '%s'",
          mpm_last_error());
    mpm_error_context(MPM_ENUMERIC, "step 3");
    CHECK(nt < 2 || strncmp(mpm_last_error(), "step 3: worker", 14) == 0, "context after a worker's message: %s",
          mpm_last_error());
    mpm_clear_error();
#pragma omp parallel num_threads(8)
    for (int k = 0; k < 1000; ++k) mpm_error(MPM_ENUMERIC, "report %d from thread %d", k, omp_get_thread_num());
    int k = -1, t = -1;
    CHECK(sscanf(mpm_last_error(), "report %d from thread %d", &k, &t) == 2 && k == 0, "one intact message: %s",
          mpm_last_error());
    mpm_clear_error();
}

/* ------------------------------------------------------------- reductions */

static double square_range(const void *ctx, size_t b, size_t e)
{
    const double *x = ctx;
    double s = 0;
    for (size_t i = b; i < e; ++i) s += x[i] * x[i];
    return s;
}

static void test_reduce(void)
{
    const size_t n = 100003;
    double *x = malloc(sizeof(double) * n);
    unsigned long long rs = 3;
    for (size_t i = 0; i < n; ++i) x[i] = test_uniform(&rs, -1, 1) * pow(10.0, test_uniform(&rs, -8, 8));
    int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    double ref = vec_dot(n, x, x), ref_sum = reduce_sum(n, 7, square_range, x);
    long double exact = 0;
    for (size_t i = 0; i < n; ++i) exact += (long double)x[i] * x[i];
    CHECK(fabs((double)exact - ref) <= 1e-12 * ref, "the sum is right: %.17g vs %.17Lg", ref, exact);
    int same = 1;
    const int counts[] = {2, 3, 7, 64, 257, 300, 1024};
    for (size_t c = 0; c < sizeof counts / sizeof *counts; ++c) {
        omp_set_num_threads(counts[c]);
        double d = vec_dot(n, x, x), r = reduce_sum(n, 7, square_range, x);
        if (d != ref || r != ref_sum) {
            same = 0;
            printf("threads %d: dot %.17g vs %.17g, sum %.17g vs %.17g\n", counts[c], d, ref, r, ref_sum);
        }
    }
    omp_set_num_threads(saved);
    CHECK(same, "the same bits for 1 to 1024 threads");
    CHECK(reduce_sum(0, 1, square_range, NULL) == 0.0 && vec_dot(0, NULL, NULL) == 0.0, "empty sums are 0");
    free(x);
}

/* ------------------------------------------------------------ thread counts */

static void test_thread_counts(void)
{
    int n = 0;
    CHECK(threads_parse("--threads", "257", &n) == MPM_OK && n == 257, "257 threads");
    CHECK(threads_parse("--threads", "1024", &n) == MPM_OK && n == MPM_MAX_THREADS, "the limit");
    const char *bad[] = {"0", "1025", "-3", "2.5", "", "abc", "99999999999"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; ++k) {
        mpm_clear_error();
        CHECK(threads_parse("--threads", bad[k], &n) == MPM_EINPUT && strstr(mpm_last_error(), "--threads") &&
                  strstr(mpm_last_error(), "[1, 1024]"),
              "'%s' refused: %s", bad[k], mpm_last_error());
    }
    const char *env = getenv("OMP_NUM_THREADS");
    char saved[64] = "";
    if (env) snprintf(saved, sizeof saved, "%s", env);
    const char *good_env[] = {"2", "4,2", " 8 "}, *bad_env[] = {"0", "1025", "", "2,0", "x"};
    for (size_t k = 0; k < 3; ++k) {
        setenv("OMP_NUM_THREADS", good_env[k], 1);
        mpm_clear_error();
        CHECK(threads_check_env() == MPM_OK, "OMP_NUM_THREADS='%s' accepted: %s", good_env[k], mpm_last_error());
    }
    for (size_t k = 0; k < 5; ++k) {
        setenv("OMP_NUM_THREADS", bad_env[k], 1);
        mpm_clear_error();
        CHECK(threads_check_env() == MPM_EINPUT && strstr(mpm_last_error(), "OMP_NUM_THREADS"),
              "OMP_NUM_THREADS='%s' refused: %s", bad_env[k], mpm_last_error());
    }
    if (env)
        setenv("OMP_NUM_THREADS", saved, 1);
    else
        unsetenv("OMP_NUM_THREADS");
    mpm_clear_error();
}

/* ---------------------------------------------------------------- box tree */

typedef struct {
    int n;
    const double *lo, *hi, *c, *r; /* box i and the sphere inside it */
} Balls;

static double ball_sdf(const void *ctx, int i, const double x[3])
{
    const Balls *b = ctx;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (x[k] - b->c[3 * i + k]) * (x[k] - b->c[3 * i + k]);
    return sqrt(d2) - b->r[i];
}

static int ball_contains(const void *ctx, int i, const double x[3]) { return ball_sdf(ctx, i, x) <= 0; }

/* Exact SDFs (spheres): the tree's min and any equal brute force everywhere. */
static void test_box_tree(void)
{
    const int n = 3000;
    double *lo = malloc(sizeof(double) * 3 * n), *hi = malloc(sizeof(double) * 3 * n),
           *c = malloc(sizeof(double) * 3 * n), *r = malloc(sizeof(double) * n);
    unsigned long long rs = 11;
    for (int i = 0; i < n; ++i) {
        r[i] = test_uniform(&rs, 0.005, 0.05);
        for (int k = 0; k < 3; ++k) {
            c[3 * i + k] = test_uniform(&rs, 0, 1);
            lo[3 * i + k] = c[3 * i + k] - r[i];
            hi[3 * i + k] = c[3 * i + k] + r[i];
        }
    }
    Balls b = {n, lo, hi, c, r};
    BoxTree *t = box_tree_build(n, lo, hi);
    CHECK(t != NULL, "build");
    if (!t) return;
    int min_ok = 1, any_ok = 1, inside = 0;
    for (int q = 0; q < 20000; ++q) {
        double x[3] = {test_uniform(&rs, -0.2, 1.2), test_uniform(&rs, -0.2, 1.2), test_uniform(&rs, -0.2, 1.2)};
        double brute = HUGE_VAL;
        int in = 0;
        for (int i = 0; i < n; ++i) {
            brute = fmin(brute, ball_sdf(&b, i, x));
            in |= ball_contains(&b, i, x);
        }
        inside += in;
        if (box_tree_min(t, x, ball_sdf, &b) != brute) min_ok = 0;
        if (box_tree_any(t, x, ball_contains, &b) != in) any_ok = 0;
    }
    CHECK(min_ok, "tree min = brute-force min (exact SDFs)");
    CHECK(any_ok, "tree any = brute-force any");
    CHECK(inside > 1000 && inside < 19000, "queries inside and outside (%d inside)", inside);
    box_tree_free(t);
    BoxTree *e = box_tree_build(0, NULL, NULL);
    double x0[3] = {0, 0, 0};
    CHECK(e && box_tree_min(e, x0, ball_sdf, &b) == HUGE_VAL && !box_tree_any(e, x0, ball_contains, &b), "empty");
    box_tree_free(e);
    free(lo), free(hi), free(c), free(r);
}

/* ------------------------------------------------------- step-level failures */

static const char *k_scene =
    "{\"name\": \"t\", \"dx\": 0.05, \"fps\": 24, \"frames\": 1, \"gravity\": [0, 0, 0],"
    " \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, \"domain_walls\": %s,"
    " \"materials\": {\"m\": {\"E\": 1e4, \"nu\": 0.3, \"density\": 1000}},"
    " \"objects\": [{\"material\": \"m\", \"ppc\": 8, \"velocity\": [-4, 0, 0],"
    "   \"shape\": {\"type\": \"box\", \"min\": [0.1, 0.4, 0.4], \"max\": [0.3, 0.6, 0.6]}}]}";

static int load_box(const char *walls, Scene *s)
{
    char path[128], text[1024];
    snprintf(path, sizeof path, "/tmp/mpm_test_robust_%d.json", (int)getpid());
    snprintf(text, sizeof text, k_scene, walls);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    fclose(f);
    mpm_clear_error();
    int st = scene_load(path, NULL, s);
    remove(path);
    return st;
}

/* Steps with dv = v_target - v^n = 0 (the grid velocities carried over):
 * particles keep moving at -4 m/s in x toward the x-min face. */
static int run_steps(Simulation *sim, int steps)
{
    int st = MPM_OK;
    for (int k = 0; k < steps && !st; ++k) {
        if ((st = step_begin(sim))) break;
        double *dv = calloc(3 * (size_t)(sim->grid.n > 0 ? sim->grid.n : 1), sizeof(double));
        st = step_end(sim, dv);
        free(dv);
    }
    return st;
}

static void test_step_failures(void)
{
    Scene s;
    Simulation sim;
    /* without walls the box leaves the domain: MPM_ENUMERIC naming the particle */
    int st = load_box("false", &s);
    CHECK(st == 0, "scene: %s", mpm_last_error());
    if (st) return;
    sim_init(&sim, &s);
    mpm_clear_error();
    st = run_steps(&sim, 40);
    CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "left the domain") && strstr(mpm_last_error(), "no domain_walls"),
          "escape without walls: status %d, %s", st, mpm_last_error());
    /* NaN state: MPM_ENUMERIC at the next step_end */
    sim_free(&sim);
    sim_init(&sim, &s);
    sim.p.v[4] = NAN;
    mpm_clear_error();
    st = run_steps(&sim, 1);
    CHECK(st == MPM_ENUMERIC && (strstr(mpm_last_error(), "not finite") || strstr(mpm_last_error(), "non-finite")),
          "NaN velocity: status %d, %s", st, mpm_last_error());
    /* a CFL step below min_dt is refused, not floored */
    sim_free(&sim);
    sim_init(&sim, &s);
    sim.p.v[0] = 1e9;
    mpm_clear_error();
    double dt = -1;
    st = sim_next_dt(&sim, &dt);
    CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "below min_dt") && strstr(mpm_last_error(), "particle 0") &&
              dt == -1,
          "CFL below min_dt: %d %s", st, mpm_last_error());
    sim.p.v[0] = 1e300;
    mpm_clear_error();
    st = sim_next_dt(&sim, &dt);
    CHECK(st == MPM_ENUMERIC && strstr(mpm_last_error(), "not finite"), "overflowing speed: %s", mpm_last_error());
    sim_free(&sim);
    scene_free(&s);

    /* with walls the same box stops at the x-min face and stays in the domain */
    st = load_box("true", &s);
    CHECK(st == 0, "walled scene: %s", mpm_last_error());
    if (st) return;
    sim_init(&sim, &s);
    mpm_clear_error();
    double xmin = HUGE_VAL;
    int inside = 1;
    for (int step = 0; step < 12 && !st; ++step) { /* 4 m/s for 12 steps of 7.5 ms: 0.36 m, past the face */
        st = run_steps(&sim, 1);
        for (size_t k = 0; k < sim.p.n; ++k) {
            xmin = fmin(xmin, sim.p.x[3 * k]);
            for (int d = 0; d < 3; ++d) inside &= sim.p.x[3 * k + d] >= 0 && sim.p.x[3 * k + d] <= 1;
        }
    }
    CHECK(st == MPM_OK, "walls hold the box: %s", mpm_last_error());
    CHECK(inside && xmin == 0.0, "particles reached the face and stayed in the domain: x_min %g", xmin);
    sim_free(&sim);
    scene_free(&s);
}

/* A scene that starts with no particles (sources only) steps without
 * touching empty arrays (UBSan: memcpy/memset on NULL). */
static void test_empty_start(void)
{
    Scene s;
    mpm_clear_error();
    int st = scene_load("sauce", &(SceneLoadOptions){.scale = 4.0}, &s);
    CHECK(st == 0 && s.particles.n == 0, "sauce starts empty: %s", mpm_last_error());
    if (st) return;
    Simulation sim;
    st = sim_init(&sim, &s);
    if (!st) st = step_begin(&sim);
    double dv[3] = {0, 0, 0};
    if (!st) st = step_end(&sim, dv);
    CHECK(st == 0 && sim.grid.n == 0, "an empty step: %s", mpm_last_error());
    sim_free(&sim);
    scene_free(&s);
}

int main(void)
{
    test_errors();
    test_reduce();
    test_thread_counts();
    test_box_tree();
    test_step_failures();
    test_empty_start();
    return test_summary("test_robust");
}
