#include "solvers/mg/gmg_level.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/transfer.h"

typedef struct {
    uint64_t key;
    size_t idx;
} KeyIdx;

static int cmp_keyidx(const void *a, const void *b)
{
    const KeyIdx *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->idx > y->idx) - (x->idx < y->idx);
}

int gmg_level_build(GmgLevel *L, const StepProblem *fine, double h, Bsr *A)
{
    const Particles *fp = fine->parts;
    size_t n = fp->n;
    int st;
    if (!fine->tangent_stored)
        return mpm_error(MPM_EINTERNAL, "multigrid level: the fine problem has no stored tangent (problem_tangent)");
    /* visit particles in this level's cell order, so grid_build finds them
     * sorted and the copied tangents stay aligned with the particles */
    KeyIdx *ki = malloc(sizeof(KeyIdx) * (n ? n : 1));
    if (!ki) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid level");
    double inv_h = 1.0 / h;
    for (size_t k = 0; k < n; ++k) {
        int b[3];
        for (int d = 0; d < 3; ++d) b[d] = (int)floor(fp->x[3 * k + d] * inv_h - 0.5);
        ki[k].key = node_order_key(b);
        ki[k].idx = k;
    }
    qsort(ki, n, sizeof(KeyIdx), cmp_keyidx);
    if ((st = particles_reserve(&L->parts, n))) {
        free(ki);
        return st;
    }
    Particles *p = &L->parts;
    p->n = n;
    for (size_t k = 0; k < n; ++k) {
        size_t s = ki[k].idx;
        memcpy(p->x + 3 * k, fp->x + 3 * s, 3 * sizeof(double));
        memcpy(p->F + 9 * k, fp->F + 9 * s, 9 * sizeof(double));
        memset(p->v + 3 * k, 0, 3 * sizeof(double));
        memset(p->C + 9 * k, 0, 9 * sizeof(double));
        p->mass[k] = fp->mass[s];
        p->vol[k] = fp->vol[s];
        p->mat[k] = fp->mat[s];
    }
    if ((st = grid_build(&L->grid, &L->st, p, h)) == MPM_OK) {
        if (fine->st->mls) stencils_use_mls_gradients(&L->st, p, h); /* rediscretise as the fine level */
        transfer_p2g(&L->grid, &L->st, p);
        st = problem_prepare(&L->pb, &L->grid, &L->st, p, fine->mats, fine->n_mats, fine->dt, fine->gravity);
    }
    if (st) {
        free(ki);
        return st;
    }
    problem_mark_dirichlet(&L->pb, fine->dirichlet_fn, fine->dirichlet_ctx);
    double *LA = problem_tangent_storage(&L->pb);
    if (!LA) {
        free(ki);
        return MPM_EINTERNAL;
    }
    for (size_t k = 0; k < n; ++k) memcpy(LA + 81 * k, fine->A + 81 * ki[k].idx, 81 * sizeof(double));
    L->pb.tangent_projected = fine->tangent_projected;
    L->pb.tangent_stored = 1;
    free(ki);
    return problem_assemble(&L->pb, A);
}

void gmg_level_free(GmgLevel *L)
{
    problem_free(&L->pb);
    grid_free(&L->grid);
    stencils_free(&L->st);
    particles_free(&L->parts);
    memset(L, 0, sizeof *L);
}

static int grow(void **p, size_t bytes)
{
    void *q = realloc(*p, bytes);
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid transfer");
    *p = q;
    return MPM_OK;
}

int gmg_transfer_onto(MgTransfer *T, const int *fine_coord, int n_fine, const Grid *coarse)
{
    int m = coarse->n, st;
    int64_t max_e = 8 * (int64_t)n_fine;
    if (n_fine + 1 > T->cap_fine) {
        if ((st = grow((void **)&T->p_ptr, sizeof(int64_t) * (size_t)(n_fine + 1)))) return st;
        T->cap_fine = n_fine + 1;
    }
    if (max_e > T->cap_entries) {
        if ((st = grow((void **)&T->p_col, sizeof(int) * (size_t)max_e)) ||
            (st = grow((void **)&T->p_w, sizeof(double) * (size_t)max_e)) ||
            (st = grow((void **)&T->r_col, sizeof(int) * (size_t)max_e)) ||
            (st = grow((void **)&T->r_w, sizeof(double) * (size_t)max_e)))
            return st;
        T->cap_entries = max_e;
    }
    if (m + 1 > T->cap_coarse) {
        if ((st = grow((void **)&T->coarse_coord, sizeof(int) * 3 * (size_t)(m + 1))) ||
            (st = grow((void **)&T->r_ptr, sizeof(int64_t) * (size_t)(m + 1))))
            return st;
        T->cap_coarse = m + 1;
    }
    T->n_fine = n_fine;
    T->n_coarse = m;
    memcpy(T->coarse_coord, coarse->coord, sizeof(int) * 3 * (size_t)m);
    /* P rows: product of the per-axis linear embeddings, kept where the
     * coarse node exists; sorted by coarse id within a row */
    int64_t e = 0;
    T->p_ptr[0] = 0;
    for (int i = 0; i < n_fine; ++i) {
        int X[3][3], cnt[3];
        double W[3][3];
        for (int d = 0; d < 3; ++d) cnt[d] = mg_embed_1d(MG_EMBED_LINEAR, fine_coord[3 * (size_t)i + d], X[d], W[d]);
        int64_t row0 = e;
        for (int a = 0; a < cnt[0]; ++a)
            for (int b = 0; b < cnt[1]; ++b)
                for (int c = 0; c < cnt[2]; ++c) {
                    int cc[3] = {X[0][a], X[1][b], X[2][c]};
                    int J = grid_lookup(coarse, cc);
                    if (J < 0) continue;
                    int64_t pos = e++;
                    while (pos > row0 && T->p_col[pos - 1] > J) {
                        T->p_col[pos] = T->p_col[pos - 1];
                        T->p_w[pos] = T->p_w[pos - 1];
                        --pos;
                    }
                    T->p_col[pos] = J;
                    T->p_w[pos] = W[0][a] * W[1][b] * W[2][c];
                }
        T->p_ptr[i + 1] = e;
    }
    /* R = P^T by counting sort on the coarse column (fine ids increase within a row) */
    memset(T->r_ptr, 0, sizeof(int64_t) * (size_t)(m + 1));
    for (int64_t k = 0; k < e; ++k) T->r_ptr[T->p_col[k] + 1]++;
    for (int J = 0; J < m; ++J) T->r_ptr[J + 1] += T->r_ptr[J];
    int64_t *fill = malloc(sizeof(int64_t) * (size_t)(m > 0 ? m : 1));
    if (!fill) return mpm_error(MPM_EINTERNAL, "out of memory: multigrid transfer");
    memcpy(fill, T->r_ptr, sizeof(int64_t) * (size_t)m);
    for (int i = 0; i < n_fine; ++i)
        for (int64_t k = T->p_ptr[i]; k < T->p_ptr[i + 1]; ++k) {
            int64_t pos = fill[T->p_col[k]]++;
            T->r_col[pos] = i;
            T->r_w[pos] = T->p_w[k];
        }
    free(fill);
    return MPM_OK;
}
