/* Wavefront OBJ loading, AABB tree, exact distance and hierarchical
 * generalized winding number. See mesh.h. */
#include "core/scene/mesh.h"

#include "core/error.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef MESH_LEAF_SIZE
#define MESH_LEAF_SIZE 4
#endif
#define MESH_STACK 256
/* Far-field criterion of the winding number: a cluster of radius R around
 * its expansion point p is approximated when |q - p| > BETA * R. */
#ifndef MESH_WN_BETA
#define MESH_WN_BETA 2.0
#endif
#define MESH_PI 3.14159265358979323846
/* Largest accepted |vertex coordinate| [m]. */
#define MESH_MAX_COORD 1e12

typedef struct {
    double lo[3], hi[3];
    int start, count; /* leaf: triangles [start, start+count) of tv; internal: count = 0 */
    int right;        /* internal: right child (the left child is this node + 1) */
} BvhNode;

typedef struct {
    double p[3];  /* expansion point: area-weighted centroid */
    double N[3];  /* sum of area vectors (dipole moment) */
    double M[9];  /* sum of a_i (c - p)_j: second-order moment, row-major */
    double r2;    /* (BETA * radius)^2: far field beyond this squared distance */
} WnNode;

struct Mesh {
    int nv, nt;
    double *v;   /* 3 nv, file order */
    int *tri;    /* 3 nt, outward orientation */
    double lo[3], hi[3];
    double volume;
    int boundary_edges;
    int nnodes;
    BvhNode *nodes;
    WnNode *wn;
    double *tv;  /* 9 nt: triangle corners in tree order */
};

/* ------------------------------------------------------------------ small vector helpers */

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void sub3(double r[3], const double a[3], const double b[3])
{
    r[0] = a[0] - b[0];
    r[1] = a[1] - b[1];
    r[2] = a[2] - b[2];
}

