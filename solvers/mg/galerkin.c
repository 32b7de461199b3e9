/* Sparse Galerkin product A_c = P^T A P (HOT paper §4.1; reference §5.1),
 * see galerkin.h. Rows are split into one contiguous range per thread; each
 * thread keeps its own dense markers, so nothing is shared while computing. */
#include "solvers/mg/galerkin.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* In-place ascending sort of small int arrays (quicksort, insertion below 16). */
static void sort_ints(int *a, int n)
{
    while (n > 16) {
        int x = a[0], y = a[n / 2], z = a[n - 1];
        int piv = x < y ? (y < z ? y : (x < z ? z : x)) : (x < z ? x : (y < z ? z : y));
        int i = 0, j = n - 1;
        for (;;) {
            while (a[i] < piv) ++i;
            while (a[j] > piv) --j;
            if (i >= j) break;
            int t = a[i];
            a[i] = a[j];
            a[j] = t;
            ++i;
            --j;
        }
        /* recurse on the smaller part, loop on the larger */
        int left = j + 1;
        if (left < n - left) {
            sort_ints(a, left);
            a += left;
            n -= left;
        } else {
            sort_ints(a + left, n - left);
            n = left;
        }
    }
    for (int i = 1; i < n; ++i) {
        int v = a[i], k = i;
        for (; k > 0 && a[k - 1] > v; --k) a[k] = a[k - 1];
        a[k] = v;
    }
}

/* acc = w a, acc += w a over one 3x3 block (restrict lets the compiler vectorise) */
static inline void set9(double w, const double *restrict a, double *restrict acc)
{
    for (int q = 0; q < 9; ++q) acc[q] = w * a[q];
}
static inline void axpy9(double w, const double *restrict a, double *restrict acc)
{
    for (int q = 0; q < 9; ++q) acc[q] += w * a[q];
}

/* Sparse accumulator: acc[slot of key] (+)= w a, the slot made on first use
 * (pos: key -> slot or -1; list: the keys in slot order; *n slots used). */
static inline void accumulate(int *pos, int *list, double *acc, int *n, int key, double w, const double *a)
{
    int p = pos[key];
    if (p < 0) {
        p = pos[key] = (*n)++;
        list[p] = key;
        set9(w, a, acc + 9 * (size_t)p);
    } else {
        axpy9(w, a, acc + 9 * (size_t)p);
    }
}

typedef struct {
    int *fpos, *flist;
    double *facc;
    int64_t fcap;
    int *cpos, *clist;
    double *cacc;
    int64_t ccap;
    int *ocol;     /* upper entries of this thread's rows, row after row */
    double *oval;
    int64_t ocap, onnz;
    int *lower;    /* m: lower entries this thread contributes to each row, then its offset */
    int err;
} GThread;

static int grow_pair(int **ip, double **dp, int64_t need, int64_t *cap)
{
    if (need <= *cap) return 0;
    int64_t nc = *cap ? *cap : 256;
    while (nc < need) nc *= 2;
    int *i2 = realloc(*ip, sizeof(int) * (size_t)nc);
    if (!i2) return 1;
    *ip = i2;
    double *d2 = realloc(*dp, sizeof(double) * 9 * (size_t)nc);
    if (!d2) return 1;
    *dp = d2;
    *cap = nc;
    return 0;
}

static void gthread_free(GThread *g)
{
    free(g->fpos);
    free(g->flist);
    free(g->facc);
    free(g->cpos);
    free(g->clist);
    free(g->cacc);
    free(g->ocol);
    free(g->oval);
    free(g->lower);
}

struct MgGalerkinWork {
    int n_threads;
    GThread *g;
    int *ucnt, *ltot;
    int cap_fine, cap_coarse; /* sizes of fpos / cpos, lower, ucnt, ltot */
};

void mg_galerkin_work_free(MgGalerkinWork *w)
{
    if (!w) return;
    for (int t = 0; t < w->n_threads; ++t) gthread_free(&w->g[t]);
    free(w->g);
    free(w->ucnt);
    free(w->ltot);
    free(w);
}

/* Makes sure w has per-thread state for nt threads and arrays for nf fine
 * and m coarse nodes. Buffers only grow, so steady-state setups do not touch
 * fresh pages. */
