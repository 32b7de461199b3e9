#include "experiments/driver/registry.h"

#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "solvers/line_search.h"
#include "solvers/stop_rule.h"

/* Outer methods: one line each. The implementation's file defines the ops
 * (solvers/<name>.c); the list declares and registers it. */
#define OUTER_METHODS(X) \
    X(outer_pn)          \
    X(outer_lbfgs)       \
    X(outer_gast15)      \
    X(outer_semi_implicit)

/* The adapters are compiled only when their CMake option is ON (the build
 * defines MPM_WITH_<LIBRARY>=1, docs/design.md, floors). */
#if MPM_WITH_CHOLMOD
#define CHOLMOD_INVERSE(X) X(inv_cholmod_ops)
#else
#define CHOLMOD_INVERSE(X)
#endif
#if MPM_WITH_HYPRE
#define HYPRE_INVERSE(X) X(inv_boomeramg_ops)
#else
#define HYPRE_INVERSE(X)
#endif
#if MPM_WITH_ML
#define ML_INVERSE(X) X(inv_ml_ops)
#else
#define ML_INVERSE(X)
#endif

/* Inverse approximations: one line each (solvers/, adapters/). */
#define INVERSE_APPROXIMATIONS(X) \
    X(inv_block_jacobi_ops)       \
    X(inv_scalar_jacobi_ops)      \
    X(inv_sgs_ops)                \
    X(inv_mg_ops)                 \
    X(inv_inexact_pcg_ops)        \
    CHOLMOD_INVERSE(X)            \
    HYPRE_INVERSE(X)              \
    ML_INVERSE(X)                 \
    X(inv_gast_diagonal_ops)

#define DECLARE_OUTER(sym) extern const OuterMethodOps sym;
#define DECLARE_INVERSE(sym) extern const InvApproxOps sym;
#define ADDRESS(sym) &sym,
OUTER_METHODS(DECLARE_OUTER)
INVERSE_APPROXIMATIONS(DECLARE_INVERSE)
static const OuterMethodOps *const g_outer[] = {OUTER_METHODS(ADDRESS)};
static const InvApproxOps *const g_inverse[] = {INVERSE_APPROXIMATIONS(ADDRESS)};

