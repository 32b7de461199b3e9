/* floor: scene */
/* OBJ meshes as solids: loading (all face-index forms, orientation), volume,
 * inside/outside and distance against analytic shapes, the lenient loader,
 * and every input error. The meshes are generated here under /tmp. */
#include "core/error.h"
#include "core/scene/mesh.h"
#include "tests/common/testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define PI 3.14159265358979323846

/* Files go to a directory of this process under /tmp, removed at the end. */
static char g_dir[256];
static char g_files[32][512];
static int g_nfiles;

static const char *tmp_path(const char *name)
{
    for (int k = 0; k < g_nfiles; ++k)
        if (!strcmp(strrchr(g_files[k], '/') + 1, name)) return g_files[k];
    if (g_nfiles == 32) return "/tmp/mpm_test_mesh_too_many_files";
    snprintf(g_files[g_nfiles], sizeof g_files[0], "%s/%s", g_dir, name);
    return g_files[g_nfiles++];
}

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

/* Unit cube [0,1]^3 from quads, outward, in every index form the loader
 * accepts, with lines it must ignore. `skip_face` >= 0 leaves that face
 * out; `inward` reverses every face. */
static int write_cube(const char *path, int skip_face, int inward)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fprintf(f, "# unit cube\nmtllib cube.mtl\no cube\n#");
    for (int k = 0; k < 2000; ++k) fputc('a' + k % 26, f); /* a line longer than any buffer guess */
    fputc('\n', f);
    for (int k = 0; k < 8; ++k) fprintf(f, "v %d %d %d\n", k & 1, (k >> 1) & 1, (k >> 2) & 1);
    fprintf(f, "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng box\nusemtl grey\ns off\n");
    /* outward quads (vertex k = (k&1, k>>1&1, k>>2&1), 1-based) */
    static const int quads[6][4] = {
        {1, 3, 4, 2}, /* z = 0 */
        {5, 6, 8, 7}, /* z = 1 */
        {1, 2, 6, 5}, /* y = 0 */
        {3, 7, 8, 4}, /* y = 1 */
        {1, 5, 7, 3}, /* x = 0 */
        {2, 4, 8, 6}, /* x = 1 */
    };
    for (int q = 0; q < 6; ++q) {
        if (q == skip_face) continue;
        int idx[4];
        for (int c = 0; c < 4; ++c) idx[c] = inward ? quads[q][3 - c] : quads[q][c];
        fputs("f", f);
        for (int c = 0; c < 4; ++c) {
            switch ((q + c) % 5) {
            case 0: fprintf(f, " %d", idx[c]); break;
            case 1: fprintf(f, " %d/%d", idx[c], c + 1); break;
            case 2: fprintf(f, " %d/%d/1", idx[c], c + 1); break;
            case 3: fprintf(f, " %d//1", idx[c]); break;
            default: fprintf(f, " %d/%d", idx[c] - 9, c + 1); break; /* relative: -1 is vertex 8 */
            }
        }
        fputs("   # trailing comment\n", f);
    }
    return fclose(f);
}

/* UV sphere of radius r from triangles; returns the polyhedron's volume
 * computed here, independently of the loader. */
static double write_sphere(const char *path, double r, int nlat, int nlon)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    int nv = 2 + (nlat - 1) * nlon;
    double *v = malloc(3 * (size_t)nv * sizeof *v);
    v[0] = 0, v[1] = 0, v[2] = r;  /* north pole: vertex 1 */
    v[3] = 0, v[4] = 0, v[5] = -r; /* south pole: vertex 2 */
    for (int i = 1; i < nlat; ++i)
        for (int j = 0; j < nlon; ++j) {
            double th = PI * i / nlat, ph = 2 * PI * j / nlon;
            double *p = v + 3 * (2 + (i - 1) * nlon + j);
            p[0] = r * sin(th) * cos(ph);
            p[1] = r * sin(th) * sin(ph);
            p[2] = r * cos(th);
        }
    for (int k = 0; k < nv; ++k) fprintf(f, "v %.17g %.17g %.17g\n", v[3 * k], v[3 * k + 1], v[3 * k + 2]);
    double vol = 0;
