/* The step problem: the incremental potential of one implicit timestep and
 * everything a solver may ask of it (SPEC 3, 4; HOT reference §1.4-1.6).
 *
 *   E(dv) = sum_i 1/2 m_i |dv_i|^2 - dt sum_i m_i g.dv_i + sum_p V_p psi(F_p(dv))
 *   F_p(dv) = F_p^n + dt sum_i (v_i^n + dv_i) a_ip^T,   a_ip = F_p^nT grad w_ip
 *   g_i = m_i dv_i - dt m_i g + dt sum_p V_p P(F_p) a_ip
 *   H = M + dt^2 K,  [K_ij]_ac = sum_p V_p sum_bd A_p[(a,b),(c,d)] a_ip(b) a_jp(d)
 *
 * The sign convention is the gradient g = dE/d(dv) (not the reference's
 * residual r = -g). Dirichlet nodes (sticky or slip colliders) are handled by
 * the per-node projector P_i (0 for sticky, I - n n^T for slip): gradients and
 * directions are projected, and the "BC-projected" Hessian is
 * P H P + (I - P), which is what every solver sees, assembled or matrix-free.
 *
 * Usage per Newton/L-BFGS iterate: problem_energy(dv) evaluates F, P and E
 * at dv and caches them; problem_gradient() then scatters the cached stress;
 * problem_tangent() computes the (projected) dP/dF per particle from the
 * cached F, after which problem_assemble, problem_hessvec and
 * problem_diagonal are available; problem_assemble_fused assembles without
 * keeping the tangents. */
#ifndef MPM_PROBLEM_H
#define MPM_PROBLEM_H

#include <stddef.h>

#include "core/bsr.h"
#include "core/dist/comm_ops.h"
#include "core/dist/decomposition.h"
#include "core/grid.h"
#include "core/material.h"
#include "core/particles.h"

enum { BC_FREE = 0, BC_STICKY = 1, BC_SLIP = 2 };

struct StepProblem;
/* Decides whether the node at world position x is constrained and, if so,
 * calls problem_set_dirichlet for it (the step driver tests colliders). Kept
 * in the problem so coarse grids (geometric multigrid) can ask the same
 * question at their own nodes. Must be safe to call concurrently. */
typedef void (*DirichletFn)(const void *ctx, struct StepProblem *pb, int node, const double x[3]);

typedef struct StepProblem {
    int n_nodes;
    size_t n_particles;
    double dt, dx, gravity[3];

    /* borrowed, valid for one step */
    const Grid *grid;
    const Stencils *st;
    const Particles *parts;
    const Material *mats;
    int n_mats;

    /* per step */
    double *a;           /* 81 per particle: a_ip (27 x 3) */
    double *mu, *lambda; /* per particle Lame parameters (material, times hardening) */
    double *stiff;       /* per particle CN stiffness a_p */
    unsigned char *bc;   /* per node BC_* */
    double *bc_P;        /* 9 per node projector (read for BC_SLIP) */
    double *dv0;         /* 3 per node initial guess (Dirichlet values at constrained nodes) */
    double *kappa;       /* per node: 24 dx^2 dt abar_i (SPEC 4, without eps) */
    double max_stiffness;/* max_p a_p this step */
    int n_dirichlet;
    DirichletFn dirichlet_fn; /* NULL: no constraints */
    const void *dirichlet_ctx;

    /* iterate cache */
    double *F, *P;       /* 9 per particle at the last problem_energy point */
    double *A;           /* 81 per particle after problem_tangent (allocated by it) */
    size_t cap_A;
    int tangent_projected;
    int tangent_stored;  /* A holds the tangent at the cached F (problem_tangent since the last energy) */
    int stress_kernel;   /* FCR4_AUTO (0) or _PORTABLE: the kernel of the energy (psi, P) and of the tangent (core/fcr4.h) */
    int gradient_kernel; /* GRADIENT_CELL_AUTO (0) or _PORTABLE: the gradient's cell kernel (core/gradient_cell.h) */
    int cell_kernel;     /* HESSIAN_CELL_AUTO (0) or _PORTABLE: the assembly's cell kernel (core/hessian_cell.h) */
    double elastic_energy;

    /* Hessian sparsity (per step) */
    int pattern_ready;
    short *slot;         /* 125 per node: position of neighbour offset in the row, -1 absent */
    uint64_t *rowmask;   /* 2 per node: neighbour offsets present */

    /* A distributed run (docs/distributed.md; comm NULL: one process).
     * The local grid holds owned nodes and ghosts; ghosts carry no mass
     * (their inertia is their owner's). Node fields that come in (dv, x)
     * are read with their ghosts set from the owners; the ones that go out
     * (a gradient, H x, the diagonal) hold the sums of every rank's
     * particles at the owners and zero (identity blocks for the diagonal)
     * at the ghosts, so sums over the local nodes are the owned nodes'
     * share of the global ones; energies, norms and counts are summed over
     * the ranks. A failed communication sets comm_failed. */
    const CommOps *comm;
    const unsigned char *owned; /* per node: 1 when this rank owns it (comm only) */
    const Decomposition *decomp; /* the split: the owner of any grid position (comm only) */
    double n_global;     /* the active nodes of every rank (the CN rule's count) */
    int comm_failed;
    double *halo;        /* 3 per node: an incoming field with its ghosts */

    /* scratch */
    double *tmp;         /* 3 per node */
    size_t cap_particles;
    int cap_nodes;
} StepProblem;

