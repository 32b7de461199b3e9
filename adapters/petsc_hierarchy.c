/* HOT's node-embedding hierarchy as a PETSc PCMG (adapters/petsc_hierarchy.h).
 *
 * API use follows the PETSc 3.18 manual pages (PCMGSetLevels,
 * PCMGSetInterpolation, PCMGSetGalerkin, PCMGGetSmoother, PCMGGetCoarseSolve,
 * PCShellSetApply, PCShellSetSetUp, KSPConvergedDefaultCreate,
 * MatGetRowIJ). PETSc numbers levels from the coarsest (0) up; this file
 * keeps mpmbench's numbering (0 = finest) and converts at the calls. */
#include "adapters/petsc_hierarchy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc_error.h"
#include "core/bsr.h"
#include "core/error.h"
#include "core/node_order.h"
#include "core/vec.h"
#include "solvers/inverse/jacobi.h"
#include "solvers/inverse/sgs.h"
#include "solvers/mg/mg.h"

/* A level as the shell PCs see it: the matrix PETSc holds for it, copied
 * into block CSR at each setup, its colouring and block diagonal inverse. */
typedef struct {
    int level; /* 0 = finest */
    int n;
    const int *coord;
    Bsr A;
    NodeColoring col;
    const NodeColoring *colp; /* &col, or the fine level's given colouring */
    double *diag, *dinv, *work; /* 9n, 9n, 6n */
    int cap;
    int l1; /* a smoothed level across ranks: the l1 term on its diagonal (add_l1_term) */
} ShellLevel;

struct PetscHierarchy {
    PetscHierarchyOptions o;
    int nlev;
    int n[MG_MAX_LEVELS];
    MgTransfer T[MG_MAX_LEVELS];       /* T[k]: level k to k+1 */
    ShellLevel lev[MG_MAX_LEVELS];
    KSP coarse;                        /* the coarsest level's CG (PCMG's) */
    double *bbar[2];                   /* the input restricted straight down */
    int cap_bbar;
    long vcycles, coarse_iters, coarse_capped;
    /* across ranks (attach's `ranks`; comm NULL: one process) */
    const CommOps *comm;
    MgCoarseRanks C[MG_MAX_LEVELS];    /* C[k]: level k+1's owned nodes and T[k]'s coarse numbers */
    int n_global[MG_MAX_LEVELS], first[MG_MAX_LEVELS];
    Mat P[MG_MAX_LEVELS];              /* the interpolations, kept for prepare's restriction */
    Vec down[MG_MAX_LEVELS];           /* the input restricted to level l (down[0]: b's array placed) */
};

static int pk(PetscErrorCode code, int status, const char *what) { return petsc_status(code, status, what); }

/* the parallel objects of the last attach across ranks */
static void release_ranks(PetscHierarchy *h)
{
    for (int l = 0; l < MG_MAX_LEVELS; ++l) {
        if (h->P[l]) MatDestroy(&h->P[l]);
        if (h->down[l]) VecDestroy(&h->down[l]);
        h->P[l] = NULL;
        h->down[l] = NULL;
    }
}

int petsc_hierarchy_create(const PetscHierarchyOptions *options, PetscHierarchy **out)
{
    if (options->max_levels < 1 || options->max_levels > MG_MAX_LEVELS)
        return mpm_error(MPM_EINPUT, "petsc hierarchy: %d levels, expected 1..%d", options->max_levels, MG_MAX_LEVELS);
    PetscHierarchy *h = calloc(1, sizeof *h);
    if (!h) return mpm_error(MPM_EINTERNAL, "out of memory: petsc hierarchy");
    h->o = *options;
    for (int l = 0; l < MG_MAX_LEVELS; ++l) h->lev[l].level = l;
    *out = h;
    return MPM_OK;
}

