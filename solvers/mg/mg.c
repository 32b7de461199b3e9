/* Node-embedding Galerkin multigrid V-cycle (HOT paper §4, Algorithm 2;
 * reference §5.1-5.4; SPEC 6). See mg.h. */
#include "solvers/mg/mg.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/jacobi.h"
#include "solvers/mg/galerkin.h"
#include "solvers/mg/gmg_level.h"
#include "solvers/mg/transfer.h"
#include "solvers/pcg.h"
#include "solvers/sgs.h"

typedef struct {
    int n;
    const Bsr *A;          /* level 0: the input H; else &Aown */
    Bsr Aown;
    const int *coord;      /* level 0: input; else the finer transfer's coarse_coord */
    const NodeColoring *col;
    NodeColoring colown;
    const double *diag;    /* level 0: input; else diagown */
    double *diagown, *dinv;
    MgTransfer T;          /* to level l+1 */
    double *r, *u, *d, *work; /* 3n, 3n, 3n, 6n */
    int cap;               /* nodes the per-level arrays hold */
} MgLevel;

/* Block-Jacobi preconditioner of the coarse PCG, sharing a level's D^-1. */
typedef struct {
    InvApprox base;
    int n;
    const double *dinv;
} CoarseJacobi;

typedef struct {
    InvApprox base;
    MgEmbedding kind;
    int max_levels, sweeps, min_coarse, coarse_max_iters;
    double coarse_tol;
    int nlev;
    MgLevel lev[MG_MAX_LEVELS];
    const Projection *proj;
    PcgWork pw;
    MgGalerkinWork *gw;
    CoarseJacobi cj;
    MgInfo info;
    int rediscretize;            /* baseline GMG: coarse levels from particles */
    int gmg_bc_project;          /* GMG only: project coarse residuals at coarse Dirichlet nodes */
    GmgLevel gl[MG_MAX_LEVELS];  /* their particle copies and grids */
} Mg;

static int cj_apply(InvApprox *self, const double *r, double *z)
{
    CoarseJacobi *c = (CoarseJacobi *)self;
    vec_block_apply((size_t)c->n, c->dinv, r, z);
    return MPM_OK;
}
static const InvApproxOps coarse_jacobi_ops = {"mg-coarse-jacobi", NULL, NULL, cj_apply, NULL};

static void level_spmv(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }

static int level_reserve(MgLevel *L, int n, int own_diag)
{
    if (n <= L->cap) return MPM_OK;
    size_t c = (size_t)(n > 0 ? n : 1);
    double **arr[5] = {&L->dinv, &L->r, &L->u, &L->d, &L->work};
    size_t per[5] = {9, 3, 3, 3, 6};
    for (int k = 0; k < 5; ++k) {
        double *p = realloc(*arr[k], sizeof(double) * per[k] * c);
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid level (%d nodes)", n);
        *arr[k] = p;
    }
    if (own_diag || L->diagown) {
        double *p = realloc(L->diagown, sizeof(double) * 9 * c);
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid level (%d nodes)", n);
        L->diagown = p;
    }
    L->cap = n;
    return MPM_OK;
}

static int mg_create(MgEmbedding kind, int rediscretize, SolverOptions *opt, InvApprox **out)
{
    int st = MPM_OK;
    double levels = solver_opt_number(opt, "levels", 3, &st);
    double sweeps = solver_opt_number(opt, "sweeps", 1, &st);
    double minc = solver_opt_number(opt, "min_coarse_nodes", 300, &st);
    double ctol = solver_opt_number(opt, "coarse_tol", 0.5, &st);
    double cmax = solver_opt_number(opt, "coarse_max_iters", 10000, &st);
    double exact = solver_opt_number(opt, "coarse_exact", 0, &st);
    double flexible = solver_opt_number(opt, "flexible", 1, &st);
    double bc_project = rediscretize ? solver_opt_number(opt, "coarse_bc_project", 1, &st) : 0;
    if (st) return st;
    if (!rediscretize) { /* the Galerkin hierarchy's embedding kernel (SPEC 6) */
        const char *emb = solver_opt_string(opt, "embedding", kind == MG_EMBED_LINEAR ? "linear" : "quadratic");
        if (!strcmp(emb, "linear")) kind = MG_EMBED_LINEAR;
        else if (!strcmp(emb, "quadratic")) kind = MG_EMBED_QUADRATIC;
        else return mpm_error(MPM_EINPUT, "--solver-opt embedding=%s: expected linear or quadratic", emb);
    }
    if (!(levels >= 1 && levels <= MG_MAX_LEVELS && levels == floor(levels)))
        return mpm_error(MPM_EINPUT, "--solver-opt levels=%g: expected an integer in [1, %d]", levels, MG_MAX_LEVELS);
    if (!(sweeps >= 1 && sweeps <= 100 && sweeps == floor(sweeps)))
        return mpm_error(MPM_EINPUT, "--solver-opt sweeps=%g: expected an integer in [1, 100]", sweeps);
    if (!(minc >= 1 && minc <= 1e9))
        return mpm_error(MPM_EINPUT, "--solver-opt min_coarse_nodes=%g: expected a positive integer", minc);
    if (!(ctol > 0 && ctol < 1)) return mpm_error(MPM_EINPUT, "--solver-opt coarse_tol=%g: expected 0 < tol < 1", ctol);
    if (!(cmax >= 1 && cmax <= 1e9))
        return mpm_error(MPM_EINPUT, "--solver-opt coarse_max_iters=%g: expected a positive integer", cmax);
    Mg *M = calloc(1, sizeof *M);
    if (!M) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid");
    M->base.ops = rediscretize ? &inv_gmg_ops : kind == MG_EMBED_LINEAR ? &inv_mg_linear_ops : &inv_mg_quadratic_ops;
    M->kind = kind;
    M->rediscretize = rediscretize;
    M->gmg_bc_project = bc_project != 0;
    M->max_levels = (int)levels;
    M->sweeps = (int)sweeps;
    M->min_coarse = (int)minc;
    M->coarse_tol = exact != 0 ? 1e-12 : ctol;
    M->coarse_max_iters = (int)cmax;
    M->cj.base.ops = &coarse_jacobi_ops;
    /* the adaptive coarsest PCG makes the V-cycle vary with its input: outer
     * PCG uses flexible CG unless flexible=0 (the reference's plain PCG) */
    M->base.variable = flexible != 0 && levels > 1;
    *out = &M->base;
    return MPM_OK;
}