static int work_reserve(MgGalerkinWork *w, int nt, int nf, int m)
{
    if (nt > w->n_threads) {
        GThread *g = realloc(w->g, sizeof(GThread) * (size_t)nt);
        if (!g) return 1;
        memset(g + w->n_threads, 0, sizeof(GThread) * (size_t)(nt - w->n_threads));
        w->g = g;
        w->n_threads = nt;
        w->cap_fine = w->cap_coarse = 0; /* new threads need their arrays */
    }
    if (nf > w->cap_fine) {
        for (int t = 0; t < w->n_threads; ++t) {
            int *p = realloc(w->g[t].fpos, sizeof(int) * (size_t)nf);
            if (!p) return 1;
            w->g[t].fpos = p;
        }
        w->cap_fine = nf;
    }
    if (m > w->cap_coarse) {
        for (int t = 0; t < w->n_threads; ++t) {
            int *p = realloc(w->g[t].cpos, sizeof(int) * (size_t)m);
            if (!p) return 1;
            w->g[t].cpos = p;
            p = realloc(w->g[t].lower, sizeof(int) * (size_t)m);
            if (!p) return 1;
            w->g[t].lower = p;
        }
        int *u = realloc(w->ucnt, sizeof(int) * (size_t)m);
        if (!u) return 1;
        w->ucnt = u;
        u = realloc(w->ltot, sizeof(int) * (size_t)m);
        if (!u) return 1;
        w->ltot = u;
        w->cap_coarse = m;
    }
    return 0;
}

/* Rows [lo, hi) of A_c (columns J >= I) into the thread's output buffers.
 * Inlined into a default and an AVX2 build (no FMA: both round alike, so
 * the result does not depend on the CPU); the 9-entry block updates are
 * what the vector width speeds up. */
static inline __attribute__((always_inline)) void rows_body(const Bsr *A, const MgTransfer *T, GThread *me, int lo,
                                                            int hi, int *ucnt)
{
    const int64_t *rp = A->row_ptr;
    const int *acol = A->col;
    const double *aval = A->val;
    int64_t fcap = me->fcap, ccap = me->ccap;
    for (int I = lo; I < hi && !me->err; ++I) {
        /* stage 1: B = sum_{i in R(I)} w_iI A_i (fine-indexed row) */
        int nfl = 0;
        for (int64_t e = T->r_ptr[I]; e < T->r_ptr[I + 1]; ++e) {
            const int i = T->r_col[e];
            const double w = T->r_w[e];
            if (grow_pair(&me->flist, &me->facc, nfl + (rp[i + 1] - rp[i]), &fcap)) {
                me->err = 1;
                break;
            }
            for (int64_t k = rp[i]; k < rp[i + 1]; ++k)
                accumulate(me->fpos, me->flist, me->facc, &nfl, acol[k], w, aval + 9 * k);
        }
        if (me->err) break;
        /* stage 2: row I of A_c (columns J >= I) = B P */
        int ncl = 0;
        for (int a = 0; a < nfl; ++a) {
            const int j = me->flist[a];
            const double *B = me->facc + 9 * (size_t)a;
            me->fpos[j] = -1;
            if (grow_pair(&me->clist, &me->cacc, ncl + (T->p_ptr[j + 1] - T->p_ptr[j]), &ccap)) {
                me->err = 1;
                break;
            }
            for (int64_t e = T->p_ptr[j]; e < T->p_ptr[j + 1]; ++e)
                if (T->p_col[e] >= I) accumulate(me->cpos, me->clist, me->cacc, &ncl, T->p_col[e], T->p_w[e], B);
        }
        if (me->err) break;
        /* emit the row sorted by column */
        if (grow_pair(&me->ocol, &me->oval, me->onnz + ncl, &me->ocap)) {
            me->err = 1;
            break;
        }
        sort_ints(me->clist, ncl);
        for (int a = 0; a < ncl; ++a) {
            const int J = me->clist[a];
            double *o = me->oval + 9 * (size_t)me->onnz;
            memcpy(o, me->cacc + 9 * (size_t)me->cpos[J], 9 * sizeof(double));
            if (J == I) { /* exactly symmetric diagonal block */
                double a01 = 0.5 * (o[1] + o[3]), a02 = 0.5 * (o[2] + o[6]), a12 = 0.5 * (o[5] + o[7]);
                o[1] = o[3] = a01;
                o[2] = o[6] = a02;
                o[5] = o[7] = a12;
            }
            me->ocol[me->onnz++] = J;
            me->cpos[J] = -1;
            if (J > I) me->lower[J]++;
        }
        ucnt[I] = ncl;
    }
    me->fcap = fcap;
    me->ccap = ccap;
}

