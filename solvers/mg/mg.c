/* Node-embedding Galerkin multigrid V-cycle (HOT paper §4, Algorithm 2;
 * reference §5.1-5.4; SPEC 6). See mg.h. */
#include "solvers/mg/mg.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/mg/galerkin.h"
#include "solvers/mg/gmg_level.h"
#include "solvers/mg/embedding.h"
#include "solvers/krylov/pcg.h"
#include "solvers/inverse/sgs.h"

/* What the view op reports: the hierarchy of the last setup and the work
 * done by V-cycles since. (The time of each part is in the event log.) */
typedef struct {
    int n_levels;
    int embedding;                     /* MgEmbedding */
    int rediscretized;                 /* baseline GMG */
    int n[MG_MAX_LEVELS];              /* nodes per level */
    int64_t nnzb[MG_MAX_LEVELS];       /* stored blocks per level */
    double avg_row[MG_MAX_LEVELS];     /* nonzero blocks per row, mean */
    int max_row[MG_MAX_LEVELS];        /* and max */
    long vcycles, coarse_iters, coarse_capped; /* since the last setup */
} MgInfo;

/* The sub-phases, events of the log the wrappers time setup and apply in
 * (InvApprox.log), registered by mg_create. */
typedef struct {
    EventId transfers;    /* setup: transfer operators (GMG: also the rediscretised levels) */
    EventId galerkin;     /* setup: Galerkin products R A P */
    EventId diagonal;     /* setup: coarse colourings, block diagonals and their inverses */
    EventId single;       /* setup: single-precision matrix copies (smoother_precision=single) */
    EventId transfer_apply;            /* apply: restrictions, prolongations, their residual updates */
    EventId coarse;                    /* apply: the coarsest level's PCG */
    EventId smooth[MG_MAX_LEVELS - 1]; /* apply: the smoothing of each level but the coarsest */
} MgEvents;

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
    float *valf;           /* smoother_precision=single: A's values in single precision (levels that smooth) */
    int64_t capf;
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
    int single;                  /* smoother_precision=single (SPEC 6.10) */
    double coarse_tol;
    int nlev;
    MgLevel lev[MG_MAX_LEVELS];
    const Projection *proj;
    PcgWork pw;
    MgGalerkinWork *gw;
    CoarseJacobi cj;
    MgInfo info;
    MgEvents ev;
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
static const InvApproxOps coarse_jacobi_ops = {"mg-coarse-jacobi", "the coarsest level's block Jacobi", NULL, NULL,
                                               cj_apply, NULL, NULL, NULL, NULL, NULL};

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

static int register_events(int levels, MgEvents *ev)
{
    EventId setup, apply;
    int st = inv_events(&setup, &apply);
    if (!st) st = event_register("mg_transfers", setup, &ev->transfers);
    if (!st) st = event_register("mg_galerkin", setup, &ev->galerkin);
    if (!st) st = event_register("mg_diagonal", setup, &ev->diagonal);
    if (!st) st = event_register("mg_single", setup, &ev->single);
    if (!st) st = event_register("mg_transfer_apply", apply, &ev->transfer_apply);
    if (!st) st = event_register("mg_coarse", apply, &ev->coarse);
    for (int l = 0; l < MG_MAX_LEVELS - 1; ++l) ev->smooth[l] = EVENT_NONE;
    for (int l = 0; l + 1 < levels && !st; ++l) {
        char name[EVENT_NAME_MAX + 1];
        snprintf(name, sizeof name, "mg_smooth_l%d", l);
        st = event_register(name, apply, &ev->smooth[l]);
    }
    return st;
}