static inline void cross3(double r[3], const double a[3], const double b[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

/* ------------------------------------------------------------------ OBJ parsing */

typedef struct {
    char *buf;
    size_t cap;
} LineBuf;

/* Reads one line (any length). Returns 1 if a line was read, 0 at end of
 * file, -1 when out of memory. */
static int read_line(FILE *f, LineBuf *lb)
{
    if (!lb->buf) {
        lb->cap = 256;
        lb->buf = malloc(lb->cap);
        if (!lb->buf) return -1;
    }
    size_t len = 0;
    lb->buf[0] = '\0';
    for (;;) {
        if (!fgets(lb->buf + len, (int)(lb->cap - len), f)) return len > 0 ? 1 : 0;
        len += strlen(lb->buf + len);
        if (len > 0 && lb->buf[len - 1] == '\n') return 1;
        if (len + 1 < lb->cap) continue; /* short read: end of file follows */
        size_t ncap = lb->cap * 2;
        char *nb = realloc(lb->buf, ncap);
        if (!nb) return -1;
        lb->buf = nb;
        lb->cap = ncap;
    }
}

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 0;
    size_t nc = *cap ? *cap : 1024;
    while (nc < need) nc *= 2;
    void *np = realloc(*p, nc * elem);
    if (!np) return -1;
    *p = np;
    *cap = nc;
    return 0;
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

static char *skip_space(char *s)
{
    while (*s && is_space(*s)) ++s;
    return s;
}

/* Copies at most 31 characters of the token at s, for messages. */
static const char *token_text(const char *s, char out[32])
{
    int n = 0;
    while (s[n] && !is_space(s[n]) && n < 31) {
        out[n] = s[n];
        ++n;
    }
    out[n] = '\0';
    return out;
}

/* One face-vertex token: "i", "i/t", "i/t/n", "i//n". Writes the position
 * index (as written, signed). Returns 0 or -1 if malformed. */
static int parse_face_token(char **sp, long *index)
{
    char *s = *sp, *end;
    errno = 0;
    long i = strtol(s, &end, 10);
    if (end == s || errno == ERANGE) return -1;
    s = end;
    for (int part = 0; part < 2 && *s == '/'; ++part) {
        ++s;
        if (*s == '/' || *s == '\0' || is_space(*s)) continue; /* empty t in i//n, or trailing '/' */
        strtol(s, &end, 10);
        if (end == s) return -1;
        s = end;
    }
    if (*s && !is_space(*s)) return -1;
    *index = i;
    *sp = s;
    return 0;
}

typedef struct {
    double *v;
    size_t nv, vcap;
    int *tri;      /* 3 per triangle, 0-based, not yet range-checked */
    int *tri_line; /* line of each triangle, for messages */
    size_t nt, tcap, lcap;
    long *poly;
    size_t pcap;
} ObjData;

static void obj_data_free(ObjData *d)
{
    free(d->v);
    free(d->tri);
    free(d->tri_line);
    free(d->poly);
}

static int parse_obj(const char *path, ObjData *d)
{
    FILE *f = fopen(path, "r");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot open mesh file: %s", path, strerror(errno));
    LineBuf lb = {0};
    int status = MPM_OK, line = 0, r;
    while ((r = read_line(f, &lb)) > 0) {
        ++line;
        char *hash = strchr(lb.buf, '#');
        if (hash) *hash = '\0';
        char *s = skip_space(lb.buf);
        if (s[0] == 'v' && (is_space(s[1]) || s[1] == '\0')) {
            double c[3];
            int k = 0;
            s += 1;
            for (;;) {
                s = skip_space(s);
                if (!*s) break;
                char *end;
                double val = strtod(s, &end);
                if (end == s || (*end && !is_space(*end))) {
                    char tok[32];
                    status = mpm_error(MPM_EINPUT, "%s:%d: malformed number '%s' in vertex line", path,
                                       line, token_text(s, tok));
                    goto done;
                }
                /* beyond MESH_MAX_COORD, sums (centroids) and cubes (volumes) of
                 * coordinates overflow or lose every digit that matters */
                if (!(fabs(val) <= MESH_MAX_COORD)) {
                    char tok[32];
                    status = mpm_error(MPM_EINPUT, "%s:%d: vertex coordinate '%s' is %s (expected |x| <= %g)", path,
                                       line, token_text(s, tok), isfinite(val) ? "out of range" : "not finite",
                                       MESH_MAX_COORD);
                    goto done;
                }
                if (k < 3) c[k] = val;
                ++k; /* extra values (w, vertex colours) are ignored */
                s = end;
            }
            if (k < 3) {
                status = mpm_error(MPM_EINPUT, "%s:%d: vertex has %d coordinates, expected 3", path,
                                   line, k);
                goto done;
            }
            if (d->nv >= (size_t)INT32_MAX / 4) {
                status = mpm_error(MPM_EINPUT, "%s:%d: too many vertices", path, line);
                goto done;
            }
            if (grow((void **)&d->v, &d->vcap, 3 * (d->nv + 1), sizeof(double))) goto oom;
            memcpy(d->v + 3 * d->nv, c, sizeof c);
            ++d->nv;
        } else if (s[0] == 'f' && (is_space(s[1]) || s[1] == '\0')) {
            size_t np = 0;
            s += 1;
            for (;;) {
                s = skip_space(s);
                if (!*s) break;
                long idx;
                char *tok_start = s;
                if (parse_face_token(&s, &idx)) {
                    char tok[32];
                    status = mpm_error(MPM_EINPUT, "%s:%d: malformed face vertex '%s'", path, line,
                                       token_text(tok_start, tok));
                    goto done;
                }
                long abs_idx;
                if (idx > 0) {
                    abs_idx = idx - 1; /* checked against the final vertex count later */
                    if (abs_idx >= INT32_MAX) abs_idx = INT32_MAX - 1;
                } else if (idx < 0 && -idx <= (long)d->nv) {
                    abs_idx = (long)d->nv + idx;
                } else {
                    status = mpm_error(MPM_EINPUT,
                                       "%s:%d: face index %ld out of range (%zu vertices defined so far)",
                                       path, line, idx, d->nv);
                    goto done;
                }
                if (grow((void **)&d->poly, &d->pcap, np + 1, sizeof(long))) goto oom;
                d->poly[np++] = abs_idx;
            }
            if (np < 3) {
                status = mpm_error(MPM_EINPUT, "%s:%d: face with %zu vertices (at least 3 needed)", path,
                                   line, np);
                goto done;
            }
            size_t add = np - 2;
            if (d->nt + add >= (size_t)INT32_MAX / 4) {
                status = mpm_error(MPM_EINPUT, "%s:%d: too many faces", path, line);
                goto done;
            }
            if (grow((void **)&d->tri, &d->tcap, 3 * (d->nt + add), sizeof(int))) goto oom;
            if (grow((void **)&d->tri_line, &d->lcap, d->nt + add, sizeof(int))) goto oom;
            for (size_t k = 1; k + 1 < np; ++k) {
                int *t = d->tri + 3 * d->nt;
                t[0] = (int)d->poly[0];
                t[1] = (int)d->poly[k];
                t[2] = (int)d->poly[k + 1];
                d->tri_line[d->nt] = line;
                ++d->nt;
            }
        }
        /* Everything else (vt, vn, vp, o, g, s, usemtl, mtllib, l, p, ...) is ignored. */
    }
    if (r < 0) goto oom;
    if (ferror(f)) {
        status = mpm_error(MPM_EINPUT, "%s: read error after line %d", path, line);
        goto done;
    }
    if (d->nt == 0) {
        status = mpm_error(MPM_EINPUT, "%s: no faces (%d lines, %zu vertices)", path, line, d->nv);
        goto done;
    }
    for (size_t t = 0; t < d->nt; ++t)
        for (int k = 0; k < 3; ++k)
            if (d->tri[3 * t + k] >= (int)d->nv) {
                status = mpm_error(MPM_EINPUT, "%s:%d: face index %d out of range (%zu vertices)", path,
                                   d->tri_line[t], d->tri[3 * t + k] + 1, d->nv);
                goto done;
            }
    goto done;
oom:
    status = mpm_error(MPM_EINTERNAL, "%s: out of memory reading mesh", path);
done:
    free(lb.buf);
    fclose(f);
    return status;
}

/* ------------------------------------------------------------------ topology */

typedef struct {
    double x, y, z;
    int i;
} VertKey;

static int cmp_vertkey(const void *a, const void *b)
{
    const VertKey *p = a, *q = b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    if (p->y != q->y) return p->y < q->y ? -1 : 1;
    if (p->z != q->z) return p->z < q->z ? -1 : 1;
    return (p->i > q->i) - (p->i < q->i);
}

typedef struct {
    uint64_t key; /* (smaller vertex << 32) | larger vertex */
    int dir;      /* +1 when the face runs smaller -> larger, -1 otherwise */
} EdgeUse;

static int cmp_edge(const void *a, const void *b)
{
    uint64_t x = ((const EdgeUse *)a)->key, y = ((const EdgeUse *)b)->key;
    return (x > y) - (x < y);
}

/* Edge check of the surface, with vertices at identical positions merged.
 * An edge used by an odd number of faces (e.g. by exactly one) is a boundary
 * edge; an edge used an even number of times but not equally often in both
 * directions lies between inconsistently oriented faces. Edges shared by four
 * faces, two each way (two parts touching along an edge), are fine: the
 * winding number stays exact. Returns -1 when out of memory. */
static int check_edges(const double *v, int nv, const int *tri, int nt, long *boundary, long *misoriented)
{
    VertKey *keys = malloc((size_t)nv * sizeof *keys);
    int *canon = malloc((size_t)nv * sizeof *canon);
    EdgeUse *edges = malloc((size_t)nt * 3 * sizeof *edges);
    int status = -1;
    if (!keys || !canon || !edges) goto out;
    for (int i = 0; i < nv; ++i) {
        keys[i].x = v[3 * i];
        keys[i].y = v[3 * i + 1];
        keys[i].z = v[3 * i + 2];
        keys[i].i = i;
    }
    qsort(keys, (size_t)nv, sizeof *keys, cmp_vertkey);
    for (int k = 0; k < nv; ++k) {
        int same = k > 0 && keys[k].x == keys[k - 1].x && keys[k].y == keys[k - 1].y &&
                   keys[k].z == keys[k - 1].z;
        canon[keys[k].i] = same ? canon[keys[k - 1].i] : keys[k].i;
    }
    size_t ne = 0;
    for (int t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = (uint32_t)canon[tri[3 * t + k]], b = (uint32_t)canon[tri[3 * t + (k + 1) % 3]];
            if (a == b) continue;
            edges[ne].dir = a < b ? 1 : -1;
            edges[ne].key = a < b ? ((uint64_t)a << 32) | b : ((uint64_t)b << 32) | a;
            ++ne;
        }
    qsort(edges, ne, sizeof *edges, cmp_edge);
    *boundary = *misoriented = 0;
    for (size_t k = 0; k < ne;) {
        size_t j = k;
        int balance = 0;
        while (j < ne && edges[j].key == edges[k].key) balance += edges[j++].dir;
        if ((j - k) % 2)
            ++*boundary;
        else if (balance)
            ++*misoriented;
        k = j;
    }
    status = 0;
out:
    free(keys);
    free(canon);
    free(edges);
    return status;
}

/* ------------------------------------------------------------------ tree build */

static void select_kth(int *idx, const double *cent, int axis, int lo, int hi, int k)
{
    while (hi - lo > 1) {
        double a = cent[3 * idx[lo] + axis], b = cent[3 * idx[(lo + hi) / 2] + axis],
               c = cent[3 * idx[hi - 1] + axis];
        double pv = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        int lt = lo, i = lo, gt = hi;
        while (i < gt) {
            double kv = cent[3 * idx[i] + axis];
            if (kv < pv) {
                int s = idx[lt];
                idx[lt++] = idx[i];
                idx[i++] = s;
            } else if (kv > pv) {
                int s = idx[--gt];
                idx[gt] = idx[i];
                idx[i] = s;
            } else {
                ++i;
            }
        }
        if (k < lt)
            hi = lt;
        else if (k >= gt)
            lo = gt;
        else
            return;
    }
}

typedef struct {
    Mesh *m;
    int *perm;
    const double *cent; /* 3 per triangle: centroid */
    const double *tbox; /* 6 per triangle: lo, hi */
} Builder;

static double half_area(const double lo[3], const double hi[3])
{
    double e0 = hi[0] - lo[0], e1 = hi[1] - lo[1], e2 = hi[2] - lo[2];
    return e0 * e1 + e1 * e2 + e2 * e0;
}

enum { NB = 16 }; /* SAH bins per axis */

/* The bin of centroid coordinate c in [lo, lo + ext], ext > 0. The ratio is
 * formed first: NB / ext overflows for a subnormal extent (a fuzzed mesh
 * with coordinates like 0x9p-1074), and 0 * inf is NaN, whose int cast is
 * undefined. */
static int centroid_bin(double c, double lo, double ext)
{
    double f = (c - lo) / ext * NB;
    if (!(f >= 0)) return 0;
    return f >= NB ? NB - 1 : (int)f;
}

/* Binned surface-area-heuristic split of perm[start, end): partitions the
 * range and returns the split position, or -1 when every centroid falls in
 * one bin. */
static int sah_split(Builder *b, int start, int end, const double clo[3], const double chi[3])
{
    double best_cost = INFINITY;
    int best_axis = -1, best_bin = -1;
    for (int axis = 0; axis < 3; ++axis) {
        double ext = chi[axis] - clo[axis];
        if (!(ext > 0)) continue;
        int cnt[NB] = {0};
        double blo[NB][3], bhi[NB][3];
        for (int k = 0; k < NB; ++k)
            for (int d = 0; d < 3; ++d) {
                blo[k][d] = INFINITY;
                bhi[k][d] = -INFINITY;
            }
        for (int k = start; k < end; ++k) {
            int t = b->perm[k];
            int bin = centroid_bin(b->cent[3 * t + axis], clo[axis], ext);
            ++cnt[bin];
            const double *tb = b->tbox + 6 * t;
            for (int d = 0; d < 3; ++d) {
                if (tb[d] < blo[bin][d]) blo[bin][d] = tb[d];
                if (tb[3 + d] > bhi[bin][d]) bhi[bin][d] = tb[3 + d];
            }
        }
        /* sweep from the right, then from the left */
        double right_cost[NB];
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        int nr = 0;
        for (int k = NB - 1; k > 0; --k) {
            nr += cnt[k];
            for (int d = 0; d < 3; ++d) {
                if (blo[k][d] < lo[d]) lo[d] = blo[k][d];
                if (bhi[k][d] > hi[d]) hi[d] = bhi[k][d];
            }
            right_cost[k] = nr ? nr * half_area(lo, hi) : INFINITY;
        }
        int nl = 0;
        for (int d = 0; d < 3; ++d) {
            lo[d] = INFINITY;
            hi[d] = -INFINITY;
        }
        for (int k = 0; k < NB - 1; ++k) {
            nl += cnt[k];
            for (int d = 0; d < 3; ++d) {
                if (blo[k][d] < lo[d]) lo[d] = blo[k][d];
                if (bhi[k][d] > hi[d]) hi[d] = bhi[k][d];
            }
            if (!nl || nl == end - start) continue;
            double cost = nl * half_area(lo, hi) + right_cost[k + 1];
            if (cost < best_cost) {
                best_cost = cost;
                best_axis = axis;
                best_bin = k;
            }
        }
    }
    if (best_axis < 0) return -1;
    double best_ext = chi[best_axis] - clo[best_axis];
    int i = start, j = end - 1;
    while (i <= j) {
        int t = b->perm[i];
        int bin = centroid_bin(b->cent[3 * t + best_axis], clo[best_axis], best_ext);
        if (bin <= best_bin) {
            ++i;
        } else {
            b->perm[i] = b->perm[j];
            b->perm[j--] = t;
        }
    }
    return i;
}

static int build_node(Builder *b, int start, int end, int depth)
{
    Mesh *m = b->m;
    int n = m->nnodes++;
    BvhNode *node = &m->nodes[n];
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int d = 0; d < 3; ++d) {
        node->lo[d] = INFINITY;
        node->hi[d] = -INFINITY;
    }
    for (int k = start; k < end; ++k) {
        int t = b->perm[k];
        for (int c = 0; c < 3; ++c) {
            const double *p = m->v + 3 * m->tri[3 * t + c];
            for (int d = 0; d < 3; ++d) {
                if (p[d] < node->lo[d]) node->lo[d] = p[d];
                if (p[d] > node->hi[d]) node->hi[d] = p[d];
            }
        }
        for (int d = 0; d < 3; ++d) {
            double c = b->cent[3 * t + d];
            if (c < clo[d]) clo[d] = c;
            if (c > chi[d]) chi[d] = c;
        }
    }
    node->start = start;
    node->right = -1;
    if (end - start <= MESH_LEAF_SIZE || depth >= MESH_STACK / 2 - 2) {
        node->count = end - start;
        return n;
    }
    int mid = sah_split(b, start, end, clo, chi);
    if (mid <= start || mid >= end) { /* no useful binned split: median of the longest axis */
        int axis = 0;
        for (int d = 1; d < 3; ++d)
            if (chi[d] - clo[d] > chi[axis] - clo[axis]) axis = d;
        mid = start + (end - start) / 2;
        select_kth(b->perm, b->cent, axis, start, end, mid);
    }
    node->count = 0;
    build_node(b, start, mid, depth + 1);
    int right = build_node(b, mid, end, depth + 1);
    m->nodes[n].right = right;
    return n;
}

/* Expansion data of every node from the triangles in its range. */
static void build_winding(Mesh *m)
{
    for (int n = 0; n < m->nnodes; ++n) {
        const BvhNode *node = &m->nodes[n];
        int start = node->start;
        int end = node->count ? start + node->count : -1;
        if (!node->count) {
            /* range of an internal node: from its start to the end of its rightmost leaf */
            int r = n;
            while (!m->nodes[r].count) r = m->nodes[r].right;
            end = m->nodes[r].start + m->nodes[r].count;
        }
        WnNode *w = &m->wn[n];
        double area = 0, pc[3] = {0, 0, 0}, N[3] = {0, 0, 0};
        for (int t = start; t < end; ++t) {
            const double *a = m->tv + 9 * t, *b = a + 3, *c = a + 6;
            double e1[3], e2[3], av[3];
            sub3(e1, b, a);
            sub3(e2, c, a);
            cross3(av, e1, e2);
            double ar = 0.5 * sqrt(dot3(av, av));
            for (int d = 0; d < 3; ++d) {
                N[d] += 0.5 * av[d];
                pc[d] += ar * (a[d] + b[d] + c[d]) / 3.0;
            }
            area += ar;
        }
        for (int d = 0; d < 3; ++d) {
            w->p[d] = area > 0 ? pc[d] / area : 0.5 * (node->lo[d] + node->hi[d]);
            w->N[d] = N[d];
        }
        memset(w->M, 0, sizeof w->M);
        double r2max = 0;
        for (int t = start; t < end; ++t) {
            const double *a = m->tv + 9 * t, *b = a + 3, *c = a + 6;
            double e1[3], e2[3], av[3], cd[3];
            sub3(e1, b, a);
            sub3(e2, c, a);
            cross3(av, e1, e2);
            for (int d = 0; d < 3; ++d) cd[d] = (a[d] + b[d] + c[d]) / 3.0 - w->p[d];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) w->M[3 * i + j] += 0.5 * av[i] * cd[j];
            for (int k = 0; k < 3; ++k) {
                double dv[3];
                sub3(dv, a + 3 * k, w->p);
                double r2 = dot3(dv, dv);
                if (r2 > r2max) r2max = r2;
            }
        }
        w->r2 = MESH_WN_BETA * MESH_WN_BETA * r2max;
    }
}

