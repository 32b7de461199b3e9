/* PNG pictures of a simulation state. See render.h. */
#include "experiments/render/render.h"

#include "core/error.h"

#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RENDER_MAX_SIZE 16384
#define RENDER_MAX_STEPS 256
#define RENDER_COLLIDER_ALPHA 0.5f

static const unsigned char k_palette[][3] = {
    {214, 69, 65},  /* red */
    {52, 120, 198}, /* blue */
    {70, 160, 72},  /* green */
    {235, 150, 40}, /* orange */
    {142, 88, 178}, /* purple */
    {40, 170, 180}, /* teal */
    {205, 90, 160}, /* pink */
    {140, 100, 60}, /* brown */
    {150, 160, 30}, /* olive */
    {25, 60, 130},  /* navy */
};
#define N_PALETTE ((int)(sizeof k_palette / sizeof k_palette[0]))

/* Scalar ramp, low to high: dark blue, blue, green-cyan, yellow, red. */
static const float k_ramp[][3] = {
    {40, 30, 120}, {40, 110, 200}, {50, 180, 150}, {240, 210, 50}, {210, 50, 40},
};
#define N_RAMP ((int)(sizeof k_ramp / sizeof k_ramp[0]))

void render_material_color(int m, unsigned char rgb[3])
{
    int k = m % N_PALETTE;
    if (k < 0) k += N_PALETTE;
    memcpy(rgb, k_palette[k], 3);
}

static void ramp_color(double s, float out[3])
{
    if (!(s > 0)) s = 0; /* also NaN */
    if (s > 1) s = 1;
    double f = s * (N_RAMP - 1);
    int k = (int)f;
    if (k >= N_RAMP - 1) k = N_RAMP - 2;
    float t = (float)(f - k);
    for (int c = 0; c < 3; ++c) out[c] = (1 - t) * k_ramp[k][c] + t * k_ramp[k + 1][c];
}

/* ------------------------------------------------------------------ camera */