static int mg_create(SolverOptions *opt, InvApprox **out)
{
    int st = MPM_OK;
    int rediscretize = solver_opt_int(opt, "rediscretize", 0, 0, 1, &st);
    int levels = solver_opt_int(opt, "levels", 3, 1, MG_MAX_LEVELS, &st);
    int sweeps = solver_opt_int(opt, "sweeps", 1, 1, 100, &st);
    int minc = solver_opt_int(opt, "min_coarse_nodes", 300, 1, 1000000000, &st);
    double ctol = solver_opt_number(opt, "coarse_tol", 0.5, &st);
    int cmax = solver_opt_int(opt, "coarse_max_iters", 10000, 1, 1000000000, &st);
    int exact = solver_opt_int(opt, "coarse_exact", 0, 0, 1, &st);
    int flexible = solver_opt_int(opt, "flexible", 1, 0, 1, &st);
    int single = 0;
    if (!st) { /* the matrix the smoother and the residual updates read (SPEC 6.10) */
        const char *prec = solver_opt_string(opt, "smoother_precision", "double");
        if (!strcmp(prec, "single")) single = 1;
        else if (strcmp(prec, "double") != 0)
            st = mpm_error(MPM_EINPUT, "solver option smoother_precision=%s: expected double or single", prec);
    }
    /* only where it applies, so that a misplaced option is reported as unknown */
    int bc_project = rediscretize ? solver_opt_int(opt, "coarse_bc_project", 1, 0, 1, &st) : 0;
    MgEmbedding kind = MG_EMBED_LINEAR;
    if (!st && !rediscretize) { /* the Galerkin hierarchy's embedding kernel (SPEC 6) */
        const char *emb = solver_opt_string(opt, "embedding", "linear");
        if (!strcmp(emb, "quadratic")) kind = MG_EMBED_QUADRATIC;
        else if (strcmp(emb, "linear") != 0)
            st = mpm_error(MPM_EINPUT, "solver option embedding=%s: expected linear or quadratic", emb);
    }
    if (st) return st;
    if (!(ctol > 0 && ctol < 1)) return mpm_error(MPM_EINPUT, "solver option coarse_tol=%g: expected 0 < tol < 1", ctol);
    MgEvents ev;
    if ((st = register_events(levels, &ev))) return st;
    Mg *M = calloc(1, sizeof *M);
    if (!M) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid");
    M->ev = ev;
    M->base.ops = &inv_mg_ops;
    M->kind = kind;
    M->rediscretize = rediscretize;
    M->gmg_bc_project = bc_project;
    M->max_levels = levels;
    M->sweeps = sweeps;
    M->single = single;
    M->min_coarse = minc;
    M->coarse_tol = exact ? 1e-12 : ctol;
    M->coarse_max_iters = cmax;
    M->cj.base.ops = &coarse_jacobi_ops;
    M->cj.base.ready = 1; /* shares the level's D^-1, set up with the hierarchy */
    /* the adaptive coarsest PCG makes the V-cycle vary with its input (to
     * 1e-12 with coarse_exact=1: then symmetric, as tests/unit/test_mg.c checks);
     * outer PCG uses flexible CG unless flexible=0 (the reference's plain PCG) */
    M->base.caps = INV_NEEDS_HESSIAN | INV_POSITIVE | INV_INNER_ITERS | (rediscretize ? INV_NEEDS_PROBLEM : 0u) |
                   (exact ? INV_SYMMETRIC : INV_VARIABLE);
    M->base.flexible = flexible && levels > 1;
    *out = &M->base;
    return MPM_OK;
}

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

/* smoother_precision=single: the single-precision values of levels
 * from..nlev-2 (the coarsest level does not smooth: its PCG reads the
 * doubles). Called whenever such a level's matrix changes. */
static int copy_single(Mg *M, int from)
{
    for (int l = from; l < M->nlev - 1; ++l) {
        MgLevel *L = &M->lev[l];
        int st = bsr_values_single(L->A, &L->valf, &L->capf);
        if (st) return st;
    }
    return MPM_OK;
}

static int single_copies(Mg *M, int from)
{
    if (!M->single) return MPM_OK;
    int st = event_log_begin(M->base.log, M->ev.single);
    if (!st) st = event_log_end_with(M->base.log, M->ev.single, copy_single(M, from));
    return st;
}

/* r -= A x on level l, with the matrix the smoother reads */
static void level_residual(const Mg *M, int l, const double *x, double *r)
{
    const MgLevel *L = &M->lev[l];
    if (M->single) bsr_spmv_sub_single(L->A, L->valf, x, r);
    else bsr_spmv_sub(L->A, x, r);
}

/* The inverse of level l's diagonal blocks. */
static int invert_diagonal(MgLevel *L, int l)
{
    char what[32];
    snprintf(what, sizeof what, "multigrid level %d", l);
    return block_diag_invert(L->n, L->diag, L->dinv, what);
}

