/* PNG pictures of a simulation state (libpng).
 *
 * Orthographic view of the particles, drawn as small shaded discs with a
 * depth buffer (nearer particles win, farther ones darker), coloured by
 * material or by a per-particle scalar, and of the colliders, found by
 * sphere tracing their level sets per pixel and drawn as translucent grey in
 * front of the particles they hide. White background; deterministic output. */
#ifndef MPM_RENDER_H
#define MPM_RENDER_H

typedef struct {
    int width, height;     /* pixels */
    char view[8];          /* "front" (look along -z, x right, y up), "side" (along -x, -z right),
                            * "top" (along -y, x right, -z up), "iso" (along -(1,1,1), y up);
                            * "" means "front" */
    int color_by;          /* 0 material, 1 speed, 2 stress proxy (both from `scalar`) */
    const double *scalar;  /* per-particle scalar for color_by 1 (range 0..99th percentile)
                            * and 2 (1st..99th percentile); ignored for 0 */
    double lo[3], hi[3];   /* world box to frame; lo == hi: the particles' box plus 10% */
} RenderOptions;

/* Level set of collider i at x: <= 0 inside the solid. Ideally a distance
 * (or a lower bound of it) so sphere tracing does not step through it.
 * It is called from several OpenMP threads at once and must be thread-safe. */
typedef double (*RenderSdfFn)(const void *ctx, int i, const double x[3]);

/* Writes an RGB PNG of the state to `path`. `x` holds 3 n_particles
 * positions; `mat` (may be NULL: all 0) the material of each particle, in
 * 0..n_materials-1 when n_materials > 0. Particles with non-finite positions
 * are skipped. Disc radius is half the particle spacing (estimated from the
 * positions), at least 1 pixel. Returns MPM_OK, MPM_EINPUT for bad
 * arguments or a file that cannot be written, MPM_EINTERNAL otherwise. */
int render_png(const char *path, int n_particles, const double *x, const int *mat, int n_materials,
               int n_colliders, RenderSdfFn collider_sdf, const void *ctx, const RenderOptions *opt);

/* The colour (0..255 RGB) of material `m` in pictures, before shading. */
void render_material_color(int m, unsigned char rgb[3]);

#endif