/* ------------------------------------------------------------------ loading */

static int load(const char *path, int max_boundary, Mesh **out)
{
    *out = NULL;
    if (!path) return mpm_error(MPM_EINPUT, "mesh: no file name given");
    ObjData d = {0};
    int status = parse_obj(path, &d);
    if (status) {
        obj_data_free(&d);
        return status;
    }
    free(d.tri_line);
    d.tri_line = NULL;
    free(d.poly);
    d.poly = NULL;

    Mesh *m = calloc(1, sizeof *m);
    if (!m) {
        obj_data_free(&d);
        return mpm_error(MPM_EINTERNAL, "%s: out of memory", path);
    }
    m->nv = (int)d.nv;
    m->nt = (int)d.nt;
    m->v = d.v;
    m->tri = d.tri;
    d.v = NULL;
    d.tri = NULL;

    long nb, nmis;
    if (check_edges(m->v, m->nv, m->tri, m->nt, &nb, &nmis)) {
        mesh_free(m);
        return mpm_error(MPM_EINTERNAL, "%s: out of memory", path);
    }
    m->boundary_edges = (int)(nb + nmis);
    if (nb + nmis > max_boundary) {
        char allowed[64] = "";
        if (max_boundary > 0) snprintf(allowed, sizeof allowed, " (at most %d allowed)", max_boundary);
        mesh_free(m);
        if (nb && nmis)
            return mpm_error(MPM_EINPUT,
                             "%s: %ld boundary edges and %ld edges between inconsistently oriented "
                             "faces%s: mesh is not closed",
                             path, nb, nmis, allowed);
        if (nb)
            return mpm_error(MPM_EINPUT, "%s: %ld boundary edges%s: mesh is not closed", path, nb, allowed);
        return mpm_error(MPM_EINPUT,
                         "%s: %ld edges between inconsistently oriented faces%s: the faces must all "
                         "face outward (or all inward)",
                         path, nmis, allowed);
    }

    for (int d3 = 0; d3 < 3; ++d3) {
        m->lo[d3] = INFINITY;
        m->hi[d3] = -INFINITY;
    }
    for (int k = 0; k < 3 * m->nt; ++k) {
        const double *p = m->v + 3 * m->tri[k];
        for (int d3 = 0; d3 < 3; ++d3) {
            if (p[d3] < m->lo[d3]) m->lo[d3] = p[d3];
            if (p[d3] > m->hi[d3]) m->hi[d3] = p[d3];
        }
    }
    /* Signed volume about the box centre (exact for closed meshes wherever
     * the origin is; the centre keeps round-off small and makes nearly closed
     * meshes come out sensibly). */
    double o[3], vol = 0;
    for (int d3 = 0; d3 < 3; ++d3) o[d3] = 0.5 * (m->lo[d3] + m->hi[d3]);
    for (int t = 0; t < m->nt; ++t) {
        double a[3], b[3], c[3], bc[3];
        sub3(a, m->v + 3 * m->tri[3 * t], o);
        sub3(b, m->v + 3 * m->tri[3 * t + 1], o);
        sub3(c, m->v + 3 * m->tri[3 * t + 2], o);
        cross3(bc, b, c);
        vol += dot3(a, bc);
    }
    vol /= 6.0;
    double box = (m->hi[0] - m->lo[0]) * (m->hi[1] - m->lo[1]) * (m->hi[2] - m->lo[2]);
    if (!(fabs(vol) > 1e-12 * box) || !(box > 0)) {
        mesh_free(m);
        return mpm_error(MPM_EINPUT, "%s: mesh encloses no volume (signed volume %g)", path, vol);
    }
    if (vol < 0) { /* inward-facing: flip every face */
        for (int t = 0; t < m->nt; ++t) {
            int s = m->tri[3 * t + 1];
            m->tri[3 * t + 1] = m->tri[3 * t + 2];
            m->tri[3 * t + 2] = s;
        }
        vol = -vol;
    }
    m->volume = vol;

    /* Tree over triangle centroids. */
    int *perm = malloc((size_t)m->nt * sizeof *perm);
    double *cent = malloc((size_t)m->nt * 3 * sizeof *cent);
    double *tbox = malloc((size_t)m->nt * 6 * sizeof *tbox);
    m->nodes = malloc((size_t)(2 * m->nt) * sizeof *m->nodes);
    m->wn = malloc((size_t)(2 * m->nt) * sizeof *m->wn);
    m->tv = malloc((size_t)m->nt * 9 * sizeof *m->tv);
    if (!perm || !cent || !tbox || !m->nodes || !m->wn || !m->tv) {
        free(perm);
        free(cent);
        free(tbox);
        mesh_free(m);
        return mpm_error(MPM_EINTERNAL, "%s: out of memory", path);
    }
    for (int t = 0; t < m->nt; ++t) {
        perm[t] = t;
        for (int d3 = 0; d3 < 3; ++d3) {
            double a = m->v[3 * m->tri[3 * t] + d3], bb = m->v[3 * m->tri[3 * t + 1] + d3],
                   c = m->v[3 * m->tri[3 * t + 2] + d3];
            cent[3 * t + d3] = (a + bb + c) / 3.0;
            tbox[6 * t + d3] = fmin(a, fmin(bb, c));
            tbox[6 * t + 3 + d3] = fmax(a, fmax(bb, c));
        }
    }
    Builder b = {m, perm, cent, tbox};
    m->nnodes = 0;
    build_node(&b, 0, m->nt, 0);
    for (int k = 0; k < m->nt; ++k)
        for (int c = 0; c < 3; ++c)
            memcpy(m->tv + 9 * k + 3 * c, m->v + 3 * m->tri[3 * perm[k] + c], 3 * sizeof(double));
    build_winding(m);
    free(perm);
    free(cent);
    free(tbox);
    *out = m;
    return MPM_OK;
}