static void rows_default(const Bsr *A, const MgTransfer *T, GThread *me, int lo, int hi, int *ucnt)
{
    rows_body(A, T, me, lo, hi, ucnt);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HAVE_AVX2_CLONE 1
__attribute__((target("avx2"))) static void rows_avx2(const Bsr *A, const MgTransfer *T, GThread *me, int lo, int hi,
                                                      int *ucnt)
{
    rows_body(A, T, me, lo, hi, ucnt);
}
#endif

int mg_galerkin(const Bsr *A, const MgTransfer *T, Bsr *Ac, MgGalerkinWork **work)
{
    const int nf = T->n_fine, m = T->n_coarse;
    if (A->n != nf) return mpm_error(MPM_EINTERNAL, "galerkin: matrix has %d rows, transfer %d fine nodes", A->n, nf);
    MgGalerkinWork *w = work ? *work : NULL;
    if (!w) {
        w = calloc(1, sizeof *w);
        if (!w) return mpm_error(MPM_EINTERNAL, "out of memory: galerkin product");
        if (work) *work = w;
    }
    int nt_max = omp_get_max_threads();
    if (work_reserve(w, nt_max, nf > 0 ? nf : 1, m > 0 ? m : 1)) {
        if (!work) mg_galerkin_work_free(w);
        return mpm_error(MPM_EINTERNAL, "out of memory: galerkin product");
    }
    GThread *g = w->g;
    int *ucnt = w->ucnt, *ltot = w->ltot;
    for (int t = 0; t < nt_max; ++t) g[t].err = 0, g[t].onnz = 0;
    int nt_used = 1, st = MPM_OK;
#ifdef HAVE_AVX2_CLONE
    const int use_avx2 = __builtin_cpu_supports("avx2");
#endif

#pragma omp parallel
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
#pragma omp single
        nt_used = nt;
        GThread *me = &g[t];
        const int lo = (int)((int64_t)m * t / nt), hi = (int)((int64_t)m * (t + 1) / nt);
        for (int k = 0; k < nf; ++k) me->fpos[k] = -1;
        for (int k = 0; k < m; ++k) me->cpos[k] = -1;
        memset(me->lower, 0, sizeof(int) * (size_t)m);
#ifdef HAVE_AVX2_CLONE
        if (use_avx2) rows_avx2(A, T, me, lo, hi, ucnt);
        else
#endif
            rows_default(A, T, me, lo, hi, ucnt);
    }
    for (int t = 0; t < nt_used; ++t)
        if (g[t].err) st = mpm_error(MPM_EINTERNAL, "out of memory: galerkin product (%d coarse rows)", m);

    if (!st) {
        /* lower-entry totals per row and per-thread offsets (exclusive prefix over threads) */
#pragma omp parallel for schedule(static)
        for (int J = 0; J < m; ++J) {
            int s = 0;
            for (int t = 0; t < nt_used; ++t) {
                int c = g[t].lower[J];
                g[t].lower[J] = s;
                s += c;
            }
            ltot[J] = s;
        }
        int64_t total = 0;
        for (int I = 0; I < m; ++I) total += (int64_t)ucnt[I] + ltot[I];
        st = bsr_reserve(Ac, m, total);
    }
    if (!st) {
        Ac->row_ptr[0] = 0;
        for (int I = 0; I < m; ++I) Ac->row_ptr[I + 1] = Ac->row_ptr[I] + ucnt[I] + ltot[I];
        Ac->nnzb = Ac->row_ptr[m];
        const int nt = nt_used;
#pragma omp parallel for schedule(static, 1)
        for (int t = 0; t < nt; ++t) {
            {
                GThread *me = &g[t];
                const int lo = (int)((int64_t)m * t / nt), hi = (int)((int64_t)m * (t + 1) / nt);
                int64_t src = 0;
                for (int I = lo; I < hi; ++I) {
                    int64_t dst = Ac->row_ptr[I] + ltot[I];
                    for (int a = 0; a < ucnt[I]; ++a, ++src, ++dst) {
                        const int J = me->ocol[src];
                        const double *b = me->oval + 9 * src;
                        Ac->col[dst] = J;
                        memcpy(Ac->val + 9 * dst, b, 9 * sizeof(double));
                        if (J > I) { /* mirror: A_c[J][I] = A_c[I][J]^T */
                            int64_t d2 = Ac->row_ptr[J] + me->lower[J]++;
                            double *bt = Ac->val + 9 * d2;
                            Ac->col[d2] = I;
                            bt[0] = b[0], bt[1] = b[3], bt[2] = b[6];
                            bt[3] = b[1], bt[4] = b[4], bt[5] = b[7];
                            bt[6] = b[2], bt[7] = b[5], bt[8] = b[8];
                        }
                    }
                }
            }
        }
        bsr_update_pattern_id(Ac);
    }
    if (!work) mg_galerkin_work_free(w);
    return st;
}