/* Presets: {name, description, outer, inverse, options}. */
static const SolverPreset g_presets[] = {
    {"pn-pcg", "projected Newton, PCG with 3x3 block-Jacobi on the assembled Hessian (HOT PN-PCG)", "pn",
     "block-jacobi", ""},
    {"pn-pcg-scalar", "projected Newton, PCG with scalar (diagonal) Jacobi on the assembled Hessian", "pn", "jacobi",
     ""},
    {"pn-pcg-mf", "projected Newton, matrix-free PCG with 3x3 block-Jacobi (HOT PN-PCG(MF))", "pn", "block-jacobi",
     "matrix_free=1"},
    {"pn-sgs-pcg", "projected Newton, PCG preconditioned by one coloured symmetric block Gauss-Seidel sweep (HOT Table 3)",
     "pn", "sgs", ""},
    /* the setup-bearing presets keep their setup for the step where that
     * was faster at the same CN tolerance (results/reuse, results/amg-tuning,
     * results/ml-tuning; docs/solvers.md "Setup reuse") */
    {"pn-mgpcg", "projected Newton, PCG preconditioned by one node-embedding Galerkin V-cycle, its coarse levels "
     "kept for the step (HOT PN-MGPCG with setup reuse; reuse_every=1 rebuilds every iteration as HOT does)",
     "pn", "mg", "reuse_every=0,reuse_refresh=0,smoother_precision=single"},
    {"pn-amg-pcg", "projected Newton, PCG preconditioned by one hypre BoomerAMG V-cycle, tuned, kept for the step "
     "(algebraic baseline)", "pn", "boomeramg", "amg_strong_threshold=0.25,reuse_every=0"},
    {"pn-ml-pcg", "projected Newton, PCG preconditioned by one Trilinos ML aggregation V-cycle, tuned, kept for the "
     "step (algebraic baseline)", "pn", "ml", "ml_damping=0,reuse_every=0"},
    {"pn-cholmod", "projected Newton with exact CHOLMOD Cholesky solves (exact-Newton reference)", "pn", "cholmod", ""},
    /* the multigrid presets smooth on single-precision copies of their
     * levels' matrices: the same iterations in less time on every scene
     * measured (results/smoother-precision; SPEC 6.10) */
    {"hot", "L-BFGS, initial inverse = one linear-embedding Galerkin multigrid V-cycle built once per step (HOT)",
     "lbfgs", "mg", "smoother_precision=single"},
    {"hot-quadratic", "HOT with the quadratic embedding kernel", "lbfgs", "mg",
     "embedding=quadratic,smoother_precision=single"},
    {"lbfgs-gmg", "L-BFGS, initial inverse = one V-cycle of particle-rediscretised geometric multigrid (HOT LBFGS-GMG)",
     "lbfgs", "mg", "rediscretize=1,smoother_precision=single"},
    {"pn-gmgpcg", "projected Newton, PCG preconditioned by the particle-rediscretised geometric multigrid V-cycle", "pn",
     "mg", "rediscretize=1,smoother_precision=single"},
    {"lbfgs-h", "L-BFGS, initial inverse = inexact block-Jacobi PCG on the start-of-step Hessian (HOT LBFGS-H)",
     "lbfgs", "inexact-pcg", ""},
    {"lbfgs-h-direct", "L-BFGS, initial inverse = CHOLMOD factor of the start-of-step Hessian (Li et al. 2019)", "lbfgs",
     "cholmod", ""},
    {"lbfgs-amg", "L-BFGS, initial inverse = one hypre BoomerAMG V-cycle (pn-amg-pcg's tuned options)", "lbfgs",
     "boomeramg", "amg_strong_threshold=0.25"},
    {"lbfgs-ml", "L-BFGS, initial inverse = one Trilinos ML aggregation V-cycle (pn-ml-pcg's tuned options)", "lbfgs",
     "ml", "ml_damping=0"},
    {"gast15", "Gast et al. 2015: unprojected Newton, CG stopping at indefiniteness, strong Wolfe, ||g|| < 1e-3, "
     "rest-configuration diagonal preconditioner, matrix-free", "gast15", "gast-diagonal", "linesearch=wolfe,stop=l2"},
    {"gast15-hot", "what the HOT study ran as Gast15: matrix-free projected Newton, block Jacobi, halving, ||g|| < 1e-3, "
     "PCG to min(0.5, sqrt(max(||g||, 1e-3)))", "pn", "block-jacobi", "matrix_free=1,stop=l2,forcing=gast"},
    {"semi-implicit", "Stomakhin et al. 2013: one linearised backward-Euler solve per step (MINRES, unprojected "
     "Hessian at x^n), no line search", "semi-implicit", "gast-diagonal", ""},
};

#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

/* The optional adapters: when one is not built, its presets are absent and
 * named with the option and package that build it. */
static const struct {
    const char *inverse, *option, *package;
} g_optional[] = {
    {"boomeramg", "MPM_WITH_HYPRE", "libhypre-dev"},
    {"cholmod", "MPM_WITH_CHOLMOD", "libsuitesparse-dev"},
    {"ml", "MPM_WITH_ML", "libtrilinos-ml-dev"},
};

/* The g_optional entry of inverse approximation `name` when it is not
 * built, else -1. */
static int absent_index(const char *name)
{
    if (registry_find_inverse(name)) return -1;
    for (int i = 0; i < COUNT(g_optional); ++i)
        if (!strcmp(g_optional[i].inverse, name)) return i;
    return -1;
}

static int preset_built(const SolverPreset *p) { return registry_find_inverse(p->inverse) != NULL; }

int registry_preset_count(void)
{
    int n = 0;
    for (int i = 0; i < COUNT(g_presets); ++i) n += preset_built(&g_presets[i]);
    return n;
}
const SolverPreset *registry_preset(int i)
{
    for (int k = 0; k < COUNT(g_presets); ++k)
        if (preset_built(&g_presets[k]) && i-- == 0) return &g_presets[k];
    return NULL;
}
const SolverPreset *registry_find_preset(const char *name)
{
    for (int i = 0; i < COUNT(g_presets); ++i)
        if (strcmp(g_presets[i].name, name) == 0) return preset_built(&g_presets[i]) ? &g_presets[i] : NULL;
    return NULL;
}