/* Sets up the problem for a step: borrows the grid, stencils, particles and
 * materials, computes a_ip, per-particle Lame parameters, the CN scales, and
 * marks every node free (the step driver then marks Dirichlet nodes with
 * problem_set_dirichlet). */
int problem_prepare(StepProblem *pb, const Grid *g, const Stencils *st, const Particles *p,
                    const Material *mats, int n_mats, double dt, const double gravity[3]);

/* Constrains node i: sticky (normal == NULL) fixes dv_i = v_target - v_i^n;
 * slip fixes the normal component only: P_i = I - n n^T. Several slip calls
 * on one node are combined (normals Gram-Schmidt'ed); sticky wins. */
void problem_set_dirichlet(StepProblem *pb, int node, const double v_target[3], const double normal[3]);
/* Marks every node with fn (in parallel over nodes) and remembers fn, ctx. */
void problem_mark_dirichlet(StepProblem *pb, DirichletFn fn, const void *ctx);
/* Counts the constrained nodes; call once after the last problem_set_dirichlet
 * (problem_set_dirichlet touches only its node, so callers may run it in
 * parallel over nodes). */
void problem_finish_dirichlet(StepProblem *pb);

/* Initial guess (HOT reference §1.3): free part dt g, constrained part fixed. */
void problem_initial_guess(const StepProblem *pb, double *dv);

/* Projects a vector onto the free subspace (zero at sticky nodes, tangential
 * at slip nodes). */
void problem_project(const StepProblem *pb, double *v);

/* E(dv); caches F_p and P_p at dv. */
double problem_energy(StepProblem *pb, const double *dv);

/* Projected gradient at the point of the last problem_energy call. */
void problem_gradient(StepProblem *pb, const double *dv, double *g);

/* dP/dF per particle at the cached F (projected to SPD when asked), kept in
 * pb->A for problem_assemble, problem_hessvec and problem_diagonal. */
int problem_tangent(StepProblem *pb, int projected);

/* pb->A with room for the current particles (allocated on first use), for
 * a caller that fills the tangents itself (GMG's rediscretised levels);
 * NULL when out of memory. */
double *problem_tangent_storage(StepProblem *pb);

/* Assembles the BC-projected Hessian into H (pattern built once per step,
 * storage reused) from the tangents of problem_tangent. Over ranks H is
 * the rank's part over its local nodes: a ghost's row holds this rank's
 * particles' share only (no I - P), an owned row lacks the other ranks'
 * shares; the whole scene's matrix is the sum of the parts, which
 * problem_assembled_product and problem_assembled_diagonal complete. */
int problem_assemble(StepProblem *pb, Bsr *H);

/* The same Hessian (bit for bit) with the tangent computed particle block
 * by particle block as the assembly goes and not kept: no 648 bytes a
 * particle written and read back. pb->A is left unset; problem_hessvec and
 * problem_diagonal compute the tangent again if called after it. */
int problem_assemble_fused(StepProblem *pb, int projected, Bsr *H);

/* y = (P H P + I - P) x, matrix-free (SPEC 3). Requires problem_tangent. */
void problem_hessvec(StepProblem *pb, const double *x, double *y);

/* Diagonal 3x3 blocks of the BC-projected Hessian (9 per node). */
void problem_diagonal(StepProblem *pb, double *D);

/* y = H x with the assembled H of problem_assemble: on one process
 * bsr_spmv; over ranks x's ghosts from their owners, the ghost rows'
 * partial sums added into the owners, zeros at the ghosts (as
 * problem_hessvec). Collective over ranks. */
void problem_assembled_product(StepProblem *pb, const Bsr *H, const double *x, double *y);

/* The diagonal blocks of the assembled H (bsr_diagonal), over ranks summed
 * at the owners, the identity at ghosts (as problem_diagonal). Collective. */
void problem_assembled_diagonal(StepProblem *pb, const Bsr *H, double *D);

/* Scaled CN residual s = sqrt(1/n sum_i |g_i|^2 / kappa_i^2) (SPEC 4). The
 * stopping rule of every solver is s < eps. */
double problem_cn_residual(const StepProblem *pb, const double *g);

/* Inexact-solve floor tau = eps dt 24 sqrt(n) dx^2 max_p a_p (SPEC 4). */
double problem_tau(const StepProblem *pb, double eps);

void problem_free(StepProblem *pb);

#endif