void petsc_hierarchy_destroy(PetscHierarchy *h)
{
    if (!h) return;
    for (int l = 0; l < MG_MAX_LEVELS; ++l) {
        ShellLevel *L = &h->lev[l];
        bsr_free(&L->A);
        node_coloring_free(&L->col);
        free(L->diag);
        free(L->dinv);
        free(L->work);
        mg_transfer_free(&h->T[l]);
        mg_coarse_ranks_free(&h->C[l]);
    }
    release_ranks(h);
    free(h->bbar[0]);
    free(h->bbar[1]);
    free(h);
}

int petsc_hierarchy_levels(const PetscHierarchy *h) { return h ? h->nlev : 0; }

/* ---- a level's matrix, as PETSc holds it, in block CSR ---- */

/* M (sequential AIJ, 3n rows, every block row's three scalar rows holding
 * the same full 3x3 blocks: the fine Hessian and every P^T A P of it) into
 * A. MPM_EINTERNAL when M is not laid out so. */
static int bsr_from_aij(Mat M, Bsr *A)
{
    PetscInt rows = 0;
    const PetscInt *ia = NULL, *ja = NULL;
    PetscBool done = PETSC_FALSE;
    const PetscScalar *v = NULL;
    int st = pk(MatGetRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done), MPM_EINTERNAL, "MatGetRowIJ");
    if (st) return st;
    if (!done || rows % 3) {
        MatRestoreRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done);
        return mpm_error(MPM_EINTERNAL, "petsc hierarchy: a level matrix of %d rows is not in rows of 3", (int)rows);
    }
    const int n = (int)(rows / 3);
    if (!(st = bsr_reserve(A, n, (int64_t)(ia[rows] / 9)))) st = pk(MatSeqAIJGetArrayRead(M, &v), MPM_EINTERNAL,
                                                                     "MatSeqAIJGetArrayRead");
    int bad = 0;
    if (!st) {
        A->row_ptr[0] = 0;
        for (int R = 0; R < n && !bad; ++R) { /* block pattern: every third column of scalar row 3R */
            const PetscInt len = ia[3 * R + 1] - ia[3 * R];
            bad = len % 3 || ia[3 * R + 2] - ia[3 * R + 1] != len || ia[3 * R + 3] - ia[3 * R + 2] != len;
            A->row_ptr[R + 1] = A->row_ptr[R] + len / 3;
        }
    }
    if (!st && !bad) {
#pragma omp parallel for schedule(static) reduction(| : bad)
        for (int R = 0; R < n; ++R)
            for (int64_t k = A->row_ptr[R]; k < A->row_ptr[R + 1]; ++k) {
                const int64_t j = 3 * (k - A->row_ptr[R]);
                A->col[k] = (int)(ja[ia[3 * R] + j] / 3);
                for (int a = 0; a < 3; ++a)
                    for (int b = 0; b < 3; ++b) {
                        const PetscInt q = ia[3 * R + a] + j + b;
                        bad |= ja[q] != 3 * A->col[k] + b;
                        A->val[9 * k + 3 * a + b] = v[q];
                    }
            }
        A->nnzb = A->row_ptr[n];
        bsr_update_pattern_id(A);
    }
    if (v) MatSeqAIJRestoreArrayRead(M, &v);
    MatRestoreRowIJ(M, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done);
    if (!st && bad) st = mpm_error(MPM_EINTERNAL, "petsc hierarchy: a level matrix is not in full 3x3 blocks");
    return st;
}

static int level_reserve(ShellLevel *L, int n)
{
    if (n <= L->cap) return MPM_OK;
    const size_t c = (size_t)(n > 0 ? n : 1);
    double **arr[3] = {&L->diag, &L->dinv, &L->work};
    const size_t per[3] = {9, 9, 6};
    for (int k = 0; k < 3; ++k) {
        double *p = realloc(*arr[k], sizeof(double) * per[k] * c);
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: petsc hierarchy level (%d nodes)", n);
        *arr[k] = p;
    }
    L->cap = n;
    return MPM_OK;
}