/* "pn-cholmod is not in this build (...)" for an absent preset or inverse. */
static int not_built(const char *spec, const char *what, const char *inverse)
{
    int k = absent_index(inverse);
    return mpm_error(MPM_EINPUT,
                     "--solver '%s': %s is not in this build (configure with -D%s=ON; Debian package %s)", spec,
                     what, g_optional[k].option, g_optional[k].package);
}

int registry_outer_count(void) { return COUNT(g_outer); }
const OuterMethodOps *registry_outer(int i) { return i >= 0 && i < COUNT(g_outer) ? g_outer[i] : NULL; }
const OuterMethodOps *registry_find_outer(const char *name)
{
    for (int i = 0; i < COUNT(g_outer); ++i)
        if (strcmp(g_outer[i]->name, name) == 0) return g_outer[i];
    return NULL;
}

int registry_inverse_count(void) { return COUNT(g_inverse); }
const InvApproxOps *registry_inverse(int i) { return i >= 0 && i < COUNT(g_inverse) ? g_inverse[i] : NULL; }
const InvApproxOps *registry_find_inverse(const char *name)
{
    for (int i = 0; i < COUNT(g_inverse); ++i)
        if (strcmp(g_inverse[i]->name, name) == 0) return g_inverse[i];
    return NULL;
}

static void names_of(int outer, char *buf, size_t len)
{
    size_t used = 0;
    int n = outer ? COUNT(g_outer) : COUNT(g_inverse);
    buf[0] = '\0';
    for (int i = 0; i < n && used < len; ++i)
        used += (size_t)snprintf(buf + used, len - used, "%s%s", i ? ", " : "",
                                 outer ? g_outer[i]->name : g_inverse[i]->name);
}

int solver_spec_parse(const char *spec, const char *const *opts, int n_opts, SolverSpec *out)
{
    memset(out, 0, sizeof *out);
    if (!spec || !spec[0]) return mpm_error(MPM_EINPUT, "--solver '': expected a preset name or OUTER:INVERSE");
    if (strlen(spec) >= sizeof out->name) return mpm_error(MPM_EINPUT, "--solver '%s': too long", spec);
    char buf[sizeof out->name];
    snprintf(buf, sizeof buf, "%s", spec);
    char *first = buf, *second = NULL, *rest = NULL;
    char *colon = strchr(buf, ':');
    if (colon) {
        *colon = '\0';
        second = colon + 1;
        if ((colon = strchr(second, ':'))) {
            *colon = '\0';
            rest = colon + 1;
        }
    }
    /* PRESET:k=v,... : the second part holds options */
    if (second && !rest && strchr(second, '=')) {
        rest = second;
        second = NULL;
    }
    int st;
    char origin[128];
    snprintf(origin, sizeof origin, "--solver '%s'", spec);
    if (!second) {
        const SolverPreset *p = registry_find_preset(first);
        for (int i = 0; !p && i < COUNT(g_presets); ++i)
            if (!strcmp(g_presets[i].name, first) && absent_index(g_presets[i].inverse) >= 0)
                return not_built(spec, first, g_presets[i].inverse);
        if (!p) return mpm_error(MPM_EINPUT, "unknown solver '%s' (see: mpmbench list solvers)", first);
        out->preset = p;
        out->outer = registry_find_outer(p->outer);
        out->inverse = registry_find_inverse(p->inverse);
        if (!out->outer || !out->inverse)
            return mpm_error(MPM_EINTERNAL, "preset %s names an unregistered part (%s:%s)", p->name, p->outer,
                             p->inverse);
        char porigin[96];
        snprintf(porigin, sizeof porigin, "preset %s option", p->name);
        if ((st = solver_opts_set_list(&out->opts, p->options, porigin))) return st;
        snprintf(out->name, sizeof out->name, "%s", rest ? spec : p->name);
    } else {
        char known[256];
        if (!(out->outer = registry_find_outer(first))) {
            names_of(1, known, sizeof known);
            return mpm_error(MPM_EINPUT, "--solver '%s': unknown outer method '%s' (registered: %s)", spec, first, known);
        }
        if (!(out->inverse = registry_find_inverse(second))) {
            if (absent_index(second) >= 0) return not_built(spec, second, second);
            names_of(0, known, sizeof known);
            return mpm_error(MPM_EINPUT, "--solver '%s': unknown inverse approximation '%s' (registered: %s)", spec,
                             second, known);
        }
        snprintf(out->name, sizeof out->name, "%s", spec);
    }
    if (rest) {
        if (!rest[0]) return mpm_error(MPM_EINPUT, "%s: empty option list after ':'", origin);
        if ((st = solver_opts_set_list(&out->opts, rest, origin))) return st;
    }
    for (int i = 0; i < n_opts; ++i)
        if ((st = solver_opts_set(&out->opts, opts[i], "--solver-opt"))) return st;
    return MPM_OK;
}

