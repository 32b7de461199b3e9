/* Per-step solver error against a tight reference solve (error_ref.h, SPEC 11). */
#include "experiments/accuracy/error_ref.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/event_log.h"
#include "core/error.h"
#include "core/vec.h"
#include "experiments/driver/library_startup.h"
#include "experiments/driver/registry.h"

struct ErrorRef {
    char spec[160];
    char describe[256];
    int is_auto;
    Solver *exact;       /* "auto": pn-cholmod (NULL in a build without CHOLMOD) */
    Solver *fallback;    /* "auto": pn-pcg; otherwise the one reference */
    char exact_name[32], fallback_name[160];
    SolveSettings set;
    double *dv0, *dvs, *e, *He;
    int cap;
    StepError last;
};

#define AUTO_EXACT "pn-cholmod"
#define AUTO_FALLBACK "pn-pcg"

int error_ref_parse(const char *spec, char *solver, size_t n, double *eps)
{
    *eps = ERROR_REF_DEFAULT_EPS;
    if (!spec || !spec[0]) return mpm_error(MPM_EINPUT, "--error-ref '': expected SOLVER[:eps] or auto[:eps]");
    if (strlen(spec) >= n) return mpm_error(MPM_EINPUT, "--error-ref %.60s...: too long", spec);
    snprintf(solver, n, "%s", spec);
    char *colon = strrchr(solver, ':');
    if (colon) {
        char *end = NULL;
        double v = strtod(colon + 1, &end);
        if (colon[1] && end && !*end) { /* the last field is a number: the tolerance */
            if (!(v > 0.0) || !isfinite(v))
                return mpm_error(MPM_EINPUT, "--error-ref %s: eps %s: expected a positive number", spec, colon + 1);
            *eps = v;
            *colon = '\0';
        }
    }
    if (!solver[0]) return mpm_error(MPM_EINPUT, "--error-ref %s: expected a solver before ':'", spec);
    return MPM_OK;
}

/* Replaces the recorded message by "--error-ref SPEC: message". */
static int wrap(int st, const char *spec)
{
    char msg[900];
    snprintf(msg, sizeof msg, "%s", mpm_last_error());
    mpm_clear_error();
    return mpm_error(st, "--error-ref %s: %s", spec, msg);
}

int error_ref_check(const char *spec)
{
    char solver[160];
    double eps;
    int st = error_ref_parse(spec, solver, sizeof solver, &eps);
    if (st) return st;
    SolveSettings set;
    solve_settings_default(&set);
    set.eps = eps;
    if ((st = solve_settings_check(&set))) return wrap(st, spec);
    if (!strcmp(solver, "auto")) {
        if ((registry_find_preset(AUTO_EXACT) && (st = solver_spec_check(AUTO_EXACT, NULL, 0))) ||
            (st = solver_spec_check(AUTO_FALLBACK, NULL, 0)))
            return wrap(st, spec);
        return MPM_OK;
    }
    if ((st = solver_spec_check(solver, NULL, 0))) return wrap(st, spec);
    return MPM_OK;
}

int error_ref_create(const char *spec, ErrorRef **out)
{
    *out = NULL;
    int st = error_ref_check(spec);
    if (st) return st;
    ErrorRef *r = calloc(1, sizeof *r);
    if (!r) return mpm_error(MPM_EINTERNAL, "out of memory (--error-ref)");
    char solver[160];
    double eps;
    error_ref_parse(spec, solver, sizeof solver, &eps);
    snprintf(r->spec, sizeof r->spec, "%s", spec);
    solve_settings_default(&r->set);
    r->set.eps = eps;
    r->is_auto = !strcmp(solver, "auto");
    snprintf(r->fallback_name, sizeof r->fallback_name, "%s", r->is_auto ? AUTO_FALLBACK : solver);
    st = solver_from_spec(r->fallback_name, NULL, 0, &r->fallback);
    if (!st && r->is_auto && registry_find_preset(AUTO_EXACT)) {
        snprintf(r->exact_name, sizeof r->exact_name, "%s", AUTO_EXACT);
        st = solver_from_spec(AUTO_EXACT, NULL, 0, &r->exact);
    }
    if (st) {
        error_ref_destroy(r);
        return wrap(st, spec);
    }
    if (r->is_auto && !r->exact)
        snprintf(r->describe, sizeof r->describe, "auto: %s (this build has no %s), eps %g", AUTO_FALLBACK,
                 AUTO_EXACT, eps);
    else if (r->is_auto)
        snprintf(r->describe, sizeof r->describe, "auto: %s where its factor fits %.0f%% of the memory, else %s; eps %g",
                 AUTO_EXACT, 100 * ERROR_REF_MEMORY_FRACTION, AUTO_FALLBACK, eps);
    else
        snprintf(r->describe, sizeof r->describe, "%s, eps %g", solver, eps);
    *out = r;
    return MPM_OK;
}

int error_ref_startup(const ErrorRef *r)
{
    int st = library_startup(r->fallback);
    if (!st && r->exact) st = library_startup(r->exact);
    return st;
}

const char *error_ref_describe(const ErrorRef *r) { return r->describe; }