/* Across ranks a Gauss-Seidel sweep of each rank's own rows (a hybrid,
 * processor-block smoother) can diverge where the ranks' couplings are
 * strong; it cannot once each row's diagonal gains the absolute sum of the
 * row's entries in other ranks' columns (the l1 smoother of Baker,
 * Falgout, Kolev and Yang 2011, "Multigrid smoothers for ultraparallel
 * computing", §5-6), which keeps the smoother convergent and the V-cycle
 * SPD for an SPD matrix. On one rank there are no such entries: the
 * one-process smoother exactly. Ao: the rows' off-rank part (3n rows). */
static int add_l1_term(Mat Ao, int n, double *diag)
{
    PetscInt rows = 0;
    const PetscInt *ia = NULL, *ja = NULL;
    PetscBool done = PETSC_FALSE;
    const PetscScalar *v = NULL;
    int st = pk(MatGetRowIJ(Ao, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done), MPM_EINTERNAL, "MatGetRowIJ");
    if (!st && (!done || rows != 3 * (PetscInt)n)) st = mpm_error(MPM_EINTERNAL, "petsc hierarchy: off-rank rows");
    if (!st) st = pk(MatSeqAIJGetArrayRead(Ao, &v), MPM_EINTERNAL, "MatSeqAIJGetArrayRead");
    for (PetscInt r = 0; !st && r < rows; ++r) {
        double sum = 0.0;
        for (PetscInt q = ia[r]; q < ia[r + 1]; ++q) sum += fabs(v[q]);
        diag[9 * (r / 3) + 4 * (r % 3)] += sum; /* entry (a, a) of node r/3's block */
    }
    if (v) MatSeqAIJRestoreArrayRead(Ao, &v);
    if (done) MatRestoreRowIJ(Ao, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done);
    return st;
}

/* The shell PC's setup: the level's operator into block CSR, its block
 * diagonal inverse, and (smoothed levels) its colouring. */
static PetscErrorCode shell_setup(PC pc)
{
    ShellLevel *L = NULL;
    Mat M = NULL;
    Mat Ao = NULL;
    PetscBool parallel = PETSC_FALSE;
    PetscErrorCode ierr = PCShellGetContext(pc, &L);
    if (!ierr) ierr = PCGetOperators(pc, &M, NULL);
    if (!ierr) ierr = PetscObjectTypeCompare((PetscObject)M, MATMPIAIJ, &parallel);
    /* across ranks: this rank's rows and columns only (the local diagonal block), and the
     * couplings to other ranks' nodes (Ao) for the l1 term below */
    if (!ierr && parallel) ierr = MatMPIAIJGetSeqAIJ(M, &M, &Ao, NULL);
    if (ierr) return ierr;
    int st = bsr_from_aij(M, &L->A);
    if (!st && L->A.n != L->n)
        st = mpm_error(MPM_EINTERNAL, "petsc hierarchy: level %d has %d nodes, its matrix %d rows", L->level, L->n,
                       L->A.n);
    if (!st) st = level_reserve(L, L->n);
    if (!st) {
        char what[40];
        snprintf(what, sizeof what, "petsc hierarchy level %d", L->level);
        bsr_diagonal(&L->A, L->diag);
        if (Ao && L->l1) st = add_l1_term(Ao, L->n, L->diag);
        if (!st) st = block_diag_invert(L->n, L->diag, L->dinv, what);
    }
    /* PETSc reports a user routine's failure by its code; the message is in mpm_last_error */
    return st ? PETSC_ERR_USER : 0;
}

/* z = op(L, r) on the shell PC's level: the arrays of r and z handed to op */
static PetscErrorCode shell_run(PC pc, Vec r, Vec z, void (*op)(const ShellLevel *, const double *, double *))
{
    ShellLevel *L = NULL;
    const PetscScalar *rr = NULL;
    PetscScalar *zz = NULL;
    PetscErrorCode ierr = PCShellGetContext(pc, &L);
    if (!ierr) ierr = VecGetArrayRead(r, &rr);
    if (!ierr) ierr = VecGetArray(z, &zz);
    if (ierr) return ierr;
    op(L, rr, zz);
    VecRestoreArrayRead(r, &rr);
    return VecRestoreArray(z, &zz);
}

