/* floor: app */
/* PNG pictures: a small two-material scene with a sphere collider is
 * written, read back with libpng, and checked for size, content (both
 * material colours, collider grey, background), determinism and bad input. */
#include "core/error.h"
#include "experiments/render/render.h"
#include "tests/common/testutil.h"

#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct {
    double c[3], r;
} Sphere;

static double sphere_sdf(const void *ctx, int i, const double x[3])
{
    const Sphere *s = (const Sphere *)ctx + i;
    double d[3] = {x[0] - s->c[0], x[1] - s->c[1], x[2] - s->c[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - s->r;
}

/* Reads an 8-bit RGB image; returns NULL if the file is not a valid PNG. */
static unsigned char *read_png(const char *path, int *w, int *h)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) return NULL;
    img.format = PNG_FORMAT_RGB;
    unsigned char *buf = malloc(PNG_IMAGE_SIZE(img));
    if (!buf || !png_image_finish_read(&img, NULL, buf, 0, NULL)) {
        free(buf);
        png_image_free(&img);
        return NULL;
    }
    *w = (int)img.width;
    *h = (int)img.height;
    return buf;
}

/* Is pixel p a shade f * base (0.2 < f <= 1) of the colour base? */
static int is_shade_of(const unsigned char *p, const unsigned char base[3])
{
    double bb = 0, pb = 0;
    for (int c = 0; c < 3; ++c) {
        bb += (double)base[c] * base[c];
        pb += (double)p[c] * base[c];
    }
    double f = pb / bb;
    if (f < 0.2 || f > 1.01) return 0;
    for (int c = 0; c < 3; ++c)
        if (fabs(p[c] - f * base[c]) > 6) return 0;
    return 1;
}

