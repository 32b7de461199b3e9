/* The InvApprox wrappers: object state and counters every implementation
 * shares (see inverse_approx.h). */
#include "solvers/inverse_approx.h"

#include <string.h>

#include "core/error.h"
#include "core/step_phases.h"

void inv_view_add(InvView *v, const char *key, double value)
{
    if (!v || v->n_stats >= INV_VIEW_MAX_STATS) return;
    snprintf(v->stat[v->n_stats].key, sizeof v->stat[0].key, "%s", key);
    v->stat[v->n_stats].value = value;
    v->n_stats++;
}

int inv_events(EventId *setup, EventId *apply)
{
    EventId phase[STEP_PHASES];
    int st = step_phases_register(phase);
    *setup = phase[STEP_SETUP];
    /* inside the solve's remainder: the direction (PCG, the two-loop recursion) */
    if (!st) st = event_register("inverse_apply", phase[STEP_SOLVE], apply);
    return st;
}

int inv_create(const InvApproxOps *ops, SolverOptions *opt, InvApprox **out)
{
    *out = NULL;
    if (!ops) return mpm_error(MPM_EINTERNAL, "inv_create: no inverse approximation (not in this build?)");
    /* the reuse options, shared by every implementation (docs/solvers.md
     * "Setup reuse"); read here so that each is one option, not one per
     * implementation */
    int st = MPM_OK;
    int every = solver_opt_int(opt, "reuse_every", 1, 0, 1000000, &st);
    int across = solver_opt_int(opt, "reuse_across_steps", 0, 0, 1, &st);
    int refresh = solver_opt_int(opt, "reuse_refresh", 1, 0, 1, &st);
    if (st) return st;
    if (!ops->reuse && (every != 1 || across))
        return mpm_error(MPM_EINPUT,
                         "solver option reuse_every=%d, reuse_across_steps=%d: inverse approximation '%s' cannot "
                         "reuse its setup (expected reuse_every=1, reuse_across_steps=0)",
                         every, across, ops->name);
    EventId setup_event, apply_event;
    if ((st = inv_events(&setup_event, &apply_event))) return st;
    InvApprox *M = NULL;
    st = ops->create(opt, &M);
    if (st) return st;
    M->ops = ops;
    event_log_reset(&M->own_log);
    M->log = &M->own_log;
    M->setup_event = setup_event;
    M->apply_event = apply_event;
    M->ready = 0;
    M->inner_banked = 0;
    M->reuse_every = every;
    M->reuse_across_steps = across;
    M->reuse_refresh = refresh;
    M->solve_requests = 0;
    M->since_rebuild = 0;
    M->have_key = 0;
    memset(&M->reuse, 0, sizeof M->reuse);
    *out = M;
    return MPM_OK;
}

void inv_begin_solve(InvApprox *M) { M->solve_requests = 0; }

/* FNV-1a over the node count, the coordinates and the matrix pattern id:
 * equal keys mean the same active nodes in the same order with the same
 * couplings (the grid's node order is a function of the coordinates). */
static uint64_t reuse_key(const InvSetupInput *in)
{
    uint64_t h = 1469598103934665603ull;
#define MIX(v) (h = (h ^ (uint64_t)(v)) * 1099511628211ull)
    MIX(in->n_nodes);
    MIX(in->H ? in->H->pattern_id : 0u);
    MIX(in->H ? (uint64_t)in->H->nnzb : 0u);
    if (in->coord)
        for (size_t k = 0; k < 3 * (size_t)in->n_nodes; ++k) MIX((uint32_t)in->coord[k]);
#undef MIX
    return h;
}

