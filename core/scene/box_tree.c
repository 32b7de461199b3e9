#include "core/scene/box_tree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { LEAF_SIZE = 4, STACK = 128 };

typedef struct {
    double lo[3], hi[3];
    int left, right;   /* children (-1 for a leaf) */
    int first, count;  /* leaf: boxes perm[first .. first + count) */
} Node;

struct BoxTree {
    Node *node;
    int n_nodes;
    int *perm;
    double *lo, *hi;   /* the boxes, 3 per box */
};

static void node_bounds(BoxTree *t, Node *nd)
{
    for (int d = 0; d < 3; ++d) nd->lo[d] = HUGE_VAL, nd->hi[d] = -HUGE_VAL;
    for (int k = nd->first; k < nd->first + nd->count; ++k) {
        int i = t->perm[k];
        for (int d = 0; d < 3; ++d) {
            nd->lo[d] = fmin(nd->lo[d], t->lo[3 * i + d]);
            nd->hi[d] = fmax(nd->hi[d], t->hi[3 * i + d]);
        }
    }
}

/* Splits [first, first + count) at the median centre along the longest axis
 * of the centres' extent; depth is bounded by the halving (log2 n). */
static int build_rec(BoxTree *t, int first, int count)
{
    int id = t->n_nodes++;
    Node *nd = &t->node[id];
    nd->first = first;
    nd->count = count;
    nd->left = nd->right = -1;
    node_bounds(t, nd);
    if (count <= LEAF_SIZE) return id;
    double clo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, chi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int k = first; k < first + count; ++k) {
        int i = t->perm[k];
        for (int d = 0; d < 3; ++d) {
            double c = 0.5 * (t->lo[3 * i + d] + t->hi[3 * i + d]);
            clo[d] = fmin(clo[d], c);
            chi[d] = fmax(chi[d], c);
        }
    }
    int axis = 0;
    for (int d = 1; d < 3; ++d)
        if (chi[d] - clo[d] > chi[axis] - clo[axis]) axis = d;
    /* nth-element by centre (quickselect on perm) */
    int *p = t->perm + first, lo = 0, hi = count - 1, mid = count / 2;
    while (lo < hi) {
        int a = p[(lo + hi) / 2];
        double piv = t->lo[3 * a + axis] + t->hi[3 * a + axis];
        int i = lo, j = hi;
        while (i <= j) {
            while (t->lo[3 * p[i] + axis] + t->hi[3 * p[i] + axis] < piv) ++i;
            while (t->lo[3 * p[j] + axis] + t->hi[3 * p[j] + axis] > piv) --j;
            if (i <= j) {
                int s = p[i];
                p[i++] = p[j];
                p[j--] = s;
            }
        }
        if (mid <= j) hi = j;
        else if (mid >= i) lo = i;
        else break;
    }
    int l = build_rec(t, first, mid);
    int r = build_rec(t, first + mid, count - mid);
    t->node[id].left = l;
    t->node[id].right = r;
    return id;
}

BoxTree *box_tree_build(int n, const double *lo, const double *hi)
{
    BoxTree *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    size_t nb = n > 0 ? (size_t)n : 1;
    t->node = malloc(sizeof(Node) * 2 * nb);
    t->perm = malloc(sizeof(int) * nb);
    t->lo = malloc(sizeof(double) * 3 * nb);
    t->hi = malloc(sizeof(double) * 3 * nb);
    if (!t->node || !t->perm || !t->lo || !t->hi) {
        box_tree_free(t);
        return NULL;
    }
    if (n <= 0) return t;
    memcpy(t->lo, lo, sizeof(double) * 3 * (size_t)n);
    memcpy(t->hi, hi, sizeof(double) * 3 * (size_t)n);
    for (int i = 0; i < n; ++i) t->perm[i] = i;
    build_rec(t, 0, n);
    return t;
}

void box_tree_free(BoxTree *t)
{
    if (!t) return;
    free(t->node);
    free(t->perm);
    free(t->lo);
    free(t->hi);
    free(t);
}

static int box_contains(const double lo[3], const double hi[3], const double x[3])
{
    return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1] && x[2] >= lo[2] && x[2] <= hi[2];
}

int box_tree_any(const BoxTree *t, const double x[3], BoxTestFn test, const void *ctx)
{
    if (t->n_nodes == 0) return 0;
    int stack[STACK], sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const Node *nd = &t->node[stack[--sp]];
        if (!box_contains(nd->lo, nd->hi, x)) continue;
        if (nd->left < 0) {
            for (int k = nd->first; k < nd->first + nd->count; ++k) {
                int i = t->perm[k];
                if (box_contains(t->lo + 3 * i, t->hi + 3 * i, x) && test(ctx, i, x)) return 1;
            }
            continue;
        }
        stack[sp++] = nd->left;
        stack[sp++] = nd->right;
    }
    return 0;
}

/* Signed distance from x to the box: outside the Euclidean distance, inside
 * minus the distance to the nearest face. */
static double box_signed_distance(const double lo[3], const double hi[3], const double x[3])
{
    double out = 0.0, depth = HUGE_VAL;
    for (int d = 0; d < 3; ++d) {
        double a = lo[d] - x[d], b = x[d] - hi[d], e = a > b ? a : b; /* no libm calls in this hot loop */
        if (e > 0) out += e * e;
        if (-e < depth) depth = -e;
    }
    return out > 0 ? sqrt(out) : -depth;
}

double box_tree_min(const BoxTree *t, const double x[3], BoxEvalFn eval, const void *ctx)
{
    double best = HUGE_VAL;
    if (t->n_nodes == 0) return best;
    int stack[STACK], sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const Node *nd = &t->node[stack[--sp]];
        if (!(box_signed_distance(nd->lo, nd->hi, x) < best)) continue;
        if (nd->left < 0) {
            for (int k = nd->first; k < nd->first + nd->count; ++k) {
                int i = t->perm[k];
                if (!(box_signed_distance(t->lo + 3 * i, t->hi + 3 * i, x) < best)) continue;
                double v = eval(ctx, i, x);
                if (v < best) best = v;
            }
            continue;
        }
        /* the nearer child last on the stack, so it is searched first */
        const Node *l = &t->node[nd->left], *r = &t->node[nd->right];
        int near_left = box_signed_distance(l->lo, l->hi, x) <= box_signed_distance(r->lo, r->hi, x);
        stack[sp++] = near_left ? nd->right : nd->left;
        stack[sp++] = near_left ? nd->left : nd->right;
    }
    return best;
}
