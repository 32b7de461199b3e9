#include "experiments/registry.h"

#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "adapters/cholmod_direct.h"
#include "adapters/hypre_amg.h"
#include "solvers/jacobi.h"
#include "solvers/mg/mg.h"
#include "solvers/pcg_inverse.h"
#include "solvers/sgs.h"

static const SolverPreset g_presets[] = {
    {"pn-pcg", "projected Newton, PCG with 3x3 block-Jacobi on the assembled Hessian (HOT PN-PCG)", METHOD_PN,
     &inv_block_jacobi_ops, 0, ""},
    {"pn-pcg-scalar", "projected Newton, PCG with scalar (diagonal) Jacobi on the assembled Hessian", METHOD_PN,
     &inv_scalar_jacobi_ops, 0, ""},
    {"pn-pcg-mf", "projected Newton, matrix-free PCG with 3x3 block-Jacobi (HOT PN-PCG(MF))", METHOD_PN,
     &inv_block_jacobi_ops, 1, ""},
    {"pn-sgs-pcg", "projected Newton, PCG preconditioned by one coloured symmetric block Gauss-Seidel sweep (HOT Table 3)",
     METHOD_PN, &inv_sgs_ops, 0, ""},
    {"pn-mgpcg", "projected Newton, PCG preconditioned by one node-embedding Galerkin V-cycle, rebuilt every iteration (HOT PN-MGPCG)",
     METHOD_PN, &inv_mg_linear_ops, 0, ""},
    {"pn-amg-pcg", "projected Newton, PCG preconditioned by one hypre BoomerAMG V-cycle (algebraic baseline)", METHOD_PN,
     &inv_boomeramg_ops, 0, ""},
    {"pn-cholmod", "projected Newton with exact CHOLMOD Cholesky solves (exact-Newton reference)", METHOD_PN,
     &inv_cholmod_ops, 0, ""},
    {"hot", "L-BFGS, initial inverse = one linear-embedding Galerkin multigrid V-cycle built once per step (HOT)",
     METHOD_LBFGS, &inv_mg_linear_ops, 0, ""},
    {"hot-quadratic", "HOT with the quadratic embedding kernel", METHOD_LBFGS, &inv_mg_quadratic_ops, 0, ""},
    {"lbfgs-gmg", "L-BFGS, initial inverse = one V-cycle of particle-rediscretised geometric multigrid (HOT LBFGS-GMG)",
     METHOD_LBFGS, &inv_gmg_ops, 0, ""},
    {"pn-gmgpcg", "projected Newton, PCG preconditioned by the particle-rediscretised geometric multigrid V-cycle",
     METHOD_PN, &inv_gmg_ops, 0, ""},
    {"lbfgs-h", "L-BFGS, initial inverse = inexact block-Jacobi PCG on the start-of-step Hessian (HOT LBFGS-H)",
     METHOD_LBFGS, &inv_inexact_pcg_ops, 0, ""},
    {"lbfgs-h-direct", "L-BFGS, initial inverse = CHOLMOD factor of the start-of-step Hessian (Li et al. 2019)",
     METHOD_LBFGS, &inv_cholmod_ops, 0, ""},
    {"lbfgs-amg", "L-BFGS, initial inverse = one hypre BoomerAMG V-cycle", METHOD_LBFGS, &inv_boomeramg_ops, 0, ""},
};

int registry_count(void) { return (int)(sizeof g_presets / sizeof g_presets[0]); }

const SolverPreset *registry_get(int i) { return (i >= 0 && i < registry_count()) ? &g_presets[i] : NULL; }

const SolverPreset *registry_find(const char *name)
{
    for (int i = 0; i < registry_count(); ++i)
        if (strcmp(g_presets[i].name, name) == 0) return &g_presets[i];
    return NULL;
}

static int set_option(SolverOptions *o, const char *kv, const char *origin)
{
    const char *eq = strchr(kv, '=');
    if (!eq || eq == kv || !eq[1])
        return mpm_error(MPM_EINPUT, "%s '%s': expected key=value", origin, kv);
    size_t klen = (size_t)(eq - kv);
    if (klen >= sizeof o->key[0] || strlen(eq + 1) >= sizeof o->value[0])
        return mpm_error(MPM_EINPUT, "%s '%s': key or value too long", origin, kv);
    int slot = -1;
    for (int i = 0; i < o->n; ++i)
        if (strlen(o->key[i]) == klen && strncmp(o->key[i], kv, klen) == 0) slot = i;
    if (slot < 0) {
        if (o->n >= (int)(sizeof o->key / sizeof o->key[0]))
            return mpm_error(MPM_EINPUT, "%s: too many solver options", origin);
        slot = o->n++;
    }
    memcpy(o->key[slot], kv, klen);
    o->key[slot][klen] = '\0';
    strcpy(o->value[slot], eq + 1);
    return MPM_OK;
}

int registry_options(const SolverPreset *p, const char *const *user, int n_user, SolverOptions *out)
{
    memset(out, 0, sizeof *out);
    char buf[256];
    snprintf(buf, sizeof buf, "%s", p->defaults ? p->defaults : "");
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        int st = set_option(out, tok, "preset option");
        if (st) return st;
    }
    for (int i = 0; i < n_user; ++i) {
        int st = set_option(out, user[i], "--solver-opt");
        if (st) return st;
    }
    return MPM_OK;
}