#define RING(i, j) (3 + ((i) - 1) * nlon + ((j) % nlon)) /* 1-based vertex of ring i, column j */
#define TRI(a, b, c)                                                                        \
    do {                                                                                    \
        fprintf(f, "f %d %d %d\n", a, b, c);                                                \
        const double *A = v + 3 * ((a) - 1), *B = v + 3 * ((b) - 1), *C = v + 3 * ((c) - 1); \
        vol += (A[0] * (B[1] * C[2] - B[2] * C[1]) - A[1] * (B[0] * C[2] - B[2] * C[0]) +    \
                A[2] * (B[0] * C[1] - B[1] * C[0])) / 6.0;                                  \
    } while (0)
    for (int j = 0; j < nlon; ++j) {
        TRI(1, RING(1, j), RING(1, j + 1));
        TRI(2, RING(nlat - 1, j + 1), RING(nlat - 1, j));
        for (int i = 1; i + 1 < nlat; ++i) {
            TRI(RING(i, j), RING(i + 1, j), RING(i + 1, j + 1));
            TRI(RING(i, j), RING(i + 1, j + 1), RING(i, j + 1));
        }
    }
#undef TRI
#undef RING
    free(v);
    fclose(f);
    return vol;
}

static double cube_sdf(const double x[3])
{
    double out2 = 0, in = -INFINITY;
    for (int d = 0; d < 3; ++d) {
        double e = fmax(-x[d], x[d] - 1); /* > 0 outside this slab */
        if (e > 0) out2 += e * e;
        in = fmax(in, e);
    }
    return out2 > 0 ? sqrt(out2) : in;
}

static void test_cube(void)
{
    const char *path = tmp_path("cube.obj");
    CHECK(write_cube(path, -1, 0) == 0, "cannot write %s", path);
    Mesh *m = NULL;
    int s = mesh_load_obj(path, &m);
    CHECK(s == MPM_OK, "load cube: %s", mpm_last_error());
    if (s) return;
    CHECK(mesh_triangle_count(m) == 12, "cube has %d triangles", mesh_triangle_count(m));
    CHECK(mesh_vertex_count(m) == 8, "cube has %d vertices", mesh_vertex_count(m));
    CHECK(mesh_boundary_edge_count(m) == 0, "cube has boundary edges");
    CHECK(fabs(mesh_volume(m) - 1) < 1e-14, "cube volume %.17g", mesh_volume(m));
    double lo[3], hi[3];
    mesh_bounds(m, lo, hi);
    for (int d = 0; d < 3; ++d) CHECK(lo[d] == 0 && hi[d] == 1, "cube bounds axis %d: %g %g", d, lo[d], hi[d]);

    unsigned long long rng = 1;
    int bad_sign = 0, bad_dist = 0, bad_contains = 0;
    double worst = 0;
    for (int k = 0; k < 20000; ++k) {
        double x[3];
        for (int d = 0; d < 3; ++d) x[d] = test_uniform(&rng, -0.5, 1.5);
        double exact = cube_sdf(x), d = mesh_signed_distance(m, x);
        if (fabs(exact) < 1e-9) continue;
        if ((d < 0) != (exact < 0)) ++bad_sign;
        if ((exact < 0) != mesh_contains(m, x)) ++bad_contains;
        double err = fabs(d - exact);
        if (err > worst) worst = err;
        if (err > 1e-12) ++bad_dist;
    }
    CHECK(bad_sign == 0, "cube: %d wrong signs", bad_sign);
    CHECK(bad_contains == 0, "cube: %d wrong mesh_contains", bad_contains);
    CHECK(bad_dist == 0, "cube: %d wrong distances (worst error %g)", bad_dist, worst);
    double c[3] = {0.5, 0.5, 0.5}, far[3] = {7, -3, 2};
    CHECK(fabs(mesh_winding_number(m, c) - 1) < 1e-9, "winding number at centre %g", mesh_winding_number(m, c));
    CHECK(fabs(mesh_winding_number(m, far)) < 1e-3, "winding number far away %g", mesh_winding_number(m, far));
    double on[3] = {0.5, 0.25, 1.0}, corner[3] = {2, 2, 2};
    CHECK(fabs(mesh_signed_distance(m, on)) < 1e-15, "distance on the surface %g", mesh_signed_distance(m, on));
    CHECK(fabs(mesh_signed_distance(m, corner) - sqrt(3.0)) < 1e-14, "distance to corner %g",
          mesh_signed_distance(m, corner));
    CHECK(fabs(mesh_signed_distance(m, c) + 0.5) < 1e-14, "distance at centre %g", mesh_signed_distance(m, c));
    mesh_free(m);

    /* inward-facing faces: flipped at load */
    path = tmp_path("cube_inward.obj");
    CHECK(write_cube(path, -1, 1) == 0, "cannot write %s", path);
    s = mesh_load_obj(path, &m);
    CHECK(s == MPM_OK, "load inward cube: %s", mpm_last_error());
    if (s) return;
    CHECK(fabs(mesh_volume(m) - 1) < 1e-14, "inward cube volume %g", mesh_volume(m));
    CHECK(mesh_signed_distance(m, c) < 0 && mesh_signed_distance(m, corner) > 0, "inward cube signs");
    mesh_free(m);
}