/* S r: one coloured symmetric block Gauss-Seidel sweep from zero (the
 * Richardson KSP around it makes it x += S (b - A x)) */
static void sgs_op(const ShellLevel *L, const double *r, double *z) { sgs_sweep(&L->A, L->dinv, L->colp, r, z, L->work); }
static PetscErrorCode shell_sgs_apply(PC pc, Vec r, Vec z) { return shell_run(pc, r, z, sgs_op); }

/* D^-1 r, the coarse CG's preconditioner */
static void jacobi_op(const ShellLevel *L, const double *r, double *z) { vec_block_apply((size_t)L->n, L->dinv, r, z); }
static PetscErrorCode shell_jacobi_apply(PC pc, Vec r, Vec z) { return shell_run(pc, r, z, jacobi_op); }

/* ---- the levels ---- */

/* P of transfer T as a PETSc matrix: row 3i+a holds w at column 3J+a for
 * every entry (J, w) of T's row i. */
static int interpolation_matrix(const MgTransfer *T, Mat *P)
{
    const PetscInt rows = 3 * (PetscInt)T->n_fine, cols = 3 * (PetscInt)T->n_coarse;
    const int64_t entries = 3 * T->p_ptr[T->n_fine];
    PetscInt *ia = malloc(sizeof(PetscInt) * (size_t)(rows + 1));
    PetscInt *ja = malloc(sizeof(PetscInt) * (size_t)(entries > 0 ? entries : 1));
    PetscScalar *va = malloc(sizeof(PetscScalar) * (size_t)(entries > 0 ? entries : 1));
    int st = ia && ja && va ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: petsc interpolation");
    if (!st) {
        int64_t q = 0;
        for (int i = 0; i < T->n_fine; ++i)
            for (int a = 0; a < 3; ++a) {
                ia[3 * i + a] = (PetscInt)q;
                for (int64_t k = T->p_ptr[i]; k < T->p_ptr[i + 1]; ++k, ++q) {
                    ja[q] = 3 * T->p_col[k] + a;
                    va[q] = T->p_w[k];
                }
            }
        ia[rows] = (PetscInt)q;
    }
    if (!st) st = pk(MatCreate(PETSC_COMM_SELF, P), MPM_EINTERNAL, "MatCreate");
    if (!st) st = pk(MatSetSizes(*P, rows, cols, rows, cols), MPM_EINTERNAL, "MatSetSizes");
    if (!st) st = pk(MatSetType(*P, MATSEQAIJ), MPM_EINTERNAL, "MatSetType");
    if (!st) st = pk(MatSetBlockSizes(*P, 3, 3), MPM_EINTERNAL, "MatSetBlockSizes");
    if (!st) st = pk(MatSeqAIJSetPreallocationCSR(*P, ia, ja, va), MPM_EINTERNAL, "MatSeqAIJSetPreallocationCSR");
    free(ia);
    free(ja);
    free(va);
    return st;
}

/* P of transfer T across ranks: rows of this rank's fine nodes (global
 * numbers first_fine + i), columns the coarse nodes' global numbers (C),
 * preallocated exactly: an entry's column is in the diagonal part when this
 * rank owns the coarse node. */