static int mg_linear_create(SolverOptions *opt, InvApprox **out)
{
    return mg_create(MG_EMBED_LINEAR, 0, opt, out);
}
static int mg_quadratic_create(SolverOptions *opt, InvApprox **out)
{
    return mg_create(MG_EMBED_QUADRATIC, 0, opt, out);
}
static int gmg_create(SolverOptions *opt, InvApprox **out) { return mg_create(MG_EMBED_LINEAR, 1, opt, out); }

static void fill_level_info(Mg *M, int l)
{
    const Bsr *A = M->lev[l].A;
    int mx = 0;
    for (int i = 0; i < A->n; ++i) {
        int c = (int)(A->row_ptr[i + 1] - A->row_ptr[i]);
        if (c > mx) mx = c;
    }
    M->info.n[l] = A->n;
    M->info.nnzb[l] = A->nnzb;
    M->info.avg_row[l] = A->n ? (double)A->nnzb / A->n : 0.0;
    M->info.max_row[l] = mx;
}

static int mg_setup(InvApprox *self, const InvSetupInput *in)
{
    Mg *M = (Mg *)self;
    double t0 = omp_get_wtime();
    self->stats = (InvStats){0};
    memset(&M->info, 0, sizeof M->info);
    M->info.embedding = (int)M->kind;
    M->info.rediscretized = M->rediscretize;
    M->nlev = 0;
    if (!in->H) return mpm_error(MPM_EINPUT, "multigrid needs an assembled matrix (not available matrix-free)");
    if (!in->coord || !in->coloring || !in->diag)
        return mpm_error(MPM_EINTERNAL, "multigrid: node coordinates, colouring and diagonal are required");
    if (in->H->n != in->n_nodes)
        return mpm_error(MPM_EINTERNAL, "multigrid: matrix has %d rows, expected %d", in->H->n, in->n_nodes);
    M->proj = in->proj;

    MgLevel *L0 = &M->lev[0];
    int st = level_reserve(L0, in->n_nodes, 0);
    if (st) return st;
    L0->n = in->n_nodes;
    L0->A = in->H;
    L0->coord = in->coord;
    L0->col = in->coloring;
    L0->diag = in->diag;
    double td = omp_get_wtime();
    if ((st = block_diag_invert(L0->n, L0->diag, L0->dinv, "multigrid level 0"))) return st;
    M->info.diag_s += omp_get_wtime() - td;
    int nl = 1;
    while (nl < M->max_levels && M->lev[nl - 1].n >= M->min_coarse) {
        MgLevel *F = &M->lev[nl - 1], *C = &M->lev[nl];
        double ta = omp_get_wtime();
        if (M->rediscretize) {
            /* baseline GMG: the level's own grid and Hessian from the
             * particles at spacing 2^l dx, linear transfers onto it */
            if (!in->problem) return mpm_error(MPM_EINTERNAL, "geometric multigrid needs the step problem");
            double h = in->problem->dx * (double)(1 << nl);
            if ((st = gmg_level_build(&M->gl[nl], in->problem, h, &C->Aown))) return st;
            if ((st = gmg_transfer_onto(&F->T, F->coord, F->n, &M->gl[nl].grid))) return st;
        } else if ((st = mg_transfer_build(&F->T, M->kind, F->coord, F->n))) {
            return st;
        }
        double tb = omp_get_wtime();
        M->info.transfer_s += tb - ta;
        int m = F->T.n_coarse;
        if (m == 0 || m >= F->n) break; /* no coarsening possible */
        if ((st = level_reserve(C, m, 1))) return st;
        C->n = m;
        C->coord = F->T.coarse_coord;
        if (!M->rediscretize && (st = mg_galerkin(F->A, &F->T, &C->Aown, &M->gw))) return st;
        C->A = &C->Aown;
        double tc = omp_get_wtime();
        M->info.galerkin_s += tc - tb;
        if ((st = node_coloring_build(C->coord, m, &C->colown))) return st;
        C->col = &C->colown;
        bsr_diagonal(C->A, C->diagown);
        C->diag = C->diagown;
        char what[32];
        snprintf(what, sizeof what, "multigrid level %d", nl);
        if ((st = block_diag_invert(m, C->diag, C->dinv, what))) return st;
        M->info.diag_s += omp_get_wtime() - tc;
        ++nl;
    }
    M->nlev = nl;
    M->info.n_levels = nl;
    for (int l = 0; l < nl; ++l) fill_level_info(M, l);
    M->cj.n = M->lev[nl - 1].n;
    M->cj.dinv = M->lev[nl - 1].dinv;
    M->info.setup_s = omp_get_wtime() - t0;
    self->stats.setup_s = M->info.setup_s;
    return MPM_OK;
}