int mesh_load_obj(const char *path, Mesh **out) { return load(path, 0, out); }

int mesh_load_obj_lenient(const char *path, int max_boundary_edges, Mesh **out)
{
    if (max_boundary_edges < 0) {
        *out = NULL;
        return mpm_error(MPM_EINPUT, "%s: max_boundary_edges must be >= 0, got %d", path ? path : "mesh",
                         max_boundary_edges);
    }
    return load(path, max_boundary_edges, out);
}

void mesh_free(Mesh *m)
{
    if (!m) return;
    free(m->v);
    free(m->tri);
    free(m->nodes);
    free(m->wn);
    free(m->tv);
    free(m);
}

/* ------------------------------------------------------------------ queries */

static double seg_d2(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3];
    sub3(ab, b, a);
    sub3(ap, p, a);
    double l2 = dot3(ab, ab), t = l2 > 0 ? dot3(ap, ab) / l2 : 0;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    double r[3] = {ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]};
    return dot3(r, r);
}

/* Squared distance from p to the triangle (a, b, c), by the Voronoi region
 * of the closest feature. */
static double point_tri_d2(const double p[3], const double *tv)
{
    const double *a = tv, *b = tv + 3, *c = tv + 6;
    double ab[3], ac[3], ap[3], bp[3], cp[3], r[3];
    sub3(ab, b, a);
    sub3(ac, c, a);
    sub3(ap, p, a);
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) return dot3(ap, ap);
    sub3(bp, p, b);
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) return dot3(bp, bp);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        if (d1 - d3 <= 0) goto degenerate;
        double t = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k) r[k] = ap[k] - t * ab[k];
        return dot3(r, r);
    }
    sub3(cp, p, c);
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) return dot3(cp, cp);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        if (d2 - d6 <= 0) goto degenerate;
        double t = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k) r[k] = ap[k] - t * ac[k];
        return dot3(r, r);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double den = (d4 - d3) + (d5 - d6);
        if (den <= 0) goto degenerate;
        double t = (d4 - d3) / den;
        for (int k = 0; k < 3; ++k) r[k] = bp[k] - t * (c[k] - b[k]);
        return dot3(r, r);
    }
    {
        double den = va + vb + vc;
        if (!(den > 0)) goto degenerate;
        double v = vb / den, w = vc / den;
        for (int k = 0; k < 3; ++k) r[k] = ap[k] - v * ab[k] - w * ac[k];
        return dot3(r, r);
    }
