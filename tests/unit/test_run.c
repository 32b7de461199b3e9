/* floor: app */
/* The run layer's contracts (issue 12 items 2, 3, 9):
 *  - a numerical breakdown inside a solve (MPM_ENUMERIC) becomes the step's
 *    status failed with the message as reason, the error buffer is cleared,
 *    and the step is applied only when the failure policy asks for it; any
 *    other error stays an error;
 *  - solver_spec_check validates a spec with its options completely without
 *    a step problem (the experiment-matrix runner's pre-flight);
 *  - run_config_check refuses bad settings without doing work (no folder);
 *    the CN tolerance floor SOLVE_EPS_MIN is exact. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/step.h"
#include "core/scene/scene_load.h"
#include "experiments/driver/registry.h"
#include "experiments/run/run.h"
#include "tests/common/testutil.h"

/* an outer method that breaks down (or fails hard) at once */
static int g_fail_status = MPM_ENUMERIC;
static OuterMethodOps g_mock_ops;
static int mock_create(SolverOptions *opt, OuterMethod **out)
{
    (void)opt;
    OuterMethod *m = calloc(1, sizeof *m);
    if (!m) return MPM_EINTERNAL;
    m->ops = &g_mock_ops;
    m->assembled = 1;
    *out = m;
    return MPM_OK;
}
static int mock_solve(OuterMethod *self, SolveCtx *c, double *dv, SolveStats *st)
{
    (void)self;
    (void)dv;
    st->outer_iters = 1;
    st->residual = problem_cn_residual(c->pb, dv);
    return mpm_error(g_fail_status, "mock breakdown in %s", g_fail_status == MPM_ENUMERIC ? "numerics" : "the program");
}
static void mock_destroy(OuterMethod *self) { free(self); }
static OuterMethodOps g_mock_ops = {"mock", "breaks down", 0, mock_create, mock_solve, NULL, mock_destroy};

static void breakdown_policy(void)
{
    Scene sc;
    SceneLoadOptions lo = {.scale = 3.0};
    int st = scene_load("drop", &lo, &sc);
    CHECK(st == MPM_OK, "scene: %s", mpm_last_error());
    if (st) return;
    Solver *solver = NULL;
    st = solver_create("mock", &g_mock_ops, registry_find_inverse("block-jacobi"), NULL, &solver);
    CHECK(st == MPM_OK, "mock solver: %s", mpm_last_error());
    SolveSettings set;
    solve_settings_default(&set);
    for (int apply = 0; apply < 2 && !st; ++apply) {
        Simulation sim;
        StepWork w = {.dv = NULL, .cap = 0};
        SolveStats ss;
        StepInfo si;
        st = sim_init(&sim, &sc);
        mpm_clear_error();
        g_fail_status = MPM_ENUMERIC;
        int rc = time_step_run(&sim, solver, &set, &w, NULL, NULL, apply, &ss, &si);
        CHECK(rc == MPM_OK, "apply %d: a breakdown is a status, not an error (rc %d)", apply, rc);
        CHECK(ss.status == SOLVE_FAILED && strcmp(ss.reason, "mock breakdown in numerics") == 0,
              "apply %d: status %s, reason '%s'", apply, solve_status_name(ss.status), ss.reason);
        CHECK(mpm_last_error()[0] == '\0', "apply %d: the error buffer is cleared ('%s')", apply, mpm_last_error());
        CHECK(si.advanced == apply && (apply ? sim.t > 0 : sim.t == 0), "apply %d: advanced %d, t = %g", apply,
              si.advanced, sim.t);
        CHECK(si.dt > 0 && si.active_nodes > 0, "apply %d: the row has dt %g and %d nodes", apply, si.dt,
              si.active_nodes);
        g_fail_status = MPM_EINTERNAL;
        rc = time_step_run(&sim, solver, &set, &w, NULL, NULL, apply, &ss, &si);
        CHECK(rc == MPM_EINTERNAL, "apply %d: an internal error stays an error (rc %d)", apply, rc);
        mpm_clear_error();
        free(w.dv);
        sim_free(&sim);
    }
    solver_destroy(solver);
    scene_free(&sc);
}