/* Coarse level l's diagonal blocks from its matrix, and their inverse. */
static int coarse_diagonal(MgLevel *C, int l)
{
    bsr_diagonal(C->A, C->diagown);
    C->diag = C->diagown;
    return invert_diagonal(C, l);
}

/* Galerkin products and block-diagonal inverses of levels from..nlev-1
 * (level `from` >= 1 gets A from the finer level's A), on the kept
 * transfers, coarse node sets and colourings. */
static int mg_galerkin_levels(Mg *M, int from)
{
    EventLog *log = M->base.log;
    for (int l = from; l < M->nlev; ++l) {
        MgLevel *F = &M->lev[l - 1], *C = &M->lev[l];
        int st = event_log_begin(log, M->ev.galerkin);
        if (!st) st = event_log_end_with(log, M->ev.galerkin, mg_galerkin(F->A, &F->T, &C->Aown, &M->gw));
        if (!st && !(st = event_log_begin(log, M->ev.diagonal)))
            st = event_log_end_with(log, M->ev.diagonal, coarse_diagonal(C, l));
        if (st) return st;
    }
    return MPM_OK;
}

/* Level 0's diagonal inverse, timed as a diagonal. */
static int fine_diagonal(Mg *M)
{
    int st = event_log_begin(M->base.log, M->ev.diagonal);
    if (!st) st = event_log_end_with(M->base.log, M->ev.diagonal, invert_diagonal(&M->lev[0], 0));
    return st;
}

/* Setup reuse (inverse_approx.h): the same fine nodes and pattern. The fine
 * level always takes the new H and its diagonal (the smoother must see the
 * matrix it smooths; a symmetric GS sweep on the current H keeps the V-cycle
 * positive whatever SPD coarse operators it is combined with). values = 1
 * recomputes the Galerkin products on the kept transfers (not for the
 * rediscretised GMG, whose coarse levels come from particles: kept). */
static int mg_reuse(InvApprox *self, const InvSetupInput *in, int values, int *refreshed)
{
    Mg *M = (Mg *)self;
    *refreshed = 0;
    if (M->nlev == 0 || !in->H || in->H->n != M->lev[0].n)
        return mpm_error(MPM_EINTERNAL, "multigrid: reused for a different matrix");
    MgLevel *L0 = &M->lev[0];
    M->proj = in->proj;
    L0->A = in->H;
    L0->coord = in->coord;
    L0->col = in->coloring;
    L0->diag = in->diag;
    int st = fine_diagonal(M);
    if (st) return st;
    if (values && !M->rediscretize && M->nlev > 1) {
        if ((st = mg_galerkin_levels(M, 1))) return st;
        for (int l = 0; l < M->nlev; ++l) fill_level_info(M, l);
        *refreshed = 1;
        return single_copies(M, 0);
    }
    /* the fine level has the new H; the coarser copies are kept with their levels */
    if (M->single && M->nlev > 1 && !(st = event_log_begin(self->log, M->ev.single)))
        st = event_log_end_with(self->log, M->ev.single, bsr_values_single(L0->A, &L0->valf, &L0->capf));
    return st;
}

/* The transfer from level nl-1 to a new level nl: onto a rediscretised
 * grid (baseline GMG: the level's own grid and Hessian from the particles
 * at spacing 2^nl dx, linear transfers onto it), or the embedding's. */
static int build_transfer(Mg *M, const InvSetupInput *in, int nl)
{
    MgLevel *F = &M->lev[nl - 1], *C = &M->lev[nl];
    if (!M->rediscretize) return mg_transfer_build(&F->T, M->kind, F->coord, F->n);
    if (!in->problem) return mpm_error(MPM_EINTERNAL, "geometric multigrid needs the step problem");
    double h = in->problem->dx * (double)(1 << nl);
    int st = gmg_level_build(&M->gl[nl], in->problem, h, &C->Aown);
    if (!st) st = gmg_transfer_onto(&F->T, F->coord, F->n, &M->gl[nl].grid);
    return st;
}

