/* A solid as a level set behind an operations table: colliders and sources
 * evaluate their shape through it, so core/ knows no shape implementation
 * (core/scene/shape.c provides the one the scenes use). phi <= 0 inside;
 * every op is const and thread-safe except destroy. */
#ifndef MPM_LEVEL_SET_H
#define MPM_LEVEL_SET_H

#include <math.h>
#include <stddef.h>

typedef struct LevelSetOps {
    const char *(*type_name)(const void *shape); /* e.g. "half_space", for messages and pictures */
    double (*sdf)(const void *shape, const double x[3]);
    int (*contains)(const void *shape, const double x[3]); /* sdf <= 0, possibly cheaper */
    /* Conservative bounds, +-HUGE_VAL on unbounded sides. */
    void (*bounds)(const void *shape, double lo[3], double hi[3]);
    /* The bounds the reference CFL rule uses (collider_max_speed_reference). */
    void (*reference_bounds)(const void *shape, double lo[3], double hi[3]);
    void (*destroy)(void *shape);
} LevelSetOps;

typedef struct LevelSet {
    const LevelSetOps *ops; /* NULL: no shape (a zeroed collider) */
    void *shape;
} LevelSet;

static inline double level_set_sdf(const LevelSet *l, const double x[3]) { return l->ops->sdf(l->shape, x); }
static inline int level_set_contains(const LevelSet *l, const double x[3]) { return l->ops->contains(l->shape, x); }
static inline void level_set_bounds(const LevelSet *l, double lo[3], double hi[3]) { l->ops->bounds(l->shape, lo, hi); }
static inline void level_set_reference_bounds(const LevelSet *l, double lo[3], double hi[3])
{
    l->ops->reference_bounds(l->shape, lo, hi);
}
static inline const char *level_set_type_name(const LevelSet *l) { return l->ops->type_name(l->shape); }

/* 1 if every side of the bounds is finite. */
static inline int level_set_is_bounded(const LevelSet *l)
{
    double lo[3], hi[3];
    level_set_bounds(l, lo, hi);
    for (int k = 0; k < 3; ++k)
        if (!isfinite(lo[k]) || !isfinite(hi[k])) return 0;
    return 1;
}

static inline void level_set_free(LevelSet *l)
{
    if (l->ops && l->ops->destroy) l->ops->destroy(l->shape);
    l->ops = NULL;
    l->shape = NULL;
}

#endif