static int interpolation_matrix_ranks(const MgTransfer *T, const MgCoarseRanks *C, int first_fine, int n_fine_global,
                                      Mat *P)
{
    const PetscInt rows = 3 * (PetscInt)T->n_fine;
    PetscInt *dnnz = calloc((size_t)rows + 1, sizeof(PetscInt)), *onnz = calloc((size_t)rows + 1, sizeof(PetscInt));
    int st = dnnz && onnz ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: petsc interpolation");
    for (int i = 0; i < T->n_fine && !st; ++i)
        for (int64_t k = T->p_ptr[i]; k < T->p_ptr[i + 1]; ++k) {
            const int g = C->global[T->p_col[k]], own = g >= C->first && g < C->first + C->n_owned;
            for (int a = 0; a < 3; ++a) (own ? dnnz : onnz)[3 * i + a]++;
        }
    if (!st) st = pk(MatCreate(PETSC_COMM_WORLD, P), MPM_EINTERNAL, "MatCreate");
    if (!st)
        st = pk(MatSetSizes(*P, rows, 3 * (PetscInt)C->n_owned, 3 * (PetscInt)n_fine_global, 3 * (PetscInt)C->total),
                MPM_EINTERNAL, "MatSetSizes");
    if (!st) st = pk(MatSetType(*P, MATAIJ), MPM_EINTERNAL, "MatSetType");
    if (!st) st = pk(MatSetBlockSizes(*P, 3, 3), MPM_EINTERNAL, "MatSetBlockSizes");
    if (!st) st = pk(MatXAIJSetPreallocation(*P, 1, dnnz, onnz, NULL, NULL), MPM_EINTERNAL, "MatXAIJSetPreallocation");
    for (int i = 0; i < T->n_fine && !st; ++i)
        for (int a = 0; a < 3 && !st; ++a) {
            const PetscInt row = 3 * (PetscInt)(first_fine + i) + a;
            for (int64_t k = T->p_ptr[i]; k < T->p_ptr[i + 1] && !st; ++k) {
                const PetscInt col = 3 * (PetscInt)C->global[T->p_col[k]] + a;
                const PetscScalar w = T->p_w[k];
                st = pk(MatSetValues(*P, 1, &row, 1, &col, &w, INSERT_VALUES), MPM_EINTERNAL, "MatSetValues");
            }
        }
    if (!st) st = pk(MatAssemblyBegin(*P, MAT_FINAL_ASSEMBLY), MPM_EINTERNAL, "MatAssemblyBegin");
    if (!st) st = pk(MatAssemblyEnd(*P, MAT_FINAL_ASSEMBLY), MPM_EINTERNAL, "MatAssemblyEnd");
    free(dnnz);
    free(onnz);
    return st;
}

/* The levels as solvers/mg/mg.c builds them, on one process: level k+1 is
 * the coarse set of level k's nodes, until max_levels or too few nodes. */
static int build_levels(PetscHierarchy *h)
{
    int nl = 1;
    while (nl < h->o.max_levels && h->n[nl - 1] >= h->o.min_coarse_nodes) {
        MgTransfer *T = &h->T[nl - 1];
        int st = mg_transfer_build(T, h->o.kind, h->lev[nl - 1].coord, h->n[nl - 1]);
        if (st) return st;
        const int m = T->n_coarse;
        if (m == 0 || m >= h->n[nl - 1]) break; /* no coarsening possible */
        h->n[nl] = h->n_global[nl] = h->lev[nl].n = m;
        h->lev[nl].coord = T->coarse_coord;
        ++nl;
    }
    h->nlev = nl;
    return MPM_OK;
}

/* The same levels across ranks: every rank embeds its owned nodes, the
 * coarse nodes are split by mg_coarse_ranks, and the stopping rule reads
 * whole-scene counts, so every rank makes the same number of levels.
 * Collective. */
static int build_levels_ranks(PetscHierarchy *h, const PetscHierarchyRanks *r)
{
    int nl = 1;
    while (nl < h->o.max_levels && h->n_global[nl - 1] >= h->o.min_coarse_nodes) {
        MgTransfer *T = &h->T[nl - 1];
        MgCoarseRanks *C = &h->C[nl - 1];
        int st = comm_agree(r->comm, mg_transfer_build(T, h->o.kind, h->lev[nl - 1].coord, h->n[nl - 1]));
        if (!st) st = mg_coarse_ranks(r->comm, r->decomp, nl, T, C);
        if (st) return st;
        if (C->total == 0 || C->total >= h->n_global[nl - 1]) break; /* no coarsening possible */
        h->n[nl] = h->lev[nl].n = C->n_owned;
        h->n_global[nl] = C->total;
        h->first[nl] = C->first;
        h->lev[nl].coord = C->owned_coord;
        ++nl;
    }
    h->nlev = nl;
    return MPM_OK;
}

