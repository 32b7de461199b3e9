/* What a linear solve sees: an operator y = A x over n nodes (3n unknowns)
 * and an optional projection onto the free subspace (Dirichlet nodes). */
#ifndef MPM_LINEAR_OP_H
#define MPM_LINEAR_OP_H

typedef struct {
    int n_nodes;
    void (*apply)(const void *ctx, const double *x, double *y);
    const void *ctx;
} LinearOp;

typedef struct {
    void (*apply)(const void *ctx, double *v); /* in place; NULL = identity */
    const void *ctx;
} Projection;

static inline void projection_apply(const Projection *P, double *v)
{
    if (P && P->apply) P->apply(P->ctx, v);
}

#endif