double error_ref_cholmod_bytes(int n_nodes)
{
    double N = 3.0 * (n_nodes > 0 ? n_nodes : 0);
    return 12.0 * 40.0 * pow(N, 4.0 / 3.0);
}

int error_ref_cholmod_fits(int n_nodes)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    double mem = pages > 0 && page > 0 ? (double)pages * (double)page : 4e9; /* unknown: assume 4 GB */
    return error_ref_cholmod_bytes(n_nodes) <= ERROR_REF_MEMORY_FRACTION * mem;
}

const StepError *error_ref_last(const ErrorRef *r) { return &r->last; }

void error_ref_clear(ErrorRef *r) { memset(&r->last, 0, sizeof r->last); }

static int all_finite(size_t len, const double *x)
{
    for (size_t k = 0; k < len; ++k)
        if (!isfinite(x[k])) return 0;
    return 1;
}

/* ||x||_H with H the BC-projected Hessian at the tangent in place. */
static double energy_norm(StepProblem *pb, const double *x, double *Hx)
{
    size_t len = 3 * (size_t)pb->n_nodes;
    problem_hessvec(pb, x, Hx);
    double q = vec_dot(len, x, Hx);
    return sqrt(q > 0.0 ? q : 0.0);
}

/* a / b, NAN when undefined; 0 / 0 is 0 (nothing to solve and nothing missed). */
static double ratio(double a, double b)
{
    if (a == 0.0 && b == 0.0) return 0.0;
    double q = a / b;
    return isfinite(q) ? q : NAN;
}

int error_ref_measure(void *ctx, StepProblem *pb, const double *dv)
{
    ErrorRef *r = ctx;
    double t0 = event_clock();
    memset(&r->last, 0, sizeof r->last);
    int n = pb->n_nodes;
    double **vecs[] = {&r->dv0, &r->dvs, &r->e, &r->He};
    const size_t per[] = {3, 3, 3, 3};
    int st = solve_reserve(vecs, per, 4, n, &r->cap);
    if (st) return st;
    size_t len = 3 * (size_t)n;
    Solver *ref = r->fallback;
    if (r->is_auto && r->exact && error_ref_cholmod_fits(n)) ref = r->exact;
    r->last.ref_solver = ref == r->exact ? r->exact_name : r->fallback_name;
    problem_initial_guess(pb, r->dv0);
    vec_copy(len, r->dv0, r->dvs);
    SolveStats rs;
    if ((st = solver_solve(ref, pb, &r->set, r->dvs, &rs, NULL, NULL, NULL))) return st;
    if (rs.status == SOLVE_FAILED && ref == r->exact) {
        /* a factorisation that broke down on round-off (tiny-mass nodes beside stiff ones): the
         * iterative reference instead, and one line saying so */
        fprintf(stderr, "mpmbench: --error-ref auto: %s failed (%s); %s instead for this step\n", r->exact_name,
                rs.reason, r->fallback_name);
        ref = r->fallback;
        r->last.ref_solver = r->fallback_name;
        vec_copy(len, r->dv0, r->dvs);
        if ((st = solver_solve(ref, pb, &r->set, r->dvs, &rs, NULL, NULL, NULL))) return st;
    }
    r->last.valid = 1;
    r->last.ref_status = rs.status;
    r->last.ref_residual = rs.residual;
    r->last.err_h = r->last.e_gap = r->last.err_v_max = NAN;
    /* no metrics against a reference that broke down: its iterate is not the minimiser */
    if (rs.status != SOLVE_FAILED && all_finite(len, dv) && all_finite(len, r->dvs)) {
        double E = problem_energy(pb, dv), E0 = problem_energy(pb, r->dv0), Es = problem_energy(pb, r->dvs);
        /* the energy norm at dv*: the projected tangent every solver uses (problem_energy set the cache at dv*) */
        if ((st = problem_tangent(pb, 1))) return st;
        double vmax = 0.0;
        for (int i = 0; i < n; ++i) {
            double s = 0.0;
            for (int d = 0; d < 3; ++d) {
                size_t k = 3 * (size_t)i + d;
                r->e[k] = dv[k] - r->dvs[k];
                s += r->e[k] * r->e[k];
            }
            if (s > vmax) vmax = s;
        }
        double num = energy_norm(pb, r->e, r->He);
        for (size_t k = 0; k < len; ++k) r->e[k] = r->dvs[k] - r->dv0[k];
        double den = energy_norm(pb, r->e, r->He);
        r->last.err_h = ratio(num, den);
        r->last.e_gap = ratio(E - Es, fabs(E0 - Es));
        r->last.err_v_max = sqrt(vmax) * pb->dt / pb->dx;
    }
    /* the cache (F, P) back at the solver's iterate, as the solve left it for step_end */
    problem_energy(pb, dv);
    r->last.ref_s = event_clock() - t0;
    return MPM_OK;
}

void error_ref_destroy(ErrorRef *r)
{
    if (!r) return;
    solver_destroy(r->exact);
    solver_destroy(r->fallback);
    free(r->dv0);
    free(r->dvs);
    free(r->e);
    free(r->He);
    free(r);
}