typedef struct {
    double right[3], up[3], back[3]; /* orthonormal; back points toward the viewer */
    double uc, vc;                   /* world (right, up) coordinates of the image centre */
    double scale;                    /* pixels per world unit */
    double w_near, w_far;            /* depth range (back . x) of the framed box */
    int width, height;
} Camera;

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int set_view(Camera *cam, const char view[8])
{
    static const struct {
        const char *name;
        double right[3], up[3], back[3];
    } views[] = {
        {"front", {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
        {"side", {0, 0, -1}, {0, 1, 0}, {1, 0, 0}},
        {"top", {1, 0, 0}, {0, 0, -1}, {0, 1, 0}},
    };
    if (!memchr(view, '\0', 8)) return -1;
    const char *name = view[0] ? view : "front";
    for (size_t k = 0; k < sizeof views / sizeof views[0]; ++k)
        if (!strcmp(name, views[k].name)) {
            memcpy(cam->right, views[k].right, sizeof cam->right);
            memcpy(cam->up, views[k].up, sizeof cam->up);
            memcpy(cam->back, views[k].back, sizeof cam->back);
            return 0;
        }
    if (!strcmp(name, "iso")) {
        const double a = 1 / sqrt(3.0), b = 1 / sqrt(6.0), c = 1 / sqrt(2.0);
        const double back[3] = {a, a, a}, up[3] = {-b, 2 * b, -b}, right[3] = {c, 0, -c};
        memcpy(cam->right, right, sizeof right);
        memcpy(cam->up, up, sizeof up);
        memcpy(cam->back, back, sizeof back);
        return 0;
    }
    return -1;
}

/* Fits the box into the image (uniform scale, centred). */
static int frame_box(Camera *cam, const double lo[3], const double hi[3])
{
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    cam->w_near = -INFINITY;
    cam->w_far = INFINITY;
    for (int k = 0; k < 8; ++k) {
        double c[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double u = dot3(c, cam->right), v = dot3(c, cam->up), w = dot3(c, cam->back);
        umin = fmin(umin, u);
        umax = fmax(umax, u);
        vmin = fmin(vmin, v);
        vmax = fmax(vmax, v);
        cam->w_near = fmax(cam->w_near, w);
        cam->w_far = fmin(cam->w_far, w);
    }
    double su = umax > umin ? cam->width / (umax - umin) : INFINITY;
    double sv = vmax > vmin ? cam->height / (vmax - vmin) : INFINITY;
    cam->scale = fmin(su, sv);
    if (!isfinite(cam->scale) || !(cam->scale > 0)) return -1;
    cam->uc = 0.5 * (umin + umax);
    cam->vc = 0.5 * (vmin + vmax);
    return 0;
}

/* ------------------------------------------------------------------ particle spacing */

/* Typical distance between neighbouring particles: the cell size s at
 * which the occupied cells hold about 8 particles each, found by a few
 * fixed-point iterations h <- s cbrt(occupied / n) with s = 2 h. */
static double estimate_spacing(int n, const double *x, const double plo[3], const double phi[3], int n_finite)
{
    double ext = fmax(phi[0] - plo[0], fmax(phi[1] - plo[1], phi[2] - plo[2]));
    if (!(ext > 0) || n_finite < 2) return 0;
    size_t cap = 1;
    while (cap < 2 * (size_t)n_finite) cap <<= 1;
    uint64_t *table = malloc(cap * sizeof *table);
    if (!table) return ext / cbrt((double)n_finite);
    double h = ext / cbrt((double)n_finite);
    for (int it = 0; it < 8; ++it) {
        double s = 2 * h;
        if (s < ext / 1.0e6) s = ext / 1.0e6;
        memset(table, 0xff, cap * sizeof *table);
        size_t occupied = 0;
        for (int p = 0; p < n; ++p) {
            const double *xp = x + 3 * (size_t)p;
            if (!isfinite(xp[0]) || !isfinite(xp[1]) || !isfinite(xp[2])) continue;
            uint64_t key = 0;
            for (int d = 0; d < 3; ++d) key = (key << 21) | ((uint64_t)((xp[d] - plo[d]) / s) & 0x1fffff);
            uint64_t hsh = key * 0x9E3779B97F4A7C15ull;
            size_t slot = (size_t)(hsh >> 20) & (cap - 1);
            while (table[slot] != UINT64_MAX && table[slot] != key) slot = (slot + 1) & (cap - 1);
            if (table[slot] == UINT64_MAX) {
                table[slot] = key;
                ++occupied;
            }
        }
        h = s * cbrt((double)occupied / n_finite);
    }
    free(table);
    return h;
}

/* ------------------------------------------------------------------ scalar range */

static double select_kth(double *a, size_t n, size_t k)
{
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        double pv = a[lo + (hi - lo) / 2];
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            if (a[i] < pv) {
                double t = a[lt];
                a[lt++] = a[i];
                a[i++] = t;
            } else if (a[i] > pv) {
                double t = a[--gt];
                a[gt] = a[i];
                a[i] = t;
            } else {
                ++i;
            }
        }
        if (k < lt)
            hi = lt;
        else if (k >= gt)
            lo = gt;
        else
            return pv;
    }
    return a[lo];
}

static int scalar_range(int n, const double *s, int color_by, double *lo, double *hi)
{
    double *tmp = malloc((size_t)(n > 0 ? n : 1) * sizeof *tmp);
    if (!tmp) return -1;
    size_t m = 0;
    for (int p = 0; p < n; ++p)
        if (isfinite(s[p])) tmp[m++] = s[p];
    if (m == 0) {
        *lo = 0;
        *hi = 1;
    } else {
        *hi = select_kth(tmp, m, (size_t)(0.99 * (double)(m - 1)));
        *lo = color_by == 1 ? 0 : select_kth(tmp, m, (size_t)(0.01 * (double)(m - 1)));
        if (color_by == 1 && *hi < 0) *lo = *hi - 1;
        if (!(*hi > *lo)) *hi = *lo + 1;
    }
    free(tmp);
    return 0;
}

/* ------------------------------------------------------------------ PNG */

typedef struct {
    jmp_buf jmp;
    char msg[200];
} PngErr;

static void png_error_cb(png_structp png, png_const_charp msg)
{
    PngErr *e = png_get_error_ptr(png);
    snprintf(e->msg, sizeof e->msg, "%s", msg);
    longjmp(e->jmp, 1);
}

static void png_warning_cb(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static int write_png(const char *path, int w, int h, unsigned char *rgb)
{
    FILE *fp = fopen(path, "wb");
    if (!fp) return mpm_error(MPM_EINPUT, "%s: cannot open for writing", path);
    png_bytep *rows = malloc((size_t)h * sizeof *rows);
    if (!rows) {
        fclose(fp);
        return mpm_error(MPM_EINTERNAL, "%s: out of memory", path);
    }
    for (int j = 0; j < h; ++j) rows[j] = rgb + 3 * (size_t)w * j;
    PngErr err;
    err.msg[0] = '\0';
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_error_cb, png_warning_cb);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_write_struct(&png, &info);
        free(rows);
        fclose(fp);
        return mpm_error(MPM_EINTERNAL, "%s: cannot create PNG writer", path);
    }
    if (setjmp(err.jmp)) {
        png_destroy_write_struct(&png, &info);
        free(rows);
        fclose(fp);
        return mpm_error(MPM_EINTERNAL, "%s: PNG write failed: %s", path, err.msg);
    }
    png_init_io(png, fp);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(rows);
    if (fclose(fp)) return mpm_error(MPM_EINPUT, "%s: write failed", path);
    return MPM_OK;
}