degenerate: {
    double e0 = seg_d2(p, a, b), e1 = seg_d2(p, b, c), e2 = seg_d2(p, c, a);
    return fmin(e0, fmin(e1, e2));
}
}

static inline double box_d2(const double p[3], const double lo[3], const double hi[3])
{
    double s = 0;
    for (int d = 0; d < 3; ++d) {
        double e = p[d] < lo[d] ? lo[d] - p[d] : (p[d] > hi[d] ? p[d] - hi[d] : 0);
        s += e * e;
    }
    return s;
}

static double nearest_d2(const Mesh *m, const double q[3])
{
    int stack[MESH_STACK];
    double sd[MESH_STACK];
    int sp = 0;
    double best = INFINITY;
    stack[sp] = 0;
    sd[sp++] = box_d2(q, m->nodes[0].lo, m->nodes[0].hi);
    while (sp) {
        --sp;
        if (sd[sp] >= best) continue;
        const BvhNode *node = &m->nodes[stack[sp]];
        if (node->count) {
            const double *tv = m->tv + 9 * (size_t)node->start;
            for (int k = 0; k < node->count; ++k) {
                double d2 = point_tri_d2(q, tv + 9 * k);
                if (d2 < best) best = d2;
            }
            continue;
        }
        int l = (int)(node - m->nodes) + 1, r = node->right;
        double dl = box_d2(q, m->nodes[l].lo, m->nodes[l].hi);
        double dr = box_d2(q, m->nodes[r].lo, m->nodes[r].hi);
        if (dl > dr) { /* push the farther first so the nearer is visited next */
            int ti = l;
            l = r;
            r = ti;
            double td = dl;
            dl = dr;
            dr = td;
        }
        if (dr < best) {
            stack[sp] = r;
            sd[sp++] = dr;
        }
        if (dl < best) {
            stack[sp] = l;
            sd[sp++] = dl;
        }
    }
    return best;
}