static int mg_setup(InvApprox *self, const InvSetupInput *in)
{
    Mg *M = (Mg *)self;
    EventLog *log = self->log;
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
    if ((st = fine_diagonal(M))) return st;
    int nl = 1;
    while (nl < M->max_levels && M->lev[nl - 1].n >= M->min_coarse) {
        MgLevel *F = &M->lev[nl - 1], *C = &M->lev[nl];
        if (!(st = event_log_begin(log, M->ev.transfers)))
            st = event_log_end_with(log, M->ev.transfers, build_transfer(M, in, nl));
        if (st) return st;
        int m = F->T.n_coarse;
        if (m == 0 || m >= F->n) break; /* no coarsening possible */
        if ((st = level_reserve(C, m, 1))) return st;
        C->n = m;
        C->coord = F->T.coarse_coord;
        if (!M->rediscretize && !(st = event_log_begin(log, M->ev.galerkin)))
            st = event_log_end_with(log, M->ev.galerkin, mg_galerkin(F->A, &F->T, &C->Aown, &M->gw));
        if (st) return st;
        C->A = &C->Aown;
        if (!(st = event_log_begin(log, M->ev.diagonal))) {
            int built = node_coloring_build(C->coord, m, &C->colown);
            if (!built) C->col = &C->colown;
            st = event_log_end_with(log, M->ev.diagonal, built ? built : coarse_diagonal(C, nl));
        }
        if (st) return st;
        ++nl;
    }
    M->nlev = nl;
    M->info.n_levels = nl;
    for (int l = 0; l < nl; ++l) fill_level_info(M, l);
    M->cj.n = M->lev[nl - 1].n;
    M->cj.dinv = M->lev[nl - 1].dinv;
    return single_copies(M, 0);
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
        if (M->single) sgs_sweep_single(L->A, L->valf, L->dinv, L->col, L->r, target, L->work);
        else sgs_sweep(L->A, L->dinv, L->col, L->r, target, L->work);
        if (target == L->d) vec_axpy(len, 1.0, L->d, L->u);
        if (s + 1 < M->sweeps || last_residual) level_residual(M, l, target, L->r);
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

/* Level l on the way down: smooth from u = 0, restrict the residual. */
static int descend(Mg *M, int l)
{
    EventLog *log = M->base.log;
    MgLevel *L = &M->lev[l];
    int st = event_log_begin(log, M->ev.smooth[l]);
    if (st) return st;
    smooth(M, l, 1, 1);
    if ((st = event_log_end(log, M->ev.smooth[l])) || (st = event_log_begin(log, M->ev.transfer_apply))) return st;
    restrict_level(M, l, L->r, M->lev[l + 1].r);
    return event_log_end(log, M->ev.transfer_apply);
}

/* Level l on the way up: prolong and add the coarse correction, smooth. */
static int ascend(Mg *M, int l)
{
    EventLog *log = M->base.log;
    MgLevel *L = &M->lev[l];
    int st = event_log_begin(log, M->ev.transfer_apply);
    if (st) return st;
    mg_prolong(&L->T, M->lev[l + 1].u, L->d);
    vec_axpy(3 * (size_t)L->n, 1.0, L->d, L->u);
    level_residual(M, l, L->d, L->r);
    if ((st = event_log_end(log, M->ev.transfer_apply)) || (st = event_log_begin(log, M->ev.smooth[l]))) return st;
    smooth(M, l, 0, 0);
    return event_log_end(log, M->ev.smooth[l]);
}

static int mg_apply(InvApprox *self, const double *in, double *out)
{
    Mg *M = (Mg *)self;
    if (M->nlev == 0) return mpm_error(MPM_EINTERNAL, "multigrid applied before setup");
    EventLog *log = self->log;
    const int nl = M->nlev;
    const int c = nl - 1;
    MgLevel *Lc = &M->lev[c];
    const size_t lenc = 3 * (size_t)Lc->n;
    PcgResult res;

    /* tolerance of the coarse solve from the input restricted straight down
     * (reference §5.3): coarse_tol * sqrt(bbar^T D^-1 bbar) */
    int st = event_log_begin(log, M->ev.transfer_apply);
    if (st) return st;
    const double *bbar = in;
    for (int l = 0; l < c; ++l) {
        restrict_level(M, l, bbar, M->lev[l + 1].d);
        bbar = M->lev[l + 1].d;
    }
    vec_block_apply((size_t)Lc->n, Lc->dinv, bbar, Lc->work);
    double bnorm2 = vec_dot(lenc, bbar, Lc->work);
    PcgOptions po = {.stop = PCG_ABSOLUTE, .abs_tol = M->coarse_tol * sqrt(fmax(bnorm2, 0.0)),
                     .max_iters = M->coarse_max_iters};
    if ((st = event_log_end(log, M->ev.transfer_apply))) return st;

    /* down: smooth, restrict the residual (nothing with a single level) */
    vec_copy(3 * (size_t)M->lev[0].n, in, M->lev[0].r);
    for (int l = 0; l < c; ++l)
        if ((st = descend(M, l))) return st;
    /* coarsest: block-Jacobi PCG; on the finest level (a one-level
     * hierarchy) with the input's Dirichlet projection, coarser levels carry
     * their BCs in R A P */
    LinearOp op = {.n_nodes = Lc->n, .apply = level_spmv, .ctx = Lc->A};
    if (!(st = event_log_begin(log, M->ev.coarse)))
        st = event_log_end_with(log, M->ev.coarse,
                                pcg_solve(&op, &M->cj.base, c == 0 ? M->proj : NULL, Lc->r, Lc->u, &po, &M->pw, &res));
    /* up: prolong and correct, smooth */
    for (int l = c - 1; l >= 0 && !st; --l) st = ascend(M, l);
    if (st) return st;
    vec_copy(3 * (size_t)M->lev[0].n, M->lev[0].u, out);
    self->stats.inner_iters += res.iters;
    M->info.coarse_iters += res.iters;
    M->info.coarse_capped += res.capped;
    M->info.vcycles++;
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
        free(L->valf);
        gmg_level_free(&M->gl[l]);
    }
    pcg_work_free(&M->pw);
    mg_galerkin_work_free(M->gw);
    free(M);
}