int solver_from_spec(const char *spec, const char *const *opts, int n_opts, Solver **out)
{
    *out = NULL;
    SolverSpec sp;
    int st = solver_spec_parse(spec, opts, n_opts, &sp);
    if (st) return st;
    return solver_create(sp.name, sp.outer, sp.inverse, &sp.opts, out);
}

int solver_spec_check(const char *spec, const char *const *opts, int n_opts)
{
    Solver *s = NULL;
    int st = solver_from_spec(spec, opts, n_opts, &s);
    solver_destroy(s);
    return st;
}

void registry_print(FILE *f)
{
    for (int i = 0; i < COUNT(g_presets); ++i) {
        const SolverPreset *p = &g_presets[i];
        if (!preset_built(p)) continue;
        fprintf(f, "%-16s %s  [%s:%s%s%s]\n", p->name, p->description, p->outer, p->inverse, p->options[0] ? ":" : "",
                p->options);
    }
    fprintf(f, "\nouter methods (compose any pair: --solver OUTER:INVERSE[:key=value,...]):\n");
    for (int i = 0; i < COUNT(g_outer); ++i) fprintf(f, "  %-14s %s\n", g_outer[i]->name, g_outer[i]->description);
    fprintf(f, "\ninverse approximations:\n");
    for (int i = 0; i < COUNT(g_inverse); ++i) {
        /* the capabilities of an instance with default options */
        char caps[160] = "?";
        InvApprox *M = NULL;
        SolverOptions none = {0};
        if (inv_create(g_inverse[i], &none, &M) == MPM_OK) inv_caps_describe(M->caps, caps, sizeof caps);
        else mpm_clear_error();
        inv_destroy(M);
        fprintf(f, "  %-14s %s [%s]\n", g_inverse[i]->name, g_inverse[i]->description, caps);
    }
    fprintf(f, "\nline searches (option linesearch=NAME, default halving):\n");
    for (int i = 0; i < line_search_count(); ++i)
        fprintf(f, "  %-14s %s\n", line_search_get(i)->name, line_search_get(i)->description);
    fprintf(f, "\nstopping rules (option stop=NAME, default cn):\n");
    for (int i = 0; i < stop_rule_count(); ++i)
        fprintf(f, "  %-14s %s\n", stop_rule_get(i)->name, stop_rule_get(i)->description);
    int header = 0;
    for (int i = 0; i < COUNT(g_optional); ++i) {
        if (absent_index(g_optional[i].inverse) < 0) continue;
        if (!header++) fprintf(f, "\nnot in this build (optional adapters):\n");
        fprintf(f, "  %-14s configure with -D%s=ON (Debian package %s); presets:", g_optional[i].inverse,
                g_optional[i].option, g_optional[i].package);
        for (int k = 0; k < COUNT(g_presets); ++k)
            if (!strcmp(g_presets[k].inverse, g_optional[i].inverse)) fprintf(f, " %s", g_presets[k].name);
        fprintf(f, "\n");
    }
}