/* ------------------------------------------------------------------ colliders */

/* Camera-space light direction (right, up, toward viewer), normalized. */
static const double k_light[3] = {-0.38, 0.55, 0.74};

typedef struct {
    const Camera *cam;
    RenderSdfFn sdf;
    const void *ctx;
    int collider;
    double pix;          /* world size of one pixel */
    double hit_eps;      /* surface reached when phi <= hit_eps */
    double min_step;     /* smallest sphere-tracing step of a pixel ray */
    const double *wstop; /* per pixel: depth where its ray ends (nearest particle or far plane) */
    double *hit_w;       /* per pixel: depth of the hit, -inf for none */
    float *hit_grey;     /* per pixel: shaded grey level of the hit */
} Tracer;

/* Point at image position (pu, pv) (pixels) and depth w. */
static void ray_point(const Camera *cam, double pu, double pv, double w, double p[3])
{
    double u = cam->uc + (pu - 0.5 * cam->width) / cam->scale;
    double v = cam->vc - (pv - 0.5 * cam->height) / cam->scale;
    for (int d = 0; d < 3; ++d) p[d] = u * cam->right[d] + v * cam->up[d] + w * cam->back[d];
}

/* Shaded grey of a hit at p (level set phi there): Lambert on the
 * level-set gradient (forward differences), seen from the front. */
static float shade_hit(const Tracer *tr, const double p[3], double phi, int flat)
{
    const Camera *cam = tr->cam;
    double n[3] = {0, 0, 1};
    if (!flat) {
        double g[3], h = 0.5 * tr->pix;
        for (int d = 0; d < 3; ++d) {
            double q[3] = {p[0], p[1], p[2]};
            q[d] += h;
            double f = tr->sdf(tr->ctx, tr->collider, q);
            g[d] = isfinite(f) ? f - phi : 0;
        }
        double nc[3] = {dot3(g, cam->right), dot3(g, cam->up), dot3(g, cam->back)};
        double len = sqrt(dot3(nc, nc));
        if (len > 0) {
            for (int d = 0; d < 3; ++d) n[d] = nc[d] / len;
            if (n[2] < 0) /* seen from behind (thin or open level sets) */
                for (int d = 0; d < 3; ++d) n[d] = -n[d];
        }
    }
    double lambert = dot3(n, k_light);
    if (lambert < 0) lambert = 0;
    return (float)(95 + 135 * lambert);
}

/* Sphere tracing of the square of S x S pixels with top-left pixel (i0, j0),
 * starting at depth w. All its rays are parallel and lie within S/sqrt(2)
 * pixels of the centre ray, so while the level set (a distance, or a lower
 * bound of one) exceeds that radius at the centre, the whole square
 * advances together; closer, it splits into four. */