int petsc_hierarchy_attach(PetscHierarchy *h, PC pc, int n, const int *coord, const NodeColoring *coloring,
                           const PetscHierarchyRanks *ranks)
{
    if (!coord && n > 0) return mpm_error(MPM_EINTERNAL, "petsc hierarchy: needs the node coordinates");
    if (ranks && !ranks->decomp) return mpm_error(MPM_EINTERNAL, "petsc hierarchy: needs the split across ranks");
    h->vcycles = h->coarse_iters = h->coarse_capped = 0;
    release_ranks(h);
    h->comm = ranks ? ranks->comm : NULL;
    h->n[0] = h->lev[0].n = n;
    h->n_global[0] = ranks ? ranks->total : n;
    h->first[0] = ranks ? ranks->first : 0;
    h->lev[0].coord = coord;
    int st = ranks ? build_levels_ranks(h, ranks) : build_levels(h);
    if (st) return st;
    const int nl = h->nlev;
    /* the colourings of the smoothed levels */
    for (int l = 0; l + 1 < nl && !st; ++l) {
        ShellLevel *L = &h->lev[l];
        if (l == 0 && coloring) {
            L->colp = coloring;
        } else {
            st = node_coloring_build(L->coord, L->n, &L->col);
            L->colp = &L->col;
        }
    }
    if (ranks) st = comm_agree(ranks->comm, st);
    if (st) return st;
    if ((st = pk(PCSetType(pc, PCMG), MPM_EINTERNAL, "PCSetType(mg)"))) return st;
    if ((st = pk(PCMGSetLevels(pc, nl, NULL), MPM_EINTERNAL, "PCMGSetLevels"))) return st;
    for (int k = 0; k + 1 < nl && !st; ++k) {
        Mat P = NULL;
        st = ranks ? interpolation_matrix_ranks(&h->T[k], &h->C[k], h->first[k], h->n_global[k], &P)
                   : interpolation_matrix(&h->T[k], &P);
        /* PETSc level nl-1-k is fine level k */
        if (!st) st = pk(PCMGSetInterpolation(pc, nl - 1 - k, P), MPM_EINTERNAL, "PCMGSetInterpolation");
        if (P && ranks && !st) h->P[k] = P; /* kept (PCMG holds its own reference too) for prepare */
        else if (P) MatDestroy(&P);
    }
    if (!st && nl > 1) st = pk(PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH), MPM_EINTERNAL, "PCMGSetGalerkin");
    if (!st) st = pk(PCMGSetNumberSmooth(pc, h->o.sweeps), MPM_EINTERNAL, "PCMGSetNumberSmooth");
    /* prepare's restriction chain: a vector per level, the finest without storage */
    if (ranks && !st)
        st = pk(VecCreateMPIWithArray(PETSC_COMM_WORLD, 3, 3 * (PetscInt)n, PETSC_DECIDE, NULL, &h->down[0]),
                MPM_EINTERNAL, "VecCreateMPIWithArray");
    for (int k = 0; ranks && k + 1 < nl && !st; ++k)
        st = pk(MatCreateVecs(h->P[k], &h->down[k + 1], NULL), MPM_EINTERNAL, "MatCreateVecs");
    return st;
}

/* A shell PC on `ksp` for level L */
static int shell_pc(KSP ksp, ShellLevel *L, PetscErrorCode (*apply)(PC, Vec, Vec), const char *name)
{
    PC spc = NULL;
    int st = pk(KSPGetPC(ksp, &spc), MPM_EINTERNAL, "KSPGetPC");
    if (!st) st = pk(PCSetType(spc, PCSHELL), MPM_EINTERNAL, "PCSetType(shell)");
    if (!st) st = pk(PCShellSetContext(spc, L), MPM_EINTERNAL, "PCShellSetContext");
    if (!st) st = pk(PCShellSetSetUp(spc, shell_setup), MPM_EINTERNAL, "PCShellSetSetUp");
    if (!st) st = pk(PCShellSetApply(spc, apply), MPM_EINTERNAL, "PCShellSetApply");
    if (!st) st = pk(PCShellSetName(spc, name), MPM_EINTERNAL, "PCShellSetName");
    return st;
}