static void mg_view(const InvApprox *self, FILE *f, InvView *out)
{
    const Mg *M = (const Mg *)self;
    const MgInfo *info = &M->info;
    if (f) {
        fprintf(f, "multigrid (%s): %d levels, setup %.4f s (its parts and the V-cycle's: the events mg_*)\n",
                info->rediscretized ? "geometric, rediscretised from particles"
                : info->embedding == MG_EMBED_LINEAR ? "linear embedding" : "quadratic embedding",
                info->n_levels, self->stats.setup_s);
        if (M->single) fprintf(f, "  smoother_precision=single: single-precision copies of the smoothed levels\n");
        for (int l = 0; l < info->n_levels; ++l)
            fprintf(f, "  level %d: %8d nodes %10lld blocks  blocks/row avg %6.1f max %4d\n", l, info->n[l],
                    (long long)info->nnzb[l], info->avg_row[l], info->max_row[l]);
        if (info->vcycles)
            fprintf(f, "  %ld V-cycles: coarse PCG %ld iterations (%.1f per cycle, %ld capped)\n", info->vcycles,
                    info->coarse_iters, (double)info->coarse_iters / info->vcycles, info->coarse_capped);
    }
    if (!out) return;
    out->n_levels = info->n_levels < INV_VIEW_MAX_LEVELS ? info->n_levels : INV_VIEW_MAX_LEVELS;
    for (int l = 0; l < out->n_levels; ++l) {
        out->level[l].nodes = info->n[l];
        out->level[l].blocks = info->nnzb[l];
        out->level[l].blocks_per_row_avg = info->avg_row[l];
        out->level[l].blocks_per_row_max = info->max_row[l];
    }
    inv_view_add(out, "levels", info->n_levels);
    inv_view_add(out, "vcycles", (double)info->vcycles);
    inv_view_add(out, "inner_iters", (double)info->coarse_iters); /* coarsest-level PCG */
    inv_view_add(out, "coarse_capped", (double)info->coarse_capped);
    inv_view_add(out, "setup_s", self->stats.setup_s);
}

const InvApproxOps inv_mg_ops = {
    "mg",
    "node-embedding Galerkin multigrid V-cycle (HOT; embedding=linear|quadratic), or with rediscretize=1 the "
    "particle-rediscretised geometric one (LBFGS-GMG)",
    mg_create,
    mg_setup,
    mg_apply,
    mg_view,
    mg_destroy,
    NULL,
    mg_reuse,
    NULL};
