#include "solvers/stop_rule.h"

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

/* the CN rule's L2 equivalent (SPEC 4; the HOT code's newton.tolerance
 * with --usecn) */
static double cn_gradient_tolerance(const StepProblem *pb, double eps) { return problem_tau(pb, eps); }

static double l2_gradient_tolerance(const StepProblem *pb, double tau)
{
    (void)pb;
    return tau;
}

static const StopRuleOps g_cn = {"cn", "node-wise characteristic norm s < eps (SPEC 4)", NULL, 0.0, cn_measure,
                                 cn_gradient_tolerance};
static const StopRuleOps g_l2 = {"l2", "plain L2 norm of the gradient ||g|| < tau (Gast et al. 2015)", "tau", 1e-3,
                                 l2_measure, l2_gradient_tolerance};
static const StopRuleOps *const g_rules[] = {&g_cn, &g_l2};

int stop_rule_count(void) { return (int)(sizeof g_rules / sizeof g_rules[0]); }

const StopRuleOps *stop_rule_get(int i) { return i >= 0 && i < stop_rule_count() ? g_rules[i] : NULL; }

const StopRuleOps *stop_rule_find(const char *name)
{
    for (int i = 0; i < stop_rule_count(); ++i)
        if (strcmp(g_rules[i]->name, name) == 0) return g_rules[i];
    return NULL;
}