static void test_sphere(void)
{
    const double r = 0.5;
    const char *path = tmp_path("sphere.obj");
    double poly_vol = write_sphere(path, r, 32, 64);
    Mesh *m = NULL;
    int s = mesh_load_obj(path, &m);
    CHECK(s == MPM_OK, "load sphere: %s", mpm_last_error());
    if (s) return;
    CHECK(mesh_triangle_count(m) == 2 * 64 * 31, "sphere has %d triangles", mesh_triangle_count(m));
    double ball = 4.0 / 3.0 * PI * r * r * r;
    CHECK(rel_diff(mesh_volume(m), poly_vol, 1e-300) < 1e-12, "sphere volume %.15g, polyhedron %.15g",
          mesh_volume(m), poly_vol);
    CHECK(rel_diff(mesh_volume(m), ball, 1e-300) < 0.01, "sphere volume %g, ball %g", mesh_volume(m), ball);

    /* faces lie inside the sphere by at most the sagitta of a cell */
    const double tol = r * (1 - cos(PI / 32)) + 1e-12;
    unsigned long long rng = 2;
    int bad_sign = 0, bad_dist = 0, tested = 0;
    double worst = 0;
    for (int k = 0; k < 20000; ++k) {
        double x[3];
        for (int d = 0; d < 3; ++d) x[d] = test_uniform(&rng, -0.8, 0.8);
        double exact = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - r, d = mesh_signed_distance(m, x);
        double err = fabs(d - exact);
        if (err > worst) worst = err;
        if (err > tol) ++bad_dist;
        if (fabs(exact) < 2 * tol) continue;
        ++tested;
        if ((d < 0) != (exact < 0)) ++bad_sign;
        if (mesh_contains(m, x) != (exact < 0)) ++bad_sign;
    }
    CHECK(tested > 15000, "only %d sphere points tested", tested);
    CHECK(bad_sign == 0, "sphere: %d wrong signs", bad_sign);
    CHECK(bad_dist == 0, "sphere: %d distances off by more than %g (worst %g)", bad_dist, tol, worst);

    /* concurrent queries give the serial answers */
    enum { NQ = 4000 };
    static double q[3 * NQ], serial[NQ], par[NQ];
    for (int k = 0; k < NQ; ++k) {
        for (int d = 0; d < 3; ++d) q[3 * k + d] = test_uniform(&rng, -0.7, 0.7);
        serial[k] = mesh_signed_distance(m, q + 3 * k);
    }
#pragma omp parallel for schedule(dynamic, 16)
    for (int k = 0; k < NQ; ++k) par[k] = mesh_signed_distance(m, q + 3 * k);
    int differ = 0;
    for (int k = 0; k < NQ; ++k) differ += serial[k] != par[k];
    CHECK(differ == 0, "%d parallel queries differ from serial ones", differ);
    mesh_free(m);
}

static void test_open_mesh(void)
{
    const char *path = tmp_path("open_cube.obj");
    CHECK(write_cube(path, 1, 0) == 0, "cannot write %s", path);
    Mesh *m = (Mesh *)1;
    mpm_clear_error();
    int s = mesh_load_obj(path, &m);
    CHECK(s == MPM_EINPUT, "open cube status %d", s);
    CHECK(m == NULL, "open cube: *out not cleared");
    CHECK(strstr(mpm_last_error(), "not closed") != NULL, "message: %s", mpm_last_error());
    CHECK(strstr(mpm_last_error(), path) != NULL, "message lacks file name: %s", mpm_last_error());
    CHECK(strstr(mpm_last_error(), "4 boundary edges") != NULL, "message: %s", mpm_last_error());

    mpm_clear_error();
    s = mesh_load_obj_lenient(path, 3, &m);
    CHECK(s == MPM_EINPUT && strstr(mpm_last_error(), "not closed"), "lenient (3) status %d: %s", s,
          mpm_last_error());

    mpm_clear_error();
    s = mesh_load_obj_lenient(path, 4, &m);
    CHECK(s == MPM_OK, "lenient (4): %s", mpm_last_error());
    if (s) return;
    CHECK(mesh_boundary_edge_count(m) == 4, "boundary edges %d", mesh_boundary_edge_count(m));
    /* centre: 5 of 6 faces seen, winding number 5/6 */
    double c[3] = {0.5, 0.5, 0.5}, out[3] = {0.5, 0.5, -0.5};
    CHECK(fabs(mesh_winding_number(m, c) - 5.0 / 6.0) < 1e-9, "winding number %g", mesh_winding_number(m, c));
    CHECK(mesh_signed_distance(m, c) < 0, "centre of the open cube not inside");
    CHECK(mesh_signed_distance(m, out) > 0, "point below the open cube not outside");
    mesh_free(m);
}