int petsc_hierarchy_configure(PetscHierarchy *h, PC pc)
{
    const int nl = h->nlev;
    int st = MPM_OK;
    if (h->o.mpm_smoother)
        for (int k = 0; k + 1 < nl && !st; ++k) {
            KSP smoother = NULL;
            st = pk(PCMGGetSmoother(pc, nl - 1 - k, &smoother), MPM_EINTERNAL, "PCMGGetSmoother");
            if (!st) st = pk(KSPSetType(smoother, KSPRICHARDSON), MPM_EINTERNAL, "KSPSetType(richardson)");
            if (!st) st = pk(KSPRichardsonSetScale(smoother, 1.0), MPM_EINTERNAL, "KSPRichardsonSetScale");
            h->lev[k].l1 = h->comm != NULL; /* the coarse CG's Jacobi keeps the plain diagonal: CG converges anyway */
            if (!st) st = shell_pc(smoother, &h->lev[k], shell_sgs_apply, "mpmbench coloured symmetric block GS");
        }
    /* the coarsest level: block-Jacobi CG in the natural norm, to the
     * tolerance prepare sets (PCMG's level 0; with one level, its only KSP) */
    void *conv = NULL;
    KSP c = NULL;
    if (!st) st = nl > 1 ? pk(PCMGGetCoarseSolve(pc, &c), MPM_EINTERNAL, "PCMGGetCoarseSolve")
                         : pk(PCMGGetSmoother(pc, 0, &c), MPM_EINTERNAL, "PCMGGetSmoother");
    if (!st) st = pk(KSPSetType(c, KSPCG), MPM_EINTERNAL, "KSPSetType(cg)");
    if (!st) st = pk(KSPSetNormType(c, KSP_NORM_NATURAL), MPM_EINTERNAL, "KSPSetNormType");
    if (!st) st = pk(KSPSetInitialGuessNonzero(c, PETSC_FALSE), MPM_EINTERNAL, "KSPSetInitialGuessNonzero");
    if (!st) st = pk(KSPConvergedDefaultCreate(&conv), MPM_EINTERNAL, "KSPConvergedDefaultCreate");
    if (!st) st = pk(KSPSetConvergenceTest(c, KSPConvergedDefault, conv, KSPConvergedDefaultDestroy), MPM_EINTERNAL,
                     "KSPSetConvergenceTest");
    if (!st) st = pk(KSPSetTolerances(c, 0.0, 0.0, 1e300, h->o.coarse_max_iters), MPM_EINTERNAL, "KSPSetTolerances");
    if (!st) st = shell_pc(c, &h->lev[nl - 1], shell_jacobi_apply, "mpmbench block Jacobi");
    if (!st) h->coarse = c;
    return st;
}