int inv_setup(InvApprox *M, const InvSetupInput *in)
{
    M->inner_banked += M->stats.inner_iters; /* the implementation restarts its count */
    M->stats.inner_iters = 0;
    M->stats.apply_s = 0.0;
    const double before = event_log_seconds(M->log, M->setup_event);
    int st = event_log_begin(M->log, M->setup_event);
    if (st) return st;
    const int first = M->solve_requests++ == 0;
    M->reuse.requests++;
    int reuse = 0;
    uint64_t key = 0;
    if (M->ops->reuse) {
        key = reuse_key(in);
        /* what the options allow, then whether the kept setup fits */
        int allowed = M->ready && M->have_key && (!first || M->reuse_across_steps) &&
                      (M->reuse_every == 0 || M->since_rebuild < M->reuse_every);
        reuse = allowed && key == M->key;
        if (in->comm) { /* over ranks every rank reuses or none does: a setup is collective */
            double rebuild = !reuse;
            if (in->comm->max(in->comm->ctx, &rebuild, 1)) {
                event_log_end_with(M->log, M->setup_event, MPM_EINTERNAL);
                return mpm_error(MPM_EINTERNAL, "%s: the ranks could not agree on setup reuse", M->ops->name);
            }
            reuse = rebuild == 0.0;
        }
        if (allowed && !reuse) M->reuse.pattern_misses++;
    }
    if (reuse) {
        int refreshed = 0;
        st = M->ops->reuse(M, in, M->reuse_refresh, &refreshed);
        if (!st && refreshed) M->reuse.refreshes++;
        else if (!st) M->reuse.lagged++;
        M->since_rebuild++;
    } else {
        M->ready = 0;
        M->have_key = 0;
        st = M->ops->setup(M, in);
        M->reuse.rebuilds++;
        M->since_rebuild = 1;
        M->key = key;
        M->have_key = st == MPM_OK && M->ops->reuse;
    }
    if (st) M->have_key = 0; /* a failed reuse leaves nothing to reuse */
    st = event_log_end_with(M->log, M->setup_event, st);
    M->stats.setup_s = event_log_seconds(M->log, M->setup_event) - before;
    M->ready = st == MPM_OK;
    return st;
}

int inv_apply(InvApprox *M, const double *r, double *z)
{
    if (!M->ready) return mpm_error(MPM_EINTERNAL, "%s: applied without a successful setup", M->ops->name);
    const double before = event_log_seconds(M->log, M->apply_event);
    int st = event_log_begin(M->log, M->apply_event);
    if (st) return st;
    st = event_log_end_with(M->log, M->apply_event, M->ops->apply(M, r, z));
    M->stats.apply_s += event_log_seconds(M->log, M->apply_event) - before;
    return st;
}

void inv_view(const InvApprox *M, FILE *f, InvView *out)
{
    if (out) memset(out, 0, sizeof *out);
    if (M->ops->view) M->ops->view(M, f, out);
    if (!M->ops->reuse) return;
    const InvReuseStats *r = &M->reuse;
    if (f)
        fprintf(f, "  setup reuse (reuse_every %d, across steps %d, refresh %d): %ld requests, %ld rebuilds, %ld "
                   "refreshes, %ld lagged, %ld pattern misses\n",
                M->reuse_every, M->reuse_across_steps, M->reuse_refresh, r->requests, r->rebuilds, r->refreshes,
                r->lagged, r->pattern_misses);
    inv_view_add(out, "setup_requests", (double)r->requests);
    inv_view_add(out, "rebuilds", (double)r->rebuilds);
    inv_view_add(out, "refreshes", (double)r->refreshes);
    inv_view_add(out, "lagged", (double)r->lagged);
    inv_view_add(out, "pattern_misses", (double)r->pattern_misses);
}

void inv_destroy(InvApprox *M)
{
    if (M) M->ops->destroy(M);
}

long inv_inner_iters(const InvApprox *M) { return M->inner_banked + M->stats.inner_iters; }

void inv_caps_describe(unsigned caps, char *buf, size_t len)
{
    static const struct {
        unsigned flag;
        const char *text;
    } names[] = {{INV_NEEDS_HESSIAN, "needs the assembled Hessian"}, {INV_MATRIX_FREE, "works matrix-free"},
                 {INV_NEEDS_PROBLEM, "needs the step problem"},    {INV_VARIABLE, "variable"},
                 {INV_SYMMETRIC, "symmetric"},                     {INV_POSITIVE, "positive"},
                 {INV_INNER_ITERS, "inner iterations"},            {INV_DISTRIBUTED, "across ranks"}};
    size_t used = 0;
    if (len) buf[0] = '\0';
    for (size_t k = 0; k < sizeof names / sizeof names[0] && used < len; ++k)
        if (caps & names[k].flag)
            used += (size_t)snprintf(buf + used, len - used, "%s%s", used ? ", " : "", names[k].text);
}