static void expect_error(const char *name, const char *text, const char *what)
{
    const char *path = tmp_path(name);
    if (text) CHECK(write_file(path, text) == 0, "cannot write %s", path);
    mpm_clear_error();
    Mesh *m = NULL;
    int s = mesh_load_obj(path, &m);
    CHECK(s == MPM_EINPUT, "%s: status %d, expected MPM_EINPUT", name, s);
    CHECK(m == NULL, "%s: mesh returned on error", name);
    CHECK(strstr(mpm_last_error(), path) != NULL, "%s: message lacks the file name: %s", name, mpm_last_error());
    CHECK(strstr(mpm_last_error(), what) != NULL, "%s: message lacks '%s': %s", name, what, mpm_last_error());
    if (!s) mesh_free(m);
}

static void test_errors(void)
{
    static const char tet[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    char buf[512];
    expect_error("does_not_exist.obj", NULL, "cannot open");
    expect_error("bad_number.obj", "v 0 0 0\nv 1 0 0\nv 0 1.5x 0\nv 0 0 1\nf 1 3 2\n", ":3: malformed number");
    expect_error("short_vertex.obj", "v 0 0\n", ":1: vertex has 2 coordinates");
    snprintf(buf, sizeof buf, "%sf 1 3 2\nf 1 2 4\nf 1 4 9\nf 2 3 4\n", tet);
    expect_error("index_range.obj", buf, ":7: face index 9 out of range");
    snprintf(buf, sizeof buf, "%sf 1 3 -5\n", tet);
    expect_error("index_negative.obj", buf, ":5: face index -5 out of range");
    snprintf(buf, sizeof buf, "%sf 1 0 2\n", tet);
    expect_error("index_zero.obj", buf, "face index 0 out of range");
    snprintf(buf, sizeof buf, "%sf 1 2\n", tet);
    expect_error("two_vertices.obj", buf, ":5: face with 2 vertices");
    snprintf(buf, sizeof buf, "%sf 1 2/x 3\n", tet);
    expect_error("bad_face.obj", buf, ":5: malformed face vertex '2/x'");
    expect_error("no_faces.obj", tet, "no faces");
    snprintf(buf, sizeof buf, "%sf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 4 3\n", tet);
    expect_error("misoriented.obj", buf, "inconsistently oriented");
    expect_error("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", "no volume");

    /* the same tetrahedron, closed and outward: loads */
    snprintf(buf, sizeof buf, "%sf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", tet);
    const char *path = tmp_path("tet.obj");
    CHECK(write_file(path, buf) == 0, "cannot write %s", path);
    Mesh *m = NULL;
    int s = mesh_load_obj(path, &m);
    CHECK(s == MPM_OK, "tetrahedron: %s", mpm_last_error());
    if (!s) {
        CHECK(fabs(mesh_volume(m) - 1.0 / 6.0) < 1e-15, "tetrahedron volume %g", mesh_volume(m));
        mesh_free(m);
    }
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/mpm_test_mesh_%ld", (long)getpid());
    if (mkdir(g_dir, 0700) != 0) {
        fprintf(stderr, "cannot create %s\n", g_dir);
        return 1;
    }
    test_cube();
    test_sphere();
    test_open_mesh();
    test_errors();
    for (int k = 0; k < g_nfiles; ++k) remove(g_files[k]);
    if (rmdir(g_dir) != 0) fprintf(stderr, "could not remove %s\n", g_dir);
    return test_summary("test_mesh");
}