/* `sweeps` symmetric GS sweeps on u (u = 0 on entry when `from_zero`),
 * keeping r = b - A u; the residual update after the last sweep is skipped
 * when `last_residual` is 0 (nobody reads it). */
static void smooth(Mg *M, int l, int from_zero, int last_residual)
{
    MgLevel *L = &M->lev[l];
    const size_t len = 3 * (size_t)L->n;
    for (int s = 0; s < M->sweeps; ++s) {
        double *target = (from_zero && s == 0) ? L->u : L->d;
        sgs_sweep(L->A, L->dinv, L->col, L->r, target, L->work);
        if (target == L->d) vec_axpy(len, 1.0, L->d, L->u);
        if (s + 1 < M->sweeps || last_residual) bsr_spmv_sub(L->A, target, L->r);
    }
}

/* coarse = R_l fine. On a rediscretised (GMG) level the coarse residual is
 * also projected at that level's own Dirichlet nodes: the coarse space is
 * its free nodes only. Their identity rows would otherwise turn the
 * restricted force-like residual there into a velocity correction of the
 * wrong scale (off by m_I + dt^2 k_I, ~1e4 for aluminium), which the linear
 * prolongation hands to the free fine nodes near every collider. The
 * Galerkin levels need nothing: R A_bc P inherits the BCs (reference §5.1). */
static void restrict_level(const Mg *M, int l, const double *fine, double *coarse)
{
    mg_restrict(&M->lev[l].T, fine, coarse);
    if (M->gmg_bc_project) problem_project(&M->gl[l + 1].pb, coarse);
}

