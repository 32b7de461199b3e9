/* A bounding-volume hierarchy over axis-aligned boxes (the children of a
 * large CSG union), so a point query visits O(log n) boxes instead of all n.
 * Built once, then only read: queries are const and thread-safe. */
#ifndef MPM_BOX_TREE_H
#define MPM_BOX_TREE_H

typedef struct BoxTree BoxTree;

/* Tree over n boxes [lo + 3i, hi + 3i] (copied). NULL when out of memory. */
BoxTree *box_tree_build(int n, const double *lo, const double *hi);
void box_tree_free(BoxTree *t);

/* 1 if test(ctx, i, x) holds for some box i containing x (in no particular
 * order; boxes not containing x are never tested). */
typedef int (*BoxTestFn)(const void *ctx, int i, const double x[3]);
int box_tree_any(const BoxTree *t, const double x[3], BoxTestFn test, const void *ctx);

/* min_i eval(ctx, i, x), skipping every box i whose lower bound cannot beat
 * the best value found so far. The bound of a box is its signed distance to
 * x: the distance when x is outside, minus the depth of x when inside. It
 * bounds eval from below wherever eval is a signed distance of a shape
 * inside the box that never exceeds the true distance in magnitude, except
 * that a shape whose SDF underestimates the distance outside may be skipped
 * although its value is smaller (the result then still never exceeds the
 * true distance to the union). HUGE_VAL for n = 0. */
typedef double (*BoxEvalFn)(const void *ctx, int i, const double x[3]);
double box_tree_min(const BoxTree *t, const double x[3], BoxEvalFn eval, const void *ctx);

#endif