static void spec_check(void)
{
    static const char *ok[] = {"hot", "pn-pcg-mf", "hot:window=4", "lbfgs:sgs", "pn:mg:embedding=quadratic",
                               "pn:block-jacobi:matrix_free=1", "lbfgs:mg:rediscretize=1,coarse_bc_project=0",
#if MPM_WITH_CHOLMOD
                               "pn:cholmod:linesearch=armijo",
#endif
#if MPM_WITH_HYPRE
                               "lbfgs:boomeramg:stop=l2,tau=1e-4",
#endif
    };
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; ++k) {
        mpm_clear_error();
        CHECK(solver_spec_check(ok[k], NULL, 0) == MPM_OK, "%s: %s", ok[k], mpm_last_error());
    }
    /* an adapter left out of the build: its presets and its name say which option builds it */
    static const char *absent[][2] = {
#if !MPM_WITH_CHOLMOD
        {"pn-cholmod", "-DMPM_WITH_CHOLMOD=ON; Debian package libsuitesparse-dev"},
        {"lbfgs:cholmod", "cholmod is not in this build (configure with -DMPM_WITH_CHOLMOD=ON"},
#endif
#if !MPM_WITH_HYPRE
        {"pn-amg-pcg", "pn-amg-pcg is not in this build (configure with -DMPM_WITH_HYPRE=ON; Debian package libhypre-dev)"},
#endif
        {"", ""}}; /* the end */
    for (size_t k = 0; absent[k][0][0]; ++k) {
        mpm_clear_error();
        CHECK(solver_spec_check(absent[k][0], NULL, 0) == MPM_EINPUT && strstr(mpm_last_error(), absent[k][1]),
              "%s absent: %s", absent[k][0], mpm_last_error());
        CHECK(registry_find_preset(absent[k][0]) == NULL, "%s: no preset in this build", absent[k][0]);
    }
    static const char *bad[][2] = {
        {"nosuch", "unknown solver 'nosuch'"},
        {"pn:nosuch", "unknown inverse approximation 'nosuch'"},
        {"newton:sgs", "unknown outer method 'newton'"},
        {"pn:sgs:matrix_free=1", "'sgs' needs the assembled Hessian"},
        {"hot:window=2.5", "window=2.5: expected an integer in [1, 64]"},
        {"hot:window=1e10", "window=1e10: expected an integer"},
        {"pn:mg:embedding=cubic", "embedding=cubic"},
        {"pn-gmgpcg:embedding=quadratic", "has no option 'embedding'"},
        {"pn:mg:levels=x", "levels=x: expected a number"},
        {"pn:mg:", "empty option list"},
        {"pn-pcg:linesearch=goldstein", "linesearch=goldstein: unknown line search"},
        {"pn-pcg:stop=l2,tau=-1", "tau=-1: expected a positive number"},
        {"pn-pcg:stall_iters=0", "stall_iters=0: expected an integer"},
        {"", "expected a preset name"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        mpm_clear_error();
        int st = solver_spec_check(bad[k][0], NULL, 0);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), bad[k][1]), "'%s' must be refused with '%s': %d '%s'",
              bad[k][0], bad[k][1], st, mpm_last_error());
    }
    /* user options apply last */
    const char *user[] = {"window=3"};
    SolverSpec sp;
    mpm_clear_error();
    int parsed = solver_spec_parse("hot:window=5", user, 1, &sp) == MPM_OK, windows = 0, wins = 0;
    for (int k = 0; parsed && k < sp.opts.n; ++k)
        if (!strcmp(sp.opts.key[k], "window")) windows++, wins = !strcmp(sp.opts.value[k], "3");
    CHECK(parsed && windows == 1 && wins, "the user's window=3 wins over the spec's 5 (one window option)");
    const char *typo[] = {"windw=3"};
    CHECK(solver_spec_check("hot", typo, 1) == MPM_EINPUT && strstr(mpm_last_error(), "no option 'windw'"),
          "a typo is an error: '%s'", mpm_last_error());
    mpm_clear_error();
}

static void config_check(void)
{
    char dir[] = "/tmp/mpm_test_run_XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "temporary directory");
    char never[600];
    snprintf(never, sizeof never, "%s/never", dir);
    RunConfig c;
    run_config_default(&c);
    c.scene = "drop";
    c.solver = "hot";
    c.out_dir = never;
    CHECK(run_config_check(&c) == MPM_OK, "defaults: %s", mpm_last_error());
    c.eps = SOLVE_EPS_MIN;
    CHECK(run_config_check(&c) == MPM_OK, "eps at the floor %g accepted: %s", SOLVE_EPS_MIN, mpm_last_error());
    c.eps = nextafter(SOLVE_EPS_MIN, 0.0);
    mpm_clear_error();
    CHECK(run_config_check(&c) == MPM_EINPUT && strstr(mpm_last_error(), "--eps"), "eps below the floor refused: %s",
          mpm_last_error());
    c.eps = SOLVE_EPS_DEFAULT;
    c.solver_opts[0] = "window=2.5";
    c.n_solver_opts = 1;
    mpm_clear_error();
    CHECK(run_config_check(&c) == MPM_EINPUT && strstr(mpm_last_error(), "window=2.5"), "window=2.5: %s",
          mpm_last_error());
    RunSummary sum;
    mpm_clear_error();
    CHECK(run_simulation(&c, &sum) == MPM_EINPUT, "run_simulation refuses it too");
    struct stat sb;
    CHECK(stat(never, &sb) != 0, "no output folder made for refused input");
    c.n_solver_opts = 0;
    c.max_step_s = -1;
    mpm_clear_error();
    CHECK(run_config_check(&c) == MPM_EINPUT && strstr(mpm_last_error(), "--max-step-seconds"), "max_step_s -1: %s",
          mpm_last_error());
    c.max_step_s = 0;
    c.max_outer = -2;
    mpm_clear_error();
    CHECK(run_config_check(&c) == MPM_EINPUT && strstr(mpm_last_error(), "--max-outer"), "max_outer -2: %s",
          mpm_last_error());
    c.max_outer = 0;
    c.armijo = 1;
    mpm_clear_error();
    CHECK(run_config_check(&c) == MPM_OK, "--armijo is the option linesearch=armijo: %s", mpm_last_error());
    mpm_clear_error();
    rmdir(dir);
}

int main(void)
{
    breakdown_policy();
    spec_check();
    config_check();
    return test_summary("test_run");
}