int petsc_hierarchy_prepare(PetscHierarchy *h, const double *b)
{
    const int c = h->nlev - 1;
    if (!h->coarse || c < 0) return mpm_error(MPM_EINTERNAL, "petsc hierarchy: applied before setup");
    /* coarse_tol sqrt(bbar^T D^-1 bbar), bbar = R_{c-1} .. R_0 b (reference §5.3) */
    int need = 0;
    for (int l = 1; l <= c; ++l)
        if (h->n[l] > need) need = h->n[l];
    if (need > h->cap_bbar) {
        for (int k = 0; k < 2; ++k) {
            double *p = realloc(h->bbar[k], sizeof(double) * 3 * (size_t)need);
            if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: petsc hierarchy");
            h->bbar[k] = p;
        }
        h->cap_bbar = need;
    }
    const double *bb = b;
    const PetscScalar *down = NULL;
    int st = MPM_OK;
    if (h->comm) { /* across ranks: R = P^T by PETSc, the ghost coarse nodes' shares reaching their owners */
        st = pk(VecPlaceArray(h->down[0], b), MPM_EINTERNAL, "VecPlaceArray");
        for (int l = 0; l < c && !st; ++l)
            st = pk(MatMultTranspose(h->P[l], h->down[l], h->down[l + 1]), MPM_EINTERNAL, "MatMultTranspose");
        VecResetArray(h->down[0]);
        if (!st && c > 0) st = pk(VecGetArrayRead(h->down[c], &down), MPM_EINTERNAL, "VecGetArrayRead");
        if (!st && c > 0) bb = down;
    } else {
        for (int l = 0; l < c; ++l) {
            double *to = h->bbar[l % 2];
            mg_restrict(&h->T[l], bb, to);
            bb = to;
        }
    }
    const ShellLevel *C = &h->lev[c];
    double norm2 = 0.0;
    for (int i = 0; i < C->n && !st; ++i) {
        const double *D = C->dinv + 9 * i, *x = bb + 3 * i;
        for (int a = 0; a < 3; ++a) norm2 += x[a] * (D[3 * a] * x[0] + D[3 * a + 1] * x[1] + D[3 * a + 2] * x[2]);
    }
    if (down) VecRestoreArrayRead(h->down[c], &down);
    /* the whole scene's norm, summed in rank order */
    if (h->comm && h->comm->sum(h->comm->ctx, &norm2, 1) && !st) st = MPM_EINTERNAL;
    if (st) return st;
    return pk(KSPSetTolerances(h->coarse, 0.0, h->o.coarse_tol * sqrt(fmax(norm2, 0.0)), 1e300, h->o.coarse_max_iters),
              MPM_EINTERNAL, "KSPSetTolerances");
}

int petsc_hierarchy_finish(PetscHierarchy *h, long *coarse_iters)
{
    PetscInt its = 0;
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    int st = pk(KSPGetIterationNumber(h->coarse, &its), MPM_EINTERNAL, "KSPGetIterationNumber");
    if (!st) st = pk(KSPGetConvergedReason(h->coarse, &reason), MPM_EINTERNAL, "KSPGetConvergedReason");
    if (st) return st;
    /* the cap still gives a usable correction, as in the in-house cycle; a breakdown does not */
    if (reason < 0 && reason != KSP_DIVERGED_ITS)
        return mpm_error(MPM_ENUMERIC, "petsc hierarchy: the coarse CG stopped (%s) after %d iterations",
                         KSPConvergedReasons[reason], (int)its);
    h->vcycles++;
    h->coarse_iters += its;
    h->coarse_capped += reason == KSP_DIVERGED_ITS;
    *coarse_iters += its;
    return MPM_OK;
}

void petsc_hierarchy_view(const PetscHierarchy *h, PC pc, InvView *out)
{
    if (!h || !out) return;
    out->n_levels = h->nlev < INV_VIEW_MAX_LEVELS ? h->nlev : INV_VIEW_MAX_LEVELS;
    for (int l = 0; l < out->n_levels; ++l) {
        /* the level's matrix as PETSc holds it (PETSc's level nlev-1-l) */
        KSP ksp = NULL;
        Mat M = NULL;
        MatInfo info;
        double blocks = 0.0;
        /* across ranks the whole scene's (MatGetInfo's sum is collective, as the view is) */
        if (pc && !PCMGGetSmoother(pc, h->nlev - 1 - l, &ksp) && !KSPGetOperators(ksp, &M, NULL) && M &&
            !MatGetInfo(M, h->comm ? MAT_GLOBAL_SUM : MAT_LOCAL, &info))
            blocks = info.nz_used / 9.0;
        out->level[l].nodes = h->n_global[l];
        out->level[l].blocks = (int64_t)blocks;
        out->level[l].blocks_per_row_avg = h->n_global[l] ? blocks / h->n_global[l] : 0.0;
        out->level[l].blocks_per_row_max = 0; /* not counted */
    }
    inv_view_add(out, "vcycles", (double)h->vcycles);
    inv_view_add(out, "inner_iters", (double)h->coarse_iters);
    inv_view_add(out, "coarse_capped", (double)h->coarse_capped);
}
