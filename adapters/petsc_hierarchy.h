/* HOT's node-embedding multigrid hierarchy as a PETSc PCMG (the petsc
 * inverse's option petsc_hierarchy; adapters/petsc.h, docs/solvers.md).
 *
 * The levels are those of the in-house V-cycle (solvers/mg/mg.h; HOT paper
 * §4.1, eq. 6-8): the fine nodes embed into the nodes of the grid of twice
 * the spacing (mg_transfer_build, linear or quadratic kernel) until
 * `max_levels` levels or a level of fewer than `min_coarse_nodes` nodes.
 * Each transfer becomes a PETSc matrix P (scalar weight w on every one of a
 * node's three unknowns) given to PCMG as its interpolation; PCMG computes
 * the coarse operators itself, P^T A P by MatPtAP (PC_MG_GALERKIN_BOTH).
 *
 * Per level but the coarsest, the smoother is either
 *  - mpmbench's coloured symmetric block Gauss-Seidel (solvers/inverse/sgs.h)
 *    as a PCSHELL under a Richardson KSP of `sweeps` iterations: x += S(b -
 *    A x), the in-house smoothing exactly, on the matrix PETSc holds for the
 *    level (copied into block CSR at each setup); or
 *  - PETSc's own, from the mg_levels_ options (the variant whose every part
 *    PETSc can run across ranks).
 * The coarsest level is solved as the in-house V-cycle solves it (reference
 * §5.3): CG with block Jacobi from a zero guess in the preconditioned
 * (natural) norm, stopped when sqrt(r^T D^-1 r) < coarse_tol
 * sqrt(bbar^T D^-1 bbar), bbar the cycle's input restricted straight down,
 * at most coarse_max_iters iterations. So with the SGS smoother the PCMG
 * V-cycle is the in-house one to round-off (tests/conformance/test_adapters.c
 * checks it), and its coarse solve is as adaptive (a variable map unless
 * coarse_tol is tiny).
 *
 * Use: attach before KSPSetFromOptions, configure after it, prepare before
 * every PCApply and finish after it. The fine coordinates are referenced,
 * not copied: they must stay unchanged while the KSP is used. */
#ifndef MPM_PETSC_HIERARCHY_H
#define MPM_PETSC_HIERARCHY_H

#include <petscksp.h>

#include "solvers/inverse_approx.h"
#include "solvers/mg/embedding.h"
#include "solvers/mg/embedding_ranks.h"

typedef struct {
    MgEmbedding kind;
    int max_levels, min_coarse_nodes, sweeps, coarse_max_iters;
    double coarse_tol;
    int mpm_smoother; /* 1: coloured SGS sweeps (PCSHELL); 0: PETSc's, from mg_levels_ options */
} PetscHierarchyOptions;

typedef struct PetscHierarchy PetscHierarchy;

/* A hierarchy over MPI ranks (docs/distributed.md, "HOT across ranks"):
 * each rank's fine nodes are its owned ones, numbered first .. first + n - 1
 * of total in the fine matrix; the coarse levels are split by
 * mg_coarse_ranks, the interpolations are parallel matrices, PETSc's
 * MatPtAP makes the coarse operators across ranks. The coloured SGS
 * smoother then sweeps each rank's own rows (the local diagonal block of
 * the level's matrix, a processor-block Gauss-Seidel; the Richardson
 * iteration around it takes the residual of the whole matrix), and the
 * coarse CG's block Jacobi is each rank's rows'. On one rank it is the
 * one-process hierarchy. */
typedef struct {
    const CommOps *comm;
    const Decomposition *decomp;
    int first, total;
} PetscHierarchyRanks;

int petsc_hierarchy_create(const PetscHierarchyOptions *options, PetscHierarchy **out);
void petsc_hierarchy_destroy(PetscHierarchy *h);

/* Makes `pc` (whose KSP has its fine operator: an AIJ matrix of 3n rows,
 * block size 3) a PCMG on the embedding levels of the n fine nodes at
 * integer coordinates `coord` (sorted by node_order_key; `coloring` their
 * colouring, or NULL to build one): levels, interpolations, Galerkin coarse
 * operators. Before KSPSetFromOptions. Across ranks (`ranks` not NULL; else
 * NULL) n and coord are this rank's owned nodes; collective. */
int petsc_hierarchy_attach(PetscHierarchy *h, PC pc, int n, const int *coord, const NodeColoring *coloring,
                           const PetscHierarchyRanks *ranks);
/* The coarse solve and, with the SGS smoother, the level smoothers. After
 * KSPSetFromOptions, before KSPSetUp. */
int petsc_hierarchy_configure(PetscHierarchy *h, PC pc);
/* Before a PCApply on input b (3n; across ranks the owned nodes'): the
 * coarse solve's tolerance. Collective across ranks. */
int petsc_hierarchy_prepare(PetscHierarchy *h, const double *b);
/* After it: adds the coarse solve's iterations to *coarse_iters. */
int petsc_hierarchy_finish(PetscHierarchy *h, long *coarse_iters);

/* Levels of the last attach (1 = the coarse solve on the fine matrix). */
int petsc_hierarchy_levels(const PetscHierarchy *h);
/* The hierarchy of the last setup into out->level[] (nodes, blocks per row),
 * and its counters; NULL out is ignored. */
void petsc_hierarchy_view(const PetscHierarchy *h, PC pc, InvView *out);

#endif