static void trace_tile(const Tracer *tr, int i0, int j0, int S, double w)
{
    const Camera *cam = tr->cam;
    const int W = cam->width, H = cam->height;
    int i1 = i0 + S < W ? i0 + S : W, j1 = j0 + S < H ? j0 + S : H;
    double w_end = INFINITY; /* deepest end of any ray of the tile */
    for (int j = j0; j < j1; ++j)
        for (int i = i0; i < i1; ++i) w_end = fmin(w_end, tr->wstop[(size_t)j * W + i]);
    double rho = S > 1 ? S / sqrt(2.0) * tr->pix : 0;
    double pc = i0 + 0.5 * S, qc = j0 + 0.5 * S, p[3];
    for (int steps = 0; steps < RENDER_MAX_STEPS; ++steps) {
        if (w < w_end) return;
        ray_point(cam, pc, qc, w, p);
        double phi = tr->sdf(tr->ctx, tr->collider, p);
        if (!(phi == phi)) return; /* NaN: nothing to draw */
        if (S == 1) {
            if (phi <= tr->hit_eps) {
                size_t k = (size_t)j0 * W + i0;
                tr->hit_w[k] = w;
                tr->hit_grey[k] = shade_hit(tr, p, phi, w == cam->w_near && phi <= 0);
                return;
            }
            w -= fmax(phi, tr->min_step);
        } else {
            if (phi < 2 * rho) break; /* close to some ray of the tile: split */
            w -= phi - rho;
        }
    }
    if (S == 1) return; /* step budget spent: treated as a miss */
    int h = S / 2;
    for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
            if (i0 + a * h < W && j0 + b * h < H) trace_tile(tr, i0 + a * h, j0 + b * h, h, w);
}

/* ------------------------------------------------------------------ main entry */