static long file_size(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

static int same_file(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        if (ca != cb) same = 0;
        if (ca == EOF || cb == EOF) break;
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return same;
}

int main(void)
{
    char path[256], path2[256];
    snprintf(path, sizeof path, "/tmp/mpm_test_render_%ld.png", (long)getpid());
    snprintf(path2, sizeof path2, "/tmp/mpm_test_render_%ld_b.png", (long)getpid());

    /* two blocks of particles, spacing 0.02: material 0 on the left, 1 on the right */
    enum { NX = 20, NY = 15, NZ = 8 };
    const int n = 2 * NX * NY * NZ;
    double *x = malloc(3 * (size_t)n * sizeof *x), *speed = malloc((size_t)n * sizeof *speed);
    int *mat = malloc((size_t)n * sizeof *mat);
    int p = 0;
    for (int b = 0; b < 2; ++b)
        for (int i = 0; i < NX; ++i)
            for (int j = 0; j < NY; ++j)
                for (int k = 0; k < NZ; ++k) {
                    x[3 * p] = 0.02 * i + b * 0.5;
                    x[3 * p + 1] = 0.02 * j;
                    x[3 * p + 2] = 0.02 * k;
                    mat[p] = b;
                    speed[p] = x[3 * p + 1];
                    ++p;
                }
    /* a sphere between the blocks, over both and over the background */
    Sphere sph = {{0.44, 0.14, 0.07}, 0.1};

    RenderOptions opt = {320, 200, "front", 0, NULL, {0, 0, 0}, {0, 0, 0}};
    mpm_clear_error();
    int s = render_png(path, n, x, mat, 2, 1, sphere_sdf, &sph, &opt);
    CHECK(s == MPM_OK, "render_png: %s", mpm_last_error());
    CHECK(file_size(path) > 0, "%s missing or empty", path);

    int w = 0, h = 0;
    unsigned char *img = read_png(path, &w, &h);
    CHECK(img != NULL, "%s is not a valid PNG", path);
    if (img) {
        CHECK(w == 320 && h == 200, "size %dx%d", w, h);
        unsigned char c0[3], c1[3];
        render_material_color(0, c0);
        render_material_color(1, c1);
        long bg = 0, m0 = 0, m1 = 0, grey = 0;
        for (int k = 0; k < w * h; ++k) {
            const unsigned char *px = img + 3 * k;
            if (px[0] == 255 && px[1] == 255 && px[2] == 255)
                ++bg;
            else if (is_shade_of(px, c0))
                ++m0;
            else if (is_shade_of(px, c1))
                ++m1;
            else if (abs(px[0] - px[1]) <= 2 && abs(px[1] - px[2]) <= 2)
                ++grey;
        }
        CHECK(bg < (long)w * h, "all pixels are background");
        CHECK(bg > 0, "no background pixels");
        CHECK(m0 > 1000, "%ld pixels of material 0", m0);
        CHECK(m1 > 1000, "%ld pixels of material 1", m1);
        CHECK(grey > 500, "%ld grey (collider) pixels", grey);
        /* left half: material 0 only; right half: material 1 only */
        long wrong = 0;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                const unsigned char *px = img + 3 * ((size_t)j * w + i);
                if (i < w / 2 && is_shade_of(px, c1) && !is_shade_of(px, c0)) ++wrong;
                if (i >= w / 2 && is_shade_of(px, c0) && !is_shade_of(px, c1)) ++wrong;
            }
        CHECK(wrong == 0, "%ld pixels of a material on the wrong side", wrong);
        free(img);
    }

    /* deterministic: the same call writes the same bytes */
    s = render_png(path2, n, x, mat, 2, 1, sphere_sdf, &sph, &opt);
    CHECK(s == MPM_OK && same_file(path, path2), "second rendering differs");

    /* the other views and colour modes run and write the requested size */
    const char *views[] = {"side", "top", "iso", ""};
    for (int v = 0; v < 4; ++v) {
        RenderOptions o = opt;
        snprintf(o.view, sizeof o.view, "%s", views[v]);
        o.color_by = v % 2 ? 1 : 2;
        o.scalar = speed;
        o.lo[0] = -0.1, o.lo[1] = -0.1, o.lo[2] = -0.1;
        o.hi[0] = 1.0, o.hi[1] = 0.6, o.hi[2] = 0.3;
        s = render_png(path2, n, x, mat, 2, 1, sphere_sdf, &sph, &o);
        CHECK(s == MPM_OK, "view '%s': %s", views[v], mpm_last_error());
        img = read_png(path2, &w, &h);
        CHECK(img && w == 320 && h == 200, "view '%s': bad PNG", views[v]);
        free(img);
    }
    /* no colliders, no material array */
    s = render_png(path2, n, x, NULL, 0, 0, NULL, NULL, &opt);
    CHECK(s == MPM_OK, "no colliders: %s", mpm_last_error());

    /* bad input */
    RenderOptions bad = opt;
    snprintf(bad.view, sizeof bad.view, "back");
    mpm_clear_error();
    CHECK(render_png(path2, n, x, mat, 2, 1, sphere_sdf, &sph, &bad) == MPM_EINPUT &&
              strstr(mpm_last_error(), "view"),
          "unknown view: %s", mpm_last_error());
    bad = opt;
    bad.color_by = 1;
    CHECK(render_png(path2, n, x, mat, 2, 1, sphere_sdf, &sph, &bad) == MPM_EINPUT, "speed colours without scalar");
    bad = opt;
    bad.width = 0;
    CHECK(render_png(path2, n, x, mat, 2, 1, sphere_sdf, &sph, &bad) == MPM_EINPUT, "zero width");
    CHECK(render_png(path2, n, x, mat, 1, 1, sphere_sdf, &sph, &opt) == MPM_EINPUT, "material out of range");
    CHECK(render_png(path2, n, x, mat, 2, 1, NULL, &sph, &opt) == MPM_EINPUT, "colliders without level set");
    CHECK(render_png(path2, 0, x, mat, 2, 0, NULL, NULL, &opt) == MPM_EINPUT, "nothing to frame");
    mpm_clear_error();
    CHECK(render_png("/nonexistent-dir/x.png", n, x, mat, 2, 1, sphere_sdf, &sph, &opt) == MPM_EINPUT &&
              strstr(mpm_last_error(), "/nonexistent-dir/x.png"),
          "unwritable path: %s", mpm_last_error());

    remove(path);
    remove(path2);
    free(x);
    free(speed);
    free(mat);
    return test_summary("test_render");
}
