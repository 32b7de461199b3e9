#include "solvers/stop_rule.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "core/vec.h"

static double cn_measure(const StepProblem *pb, const double *g, double cn_residual)
{
    (void)pb;
    (void)g;
    return cn_residual;
}

static double l2_measure(const StepProblem *pb, const double *g, double cn_residual)
{
    (void)cn_residual;
    return vec_norm(3 * (size_t)pb->n_nodes, g);
}

/* cn and l2 decide at the iterate only */
static double no_direction_measure(double gTp, double E0, double E)
{
    (void)gTp;
    (void)E0;
    (void)E;
    return INFINITY;
}

/* The decrement rule decides on the direction only, except at an exact
 * stationary point (g = 0), where no direction has anything to gain. */
static double decrement_iterate_measure(const StepProblem *pb, const double *g, double cn_residual)
{
    (void)pb;
    (void)g;
    return cn_residual == 0.0 ? 0.0 : INFINITY;
}

/* SPEC 4.1: d = -g^T p / 2 is the decrease of the quadratic model along p,
 * i.e. E(x_k) - E(x*) for a Newton step on a quadratic; relative to the
 * step's estimated total decrease E_0 - E* ~ (E_0 - E_k) + d, so at
 * iteration 0 the measure is 1 and only g = 0 stops there. */
double stop_decrement_measure(double gTp, double E0, double E)
{
    if (!(gTp <= 0.0) || !isfinite(E0) || !isfinite(E)) return INFINITY; /* no descent direction: no estimate */
    double d = -0.5 * gTp;
    if (d == 0.0) return 0.0; /* g = 0 (or p = 0): nothing left to gain */
    /* what the energy cannot resolve: its round-off, so E_0 - E_k is noise
     * and no line search could realise d either */
    if (d <= 8.0 * DBL_EPSILON * fmax(fabs(E0), fabs(E))) return 0.0;
    double gained = fmax(E0 - E, 0.0);
    return d / (gained + d);
}

/* the CN rule's L2 equivalent (SPEC 4; the HOT code's newton.tolerance
 * with --usecn) */
static double cn_gradient_tolerance(const StepProblem *pb, double eps) { return problem_tau(pb, eps); }

static double l2_gradient_tolerance(const StepProblem *pb, double tau)
{
    (void)pb;
    return tau;
}

static const StopRuleOps g_cn = {"cn", "node-wise characteristic norm s < eps (SPEC 4)", NULL, 0.0, cn_measure,
                                 no_direction_measure, cn_gradient_tolerance};
static const StopRuleOps g_l2 = {"l2", "plain L2 norm of the gradient ||g|| < tau (Gast et al. 2015)", "tau", 1e-3,
                                 l2_measure, no_direction_measure, l2_gradient_tolerance};
/* the forcing terms' tau_g: the CN floor of the same eps (a floor only) */
static const StopRuleOps g_decrement = {
    "decrement", "Newton decrement: energy still to gain / energy of the step < eps (SPEC 4.1)", NULL, 0.0,
    decrement_iterate_measure, stop_decrement_measure, cn_gradient_tolerance};
static const StopRuleOps *const g_rules[] = {&g_cn, &g_l2, &g_decrement};

int stop_rule_count(void) { return (int)(sizeof g_rules / sizeof g_rules[0]); }

const StopRuleOps *stop_rule_get(int i) { return i >= 0 && i < stop_rule_count() ? g_rules[i] : NULL; }

const StopRuleOps *stop_rule_find(const char *name)
{
    for (int i = 0; i < stop_rule_count(); ++i)
        if (strcmp(g_rules[i]->name, name) == 0) return g_rules[i];
    return NULL;
}