int render_png(const char *path, int n_particles, const double *x, const int *mat, int n_materials,
               int n_colliders, RenderSdfFn collider_sdf, const void *ctx, const RenderOptions *opt)
{
    if (!path) return mpm_error(MPM_EINPUT, "render: no output file name");
    if (!opt) return mpm_error(MPM_EINPUT, "%s: render options missing", path);
    if (opt->width < 1 || opt->height < 1 || opt->width > RENDER_MAX_SIZE || opt->height > RENDER_MAX_SIZE)
        return mpm_error(MPM_EINPUT, "%s: image size %dx%d out of range 1..%d", path, opt->width,
                         opt->height, RENDER_MAX_SIZE);
    if (n_particles < 0 || (n_particles > 0 && !x))
        return mpm_error(MPM_EINPUT, "%s: bad particle array (n = %d)", path, n_particles);
    if (n_colliders < 0 || (n_colliders > 0 && !collider_sdf))
        return mpm_error(MPM_EINPUT, "%s: %d colliders but no level-set function", path, n_colliders);
    if (opt->color_by < 0 || opt->color_by > 2)
        return mpm_error(MPM_EINPUT, "%s: color_by must be 0 (material), 1 (speed) or 2 (stress), got %d",
                         path, opt->color_by);
    if (opt->color_by && n_particles > 0 && !opt->scalar)
        return mpm_error(MPM_EINPUT, "%s: color_by %d needs a per-particle scalar", path, opt->color_by);
    Camera cam;
    memset(&cam, 0, sizeof cam);
    cam.width = opt->width;
    cam.height = opt->height;
    if (set_view(&cam, opt->view))
        return mpm_error(MPM_EINPUT, "%s: unknown view '%.7s' (front, side, top, iso)", path, opt->view);
    if (mat && n_materials > 0)
        for (int p = 0; p < n_particles; ++p)
            if (mat[p] < 0 || mat[p] >= n_materials)
                return mpm_error(MPM_EINPUT, "%s: particle %d has material %d, expected 0..%d", path, p,
                                 mat[p], n_materials - 1);

    /* particle bounds */
    double plo[3] = {INFINITY, INFINITY, INFINITY}, phi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int n_finite = 0;
    for (int p = 0; p < n_particles; ++p) {
        const double *xp = x + 3 * (size_t)p;
        if (!isfinite(xp[0]) || !isfinite(xp[1]) || !isfinite(xp[2])) continue;
        ++n_finite;
        for (int d = 0; d < 3; ++d) {
            plo[d] = fmin(plo[d], xp[d]);
            phi[d] = fmax(phi[d], xp[d]);
        }
    }

    /* framed box */
    double lo[3], hi[3];
    int auto_box = opt->lo[0] == opt->hi[0] && opt->lo[1] == opt->hi[1] && opt->lo[2] == opt->hi[2];
    if (auto_box) {
        if (n_finite == 0)
            return mpm_error(MPM_EINPUT, "%s: nothing to frame: no particles and no box given", path);
        double ext = fmax(phi[0] - plo[0], fmax(phi[1] - plo[1], phi[2] - plo[2]));
        if (!(ext > 0)) ext = 1;
        for (int d = 0; d < 3; ++d) {
            double margin = 0.1 * (phi[d] - plo[d]);
            if (margin < 0.05 * ext) margin = 0.05 * ext; /* flat or single-particle sets */
            lo[d] = plo[d] - margin;
            hi[d] = phi[d] + margin;
        }
    } else {
        for (int d = 0; d < 3; ++d) {
            lo[d] = opt->lo[d];
            hi[d] = opt->hi[d];
            if (!isfinite(lo[d]) || !isfinite(hi[d]) || hi[d] < lo[d])
                return mpm_error(MPM_EINPUT, "%s: bad frame box axis %d: [%g, %g]", path, d, lo[d], hi[d]);
        }
    }
    if (frame_box(&cam, lo, hi))
        return mpm_error(MPM_EINPUT, "%s: frame box is empty in the '%s' view", path,
                         opt->view[0] ? opt->view : "front");

    double srange_lo = 0, srange_hi = 1;
    if (opt->color_by && n_particles > 0 && scalar_range(n_particles, opt->scalar, opt->color_by, &srange_lo, &srange_hi))
        return mpm_error(MPM_EINTERNAL, "%s: out of memory", path);

    const int W = opt->width, H = opt->height;
    const size_t npix = (size_t)W * H;
    double *zbuf = malloc(npix * sizeof *zbuf);
    float *color = malloc(3 * npix * sizeof *color);
    unsigned char *rgb = malloc(3 * npix);
    if (!zbuf || !color || !rgb) {
        free(zbuf);
        free(color);
        free(rgb);
        return mpm_error(MPM_EINTERNAL, "%s: out of memory for a %dx%d image", path, W, H);
    }
    for (size_t k = 0; k < npix; ++k) {
        zbuf[k] = -INFINITY;
        color[3 * k] = color[3 * k + 1] = color[3 * k + 2] = 255.f;
    }

    /* particles: shaded spheres of radius half the spacing */
    if (n_finite > 0) {
        double h = estimate_spacing(n_particles, x, plo, phi, n_finite);
        double R = 0.5 * h * cam.scale;
        double rmax = 0.05 * (W < H ? W : H);
        if (R > rmax) R = rmax;
        if (!(R >= 1)) R = 1;
        double rw = R / cam.scale;
        double wmin = INFINITY, wmax = -INFINITY;
        for (int p = 0; p < n_particles; ++p) {
            const double *xp = x + 3 * (size_t)p;
            if (!isfinite(xp[0]) || !isfinite(xp[1]) || !isfinite(xp[2])) continue;
            double w = dot3(xp, cam.back);
            wmin = fmin(wmin, w);
            wmax = fmax(wmax, w);
        }
        double wspan = wmax > wmin ? wmax - wmin : 1;
        double R2 = R * R;
        for (int p = 0; p < n_particles; ++p) {
            const double *xp = x + 3 * (size_t)p;
            if (!isfinite(xp[0]) || !isfinite(xp[1]) || !isfinite(xp[2])) continue;
            double pu = (dot3(xp, cam.right) - cam.uc) * cam.scale + 0.5 * W;
            double pv = 0.5 * H - (dot3(xp, cam.up) - cam.vc) * cam.scale;
            double w = dot3(xp, cam.back);
            int i0 = (int)ceil(pu - R - 0.5), i1 = (int)floor(pu + R - 0.5);
            int j0 = (int)ceil(pv - R - 0.5), j1 = (int)floor(pv + R - 0.5);
            if (i1 < 0 || j1 < 0 || i0 >= W || j0 >= H) continue;
            if (i0 < 0) i0 = 0;
            if (j0 < 0) j0 = 0;
            if (i1 >= W) i1 = W - 1;
            if (j1 >= H) j1 = H - 1;
            float base[3];
            if (opt->color_by == 0) {
                unsigned char c8[3];
                render_material_color(mat ? mat[p] : 0, c8);
                for (int c = 0; c < 3; ++c) base[c] = c8[c];
            } else {
                ramp_color((opt->scalar[p] - srange_lo) / (srange_hi - srange_lo), base);
            }
            double depth_shade = 0.55 + 0.45 * (w - wmin) / wspan;
            for (int j = j0; j <= j1; ++j) {
                double dy = j + 0.5 - pv;
                for (int i = i0; i <= i1; ++i) {
                    double dx = i + 0.5 - pu, r2 = dx * dx + dy * dy;
                    if (r2 > R2) continue;
                    double nz = sqrt(1 - r2 / R2);
                    double z = w + nz * rw;
                    size_t k = (size_t)j * W + i;
                    if (z <= zbuf[k]) continue;
                    zbuf[k] = z;
                    double lambert = (dx / R) * k_light[0] - (dy / R) * k_light[1] + nz * k_light[2];
                    if (lambert < 0) lambert = 0;
                    float f = (float)((0.45 + 0.55 * lambert) * depth_shade);
                    for (int c = 0; c < 3; ++c) color[3 * k + c] = base[c] * f;
                }
            }
        }
    }

    /* colliders: sphere-traced level sets, translucent grey, composited
     * far to near over whatever is behind them */
    if (n_colliders > 0) {
        const int T = 16, ntx = (W + T - 1) / T, nty = (H + T - 1) / T;
        double *wstop = malloc(npix * sizeof *wstop);
        double *hit_w = malloc((size_t)n_colliders * npix * sizeof *hit_w);
        float *hit_grey = malloc((size_t)n_colliders * npix * sizeof *hit_grey);
        if (!wstop || !hit_w || !hit_grey) {
            free(wstop);
            free(hit_w);
            free(hit_grey);
            free(zbuf);
            free(color);
            free(rgb);
            return mpm_error(MPM_EINTERNAL, "%s: out of memory tracing colliders", path);
        }
        for (size_t k = 0; k < npix; ++k) wstop[k] = zbuf[k] > cam.w_far ? zbuf[k] : cam.w_far;
        for (size_t k = 0; k < (size_t)n_colliders * npix; ++k) hit_w[k] = -INFINITY;
        for (int c = 0; c < n_colliders; ++c) {
            Tracer tr = {&cam,   collider_sdf, ctx, c, 1.0 / cam.scale, 0.25 / cam.scale, 0.5 / cam.scale,
                         wstop, hit_w + (size_t)c * npix, hit_grey + (size_t)c * npix};
#pragma omp parallel for schedule(dynamic, 1)
            for (int t = 0; t < ntx * nty; ++t) trace_tile(&tr, (t % ntx) * T, (t / ntx) * T, T, cam.w_near);
        }
        for (size_t k = 0; k < npix; ++k) {
            /* blend the hits farthest first; equal depths in collider order */
            double last = -INFINITY;
            int last_c = -1;
            for (;;) {
                int next = -1;
                for (int c = 0; c < n_colliders; ++c) {
                    double wc = hit_w[(size_t)c * npix + k];
                    if (wc == -INFINITY) continue;
                    int after = wc > last || (wc == last && c > last_c);
                    if (after && (next < 0 || wc < hit_w[(size_t)next * npix + k])) next = c;
                }
                if (next < 0) break;
                float g = hit_grey[(size_t)next * npix + k];
                for (int ch = 0; ch < 3; ++ch)
                    color[3 * k + ch] = (1 - RENDER_COLLIDER_ALPHA) * color[3 * k + ch] + RENDER_COLLIDER_ALPHA * g;
                last = hit_w[(size_t)next * npix + k];
                last_c = next;
            }
        }
        free(wstop);
        free(hit_w);
        free(hit_grey);
    }

    for (size_t k = 0; k < 3 * npix; ++k) {
        float c = color[k] + 0.5f;
        rgb[k] = (unsigned char)(c < 0 ? 0 : (c > 255 ? 255 : c));
    }
    free(zbuf);
    free(color);
    int status = write_png(path, W, H, rgb);
    free(rgb);
    return status;
}