static int mg_apply(InvApprox *self, const double *in, double *out)
{
    Mg *M = (Mg *)self;
    double t_start = omp_get_wtime();
    if (M->nlev == 0) return mpm_error(MPM_EINTERNAL, "multigrid applied before setup");
    const int nl = M->nlev;
    const int c = nl - 1;
    MgLevel *Lc = &M->lev[c];
    const size_t lenc = 3 * (size_t)Lc->n;
    PcgResult res;
    int st;

    /* tolerance of the coarse solve from the input restricted straight down
     * (reference §5.3): coarse_tol * sqrt(bbar^T D^-1 bbar) */
    double t0 = omp_get_wtime();
    const double *bbar = in;
    for (int l = 0; l < c; ++l) {
        restrict_level(M, l, bbar, M->lev[l + 1].d);
        bbar = M->lev[l + 1].d;
    }
    vec_block_apply((size_t)Lc->n, Lc->dinv, bbar, Lc->work);
    double bnorm2 = vec_dot(lenc, bbar, Lc->work);
    PcgOptions po = {.stop = PCG_ABSOLUTE, .abs_tol = M->coarse_tol * sqrt(fmax(bnorm2, 0.0)),
                     .max_iters = M->coarse_max_iters};
    M->info.transfer_apply_s += omp_get_wtime() - t0;

    if (nl == 1) { /* LBFGS-H: block-Jacobi PCG on the fine level */
        LinearOp op = {.n_nodes = Lc->n, .apply = level_spmv, .ctx = Lc->A};
        t0 = omp_get_wtime();
        st = pcg_solve(&op, &M->cj.base, M->proj, in, out, &po, &M->pw, &res);
        M->info.coarse_s += omp_get_wtime() - t0;
    } else {
        vec_copy(3 * (size_t)M->lev[0].n, in, M->lev[0].r);
        for (int l = 0; l < c; ++l) {
            MgLevel *L = &M->lev[l];
            t0 = omp_get_wtime();
            smooth(M, l, 1, 1);
            double t1 = omp_get_wtime();
            restrict_level(M, l, L->r, M->lev[l + 1].r);
            M->info.smooth_s[l] += t1 - t0;
            M->info.transfer_apply_s += omp_get_wtime() - t1;
        }
        LinearOp op = {.n_nodes = Lc->n, .apply = level_spmv, .ctx = Lc->A};
        t0 = omp_get_wtime();
        st = pcg_solve(&op, &M->cj.base, NULL, Lc->r, Lc->u, &po, &M->pw, &res);
        M->info.coarse_s += omp_get_wtime() - t0;
        for (int l = c - 1; l >= 0 && !st; --l) {
            MgLevel *L = &M->lev[l];
            const size_t len = 3 * (size_t)L->n;
            t0 = omp_get_wtime();
            mg_prolong(&L->T, M->lev[l + 1].u, L->d);
            vec_axpy(len, 1.0, L->d, L->u);
            bsr_spmv_sub(L->A, L->d, L->r);
            double t1 = omp_get_wtime();
            smooth(M, l, 0, 0);
            M->info.transfer_apply_s += t1 - t0;
            M->info.smooth_s[l] += omp_get_wtime() - t1;
        }
        if (!st) vec_copy(3 * (size_t)M->lev[0].n, M->lev[0].u, out);
    }
    if (st) return st;
    self->stats.inner_iters += res.iters;
    M->info.coarse_iters += res.iters;
    M->info.coarse_capped += res.capped;
    M->info.vcycles++;
    self->stats.apply_s += omp_get_wtime() - t_start;
    return MPM_OK;
}

static void mg_destroy(InvApprox *self)
{
    if (!self) return;
    Mg *M = (Mg *)self;
    for (int l = 0; l < MG_MAX_LEVELS; ++l) {
        MgLevel *L = &M->lev[l];
        bsr_free(&L->Aown);
        node_coloring_free(&L->colown);
        mg_transfer_free(&L->T);
        free(L->diagown);
        free(L->dinv);
        free(L->r);
        free(L->u);
        free(L->d);
        free(L->work);
        gmg_level_free(&M->gl[l]);
    }
    pcg_work_free(&M->pw);
    mg_galerkin_work_free(M->gw);
    free(M);
}

int mg_is_multigrid(const InvApprox *self)
{
    return self && (self->ops == &inv_mg_linear_ops || self->ops == &inv_mg_quadratic_ops || self->ops == &inv_gmg_ops);
}

int mg_get_info(const InvApprox *self, MgInfo *info)
{
    if (!self || (self->ops != &inv_mg_linear_ops && self->ops != &inv_mg_quadratic_ops && self->ops != &inv_gmg_ops))
        return mpm_error(MPM_EINTERNAL, "mg_get_info: not a multigrid inverse approximation");
    *info = ((const Mg *)self)->info;
    return MPM_OK;
}

void mg_print_info(const MgInfo *info, FILE *f)
{
    fprintf(f, "multigrid (%s): %d levels, setup %.4f s (transfer %.4f, galerkin %.4f, diagonal %.4f)\n",
            info->rediscretized ? "geometric, rediscretised from particles"
            : info->embedding == MG_EMBED_LINEAR ? "linear embedding" : "quadratic embedding",
            info->n_levels, info->setup_s,
            info->transfer_s, info->galerkin_s, info->diag_s);
    for (int l = 0; l < info->n_levels; ++l)
        fprintf(f, "  level %d: %8d nodes %10lld blocks  blocks/row avg %6.1f max %4d  smooth %.4f s\n", l, info->n[l],
                (long long)info->nnzb[l], info->avg_row[l], info->max_row[l], info->smooth_s[l]);
    if (info->vcycles)
        fprintf(f, "  %ld V-cycles: coarse PCG %ld iterations (%.1f per cycle, %ld capped), coarse %.4f s, transfers %.4f s\n",
                info->vcycles, info->coarse_iters, (double)info->coarse_iters / info->vcycles, info->coarse_capped,
                info->coarse_s, info->transfer_apply_s);
}

const InvApproxOps inv_mg_linear_ops = {"mg-linear", mg_linear_create, mg_setup, mg_apply, mg_destroy};
const InvApproxOps inv_mg_quadratic_ops = {"mg-quadratic", mg_quadratic_create, mg_setup, mg_apply, mg_destroy};
const InvApproxOps inv_gmg_ops = {"gmg", gmg_create, mg_setup, mg_apply, mg_destroy};