/* Solid angle of triangle (a, b, c) seen from q (van Oosterom-Strackee). */
static inline double tri_solid_angle(const double q[3], const double *tv)
{
    double a[3], b[3], c[3], bc[3];
    sub3(a, tv, q);
    sub3(b, tv + 3, q);
    sub3(c, tv + 6, q);
    double la = sqrt(dot3(a, a)), lb = sqrt(dot3(b, b)), lc = sqrt(dot3(c, c));
    cross3(bc, b, c);
    double num = dot3(a, bc);
    double den = la * lb * lc + dot3(a, b) * lc + dot3(b, c) * la + dot3(c, a) * lb;
    return 2.0 * atan2(num, den);
}

double mesh_winding_number(const Mesh *m, const double q[3])
{
    int stack[MESH_STACK];
    int sp = 0;
    double omega = 0;
    stack[sp++] = 0;
    while (sp) {
        int n = stack[--sp];
        const WnNode *w = &m->wn[n];
        double r[3];
        sub3(r, w->p, q);
        double d2 = dot3(r, r);
        if (d2 > w->r2) {
            /* far field: dipole plus second-order term of the expansion of
             * the integrand (x - q).n / |x - q|^3 about x = p */
            double inv = 1.0 / sqrt(d2), inv3 = inv * inv * inv, inv5 = inv3 * inv * inv;
            const double *M = w->M;
            double Mr0 = M[0] * r[0] + M[1] * r[1] + M[2] * r[2];
            double Mr1 = M[3] * r[0] + M[4] * r[1] + M[5] * r[2];
            double Mr2 = M[6] * r[0] + M[7] * r[1] + M[8] * r[2];
            double rMr = r[0] * Mr0 + r[1] * Mr1 + r[2] * Mr2;
            omega += dot3(r, w->N) * inv3 + (M[0] + M[4] + M[8]) * inv3 - 3.0 * rMr * inv5;
            continue;
        }
        const BvhNode *node = &m->nodes[n];
        if (node->count) {
            const double *tv = m->tv + 9 * (size_t)node->start;
            for (int k = 0; k < node->count; ++k) omega += tri_solid_angle(q, tv + 9 * k);
            continue;
        }
        stack[sp++] = node->right;
        stack[sp++] = n + 1;
    }
    return omega / (4.0 * MESH_PI);
}

static int outside_box(const Mesh *m, const double q[3])
{
    return q[0] < m->lo[0] || q[0] > m->hi[0] || q[1] < m->lo[1] || q[1] > m->hi[1] ||
           q[2] < m->lo[2] || q[2] > m->hi[2];
}

int mesh_contains(const Mesh *m, const double x[3])
{
    if (outside_box(m, x)) return 0;
    return mesh_winding_number(m, x) >= 0.5;
}

double mesh_signed_distance(const Mesh *m, const double x[3])
{
    double d = sqrt(nearest_d2(m, x));
    if (outside_box(m, x)) return d;
    return mesh_winding_number(m, x) >= 0.5 ? -d : d;
}

void mesh_bounds(const Mesh *m, double lo[3], double hi[3])
{
    for (int d = 0; d < 3; ++d) {
        lo[d] = m->lo[d];
        hi[d] = m->hi[d];
    }
}

double mesh_volume(const Mesh *m) { return m->volume; }
int mesh_vertex_count(const Mesh *m) { return m->nv; }
const double *mesh_vertices(const Mesh *m) { return m->v; }
int mesh_triangle_count(const Mesh *m) { return m->nt; }
int mesh_boundary_edge_count(const Mesh *m) { return m->boundary_edges; }
