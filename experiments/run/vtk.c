#include "experiments/run/vtk.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/fcr.h"
#include "experiments/io/paths.h"

int vtk_series_open(VtkSeries *s, const char *dir, int grid, double min_mass, int rank, int ranks)
{
    memset(s, 0, sizeof *s);
    if (snprintf(s->dir, sizeof s->dir, "%s", dir) >= (int)sizeof s->dir)
        return mpm_error(MPM_EINPUT, "--vtk '%s': path too long", dir);
    s->grid = grid;
    s->min_mass = min_mass;
    s->rank = rank;
    s->ranks = ranks > 1 ? ranks : 1;
    return paths_mkdir_p(dir); /* on every rank: no rank waits for another to make it */
}

void vtk_series_free(VtkSeries *s)
{
    free(s->t);
    free(s->frame);
    free(s->grid_t);
    free(s->grid_frame);
    memset(s, 0, sizeof *s);
}

double vtk_von_mises(const double F[9], double mu, double lambda)
{
    double P[9], sigma[9];
    fcr_psi_P(F, mu, lambda, P);
    double J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
               F[2] * (F[3] * F[7] - F[4] * F[6]);
    for (int i = 0; i < 3; ++i) /* sigma = P F^T / J */
        for (int j = 0; j < 3; ++j) {
            double a = 0.0;
            for (int k = 0; k < 3; ++k) a += P[3 * i + k] * F[3 * j + k];
            sigma[3 * i + j] = a / J;
        }
    double p = (sigma[0] + sigma[4] + sigma[8]) / 3.0, ss = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = sigma[3 * i + j] - (i == j ? p : 0.0);
            ss += d * d;
        }
    return sqrt(1.5 * ss);
}

/* One appended array: its description and bytes. */
typedef struct {
    const char *name, *type;
    int components;
    const void *data;
    uint64_t bytes;
} VtkArray;

static int host_little_endian(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void array_xml(FILE *f, const VtkArray *a, uint64_t *offset)
{
    fprintf(f, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"appended\" "
               "offset=\"%llu\"/>\n",
            a->type, a->name, a->components, (unsigned long long)*offset);
    *offset += sizeof(uint64_t) + a->bytes;
}

/* A PolyData file of n points with vertex cells: point data arrays[0..n_data), then the points. */
static int write_vtp(const char *path, size_t n, const float *points, const VtkArray *data, int n_data)
{
    FILE *f = fopen(path, "wb");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot write", path);
    int64_t *conn = malloc(sizeof *conn * (n + 1)), *offs = malloc(sizeof *offs * (n + 1));
    if (!conn || !offs) {
        free(conn);
        free(offs);
        fclose(f);
        return mpm_error(MPM_EINTERNAL, "out of memory (%zu points)", n);
    }
    for (size_t k = 0; k < n; ++k) {
        conn[k] = (int64_t)k;
        offs[k] = (int64_t)k + 1;
    }
    VtkArray pts = {"Points", "Float32", 3, points, sizeof(float) * 3 * n};
    VtkArray cells[2] = {{"connectivity", "Int64", 1, conn, sizeof(int64_t) * n},
                         {"offsets", "Int64", 1, offs, sizeof(int64_t) * n}};
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"%s\" "
               "header_type=\"UInt64\">\n  <PolyData>\n    <Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" "
               "NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n      <PointData>\n",
            host_little_endian() ? "LittleEndian" : "BigEndian", n, n);
    uint64_t offset = 0;
    for (int i = 0; i < n_data; ++i) array_xml(f, &data[i], &offset);
    fprintf(f, "      </PointData>\n      <Points>\n");
    array_xml(f, &pts, &offset);
    fprintf(f, "      </Points>\n      <Verts>\n");
    array_xml(f, &cells[0], &offset);
    array_xml(f, &cells[1], &offset);
    fprintf(f, "      </Verts>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _");
    const VtkArray *all[64];
    int n_all = 0;
    for (int i = 0; i < n_data && n_all < 60; ++i) all[n_all++] = &data[i];
    all[n_all++] = &pts;
    all[n_all++] = &cells[0];
    all[n_all++] = &cells[1];
    for (int i = 0; i < n_all; ++i) {
        fwrite(&all[i]->bytes, sizeof(uint64_t), 1, f);
        if (all[i]->bytes) fwrite(all[i]->data, 1, all[i]->bytes, f);
    }
    fprintf(f, "\n  </AppendedData>\n</VTKFile>\n");
    free(conn);
    free(offs);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) return mpm_error(MPM_EINPUT, "%s: write failed", path);
    return MPM_OK;
}

/* The file of a frame: NAME_NNNN.vtp on one process; over ranks each rank's
 * piece NAME_NNNN_rK.vtp and rank 0's NAME_NNNN.pvtp that lists them. */
static void frame_path(const VtkSeries *s, const char *name, int frame, char *out, size_t cap)
{
    if (s->ranks > 1) snprintf(out, cap, "%s/%s_%04d_r%d.vtp", s->dir, name, frame, s->rank);
    else snprintf(out, cap, "%s/%s_%04d.vtp", s->dir, name, frame);
}

/* DIR/NAME_NNNN.pvtp: the ranks' pieces of a frame and their arrays' types
 * (ParaView reads them as one data set). */
static int write_pvtp(const VtkSeries *s, const char *name, int frame, const VtkArray *data, int n_data)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s_%04d.pvtp", s->dir, name, frame);
    FILE *f = fopen(path, "w");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot write", path);
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PPolyData\" version=\"1.0\" byte_order=\"%s\" "
               "header_type=\"UInt64\">\n  <PPolyData GhostLevel=\"0\">\n    <PPointData>\n",
            host_little_endian() ? "LittleEndian" : "BigEndian");
    for (int i = 0; i < n_data; ++i)
        fprintf(f, "      <PDataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\"/>\n", data[i].type,
                data[i].name, data[i].components);
    fprintf(f, "    </PPointData>\n    <PPoints>\n      <PDataArray type=\"Float32\" Name=\"Points\" "
               "NumberOfComponents=\"3\"/>\n    </PPoints>\n");
    for (int r = 0; r < s->ranks; ++r) fprintf(f, "    <Piece Source=\"%s_%04d_r%d.vtp\"/>\n", name, frame, r);
    fprintf(f, "  </PPolyData>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) return mpm_error(MPM_EINPUT, "%s: write failed", path);
    return MPM_OK;
}

/* A frame's file(s) of n points: this rank's piece, and over ranks rank 0's .pvtp. */
static int write_frame_files(const VtkSeries *s, const char *name, int frame, size_t n, const float *points,
                             const VtkArray *data, int n_data)
{
    char path[1200];
    frame_path(s, name, frame, path, sizeof path);
    int st = write_vtp(path, n, points, data, n_data);
    if (!st && s->ranks > 1 && s->rank == 0) st = write_pvtp(s, name, frame, data, n_data);
    return st;
}

/* DIR/NAME.pvd listing NAME_NNNN.vtp (over ranks NAME_NNNN.pvtp) of the
 * given frames and times (rewritten whole). */
static int write_pvd(const char *dir, const char *name, const char *ext, const int *frame, const double *t, int n)
{
    char path[1200], tmp[1300];
    snprintf(path, sizeof path, "%s/%s.pvd", dir, name);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) return mpm_error(MPM_EINPUT, "%s: cannot write", tmp);
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"%s\">\n"
               "  <Collection>\n",
            host_little_endian() ? "LittleEndian" : "BigEndian");
    for (int i = 0; i < n; ++i)
        fprintf(f, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s_%04d.%s\"/>\n", t[i], name,
                frame[i], ext);
    fprintf(f, "  </Collection>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad || rename(tmp, path) != 0) return mpm_error(MPM_EINPUT, "%s: write failed", path);
    return MPM_OK;
}

static int remember(double **t, int **frame, int *n, int *cap, int fr, double time)
{
    if (*n == *cap) {
        int c = *cap ? 2 * *cap : 64;
        double *nt = realloc(*t, sizeof *nt * (size_t)c);
        if (nt) *t = nt;
        int *nf = realloc(*frame, sizeof *nf * (size_t)c);
        if (nf) *frame = nf;
        if (!nt || !nf) return mpm_error(MPM_EINTERNAL, "out of memory (VTK series)");
        *cap = c;
    }
    (*t)[*n] = time;
    (*frame)[*n] = fr;
    (*n)++;
    return MPM_OK;
}

static int particles_file(VtkSeries *s, int frame, const Particles *p, const Material *materials, int n_materials)
{
    size_t n = p->n;
    float *buf = malloc(sizeof *buf * (13 * n + 1));
    int32_t *mat = malloc(sizeof *mat * (n + 1));
    int64_t *id = malloc(sizeof *id * (n + 1));
    if (!buf || !mat || !id) {
        free(buf);
        free(mat);
        free(id);
        return mpm_error(MPM_EINTERNAL, "out of memory (%zu particles)", n);
    }
    float *x = buf, *v = buf + 3 * n, *J = buf + 6 * n, *Jp = buf + 7 * n, *vm = buf + 8 * n, *m = buf + 9 * n,
          *vol = buf + 10 * n;
    for (size_t k = 0; k < n; ++k) {
        const double *F = p->F + 9 * k;
        for (int d = 0; d < 3; ++d) {
            x[3 * k + d] = (float)p->x[3 * k + d];
            v[3 * k + d] = (float)p->v[3 * k + d];
        }
        mat[k] = p->mat[k];
        id[k] = (int64_t)p->id[k];
        J[k] = (float)(F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                       F[2] * (F[3] * F[7] - F[4] * F[6]));
        Jp[k] = p->Jp ? (float)p->Jp[k] : 1.0f;
        const Material *mt = p->mat[k] >= 0 && p->mat[k] < n_materials ? &materials[p->mat[k]] : NULL;
        vm[k] = mt ? (float)vtk_von_mises(F, mt->mu, mt->lambda) : NAN;
        m[k] = (float)p->mass[k];
        vol[k] = (float)p->vol[k];
    }
    VtkArray data[] = {{"velocity", "Float32", 3, v, sizeof(float) * 3 * n},
                       {"material", "Int32", 1, mat, sizeof(int32_t) * n},
                       {"id", "Int64", 1, id, sizeof(int64_t) * n},
                       {"J", "Float32", 1, J, sizeof(float) * n},
                       {"plastic_J", "Float32", 1, Jp, sizeof(float) * n},
                       {"von_mises", "Float32", 1, vm, sizeof(float) * n},
                       {"mass", "Float32", 1, m, sizeof(float) * n},
                       {"volume", "Float32", 1, vol, sizeof(float) * n}};
    int st = write_frame_files(s, "particles", frame, n, x, data, (int)(sizeof data / sizeof data[0]));
    free(buf);
    free(mat);
    free(id);
    return st;
}

/* The frame's heaviest node is the whole scene's (over ranks the caller
 * gives it); a rank writes the nodes it owns (owned NULL: all). */
static int grid_file(VtkSeries *s, int frame, const Grid *g, const double *grid_v, const unsigned char *owned,
                     double heaviest)
{
    size_t n = (size_t)g->n;
    float *buf = malloc(sizeof *buf * (10 * n + 1));
    if (!buf) return mpm_error(MPM_EINTERNAL, "out of memory (%zu grid nodes)", n);
    float *x = buf, *v = buf + 3 * n, *m = buf + 6 * n, *q = buf + 7 * n;
    double floor_mass = s->min_mass * heaviest;
    size_t kept = 0;
    for (size_t k = 0; k < n; ++k) {
        if (owned && !owned[k]) continue;
        if (s->min_mass > 0 && g->mass[k] < floor_mass) continue;
        for (int d = 0; d < 3; ++d) {
            x[3 * kept + d] = (float)(g->coord[3 * k + d] * g->dx);
            v[3 * kept + d] = (float)grid_v[3 * k + d];
            q[3 * kept + d] = (float)(g->mass[k] * grid_v[3 * k + d]);
        }
        m[kept++] = (float)g->mass[k];
    }
    n = kept;
    VtkArray data[] = {{"mass", "Float32", 1, m, sizeof(float) * n},
                       {"velocity", "Float32", 3, v, sizeof(float) * 3 * n},
                       {"momentum", "Float32", 3, q, sizeof(float) * 3 * n}};
    int st = write_frame_files(s, "grid", frame, n, x, data, (int)(sizeof data / sizeof data[0]));
    free(buf);
    return st;
}

double vtk_heaviest_node(const Grid *g, const unsigned char *owned)
{
    double heaviest = 0.0;
    for (int k = 0; k < g->n; ++k)
        if ((!owned || owned[k]) && g->mass[k] > heaviest) heaviest = g->mass[k];
    return heaviest;
}

int vtk_series_frame(VtkSeries *s, int frame, double t, const Particles *p, const Material *materials, int n_materials,
                     const VtkGridFrame *grid)
{
    const char *ext = s->ranks > 1 ? "pvtp" : "vtp";
    int st = particles_file(s, frame, p, materials, n_materials);
    if (!st) st = remember(&s->t, &s->frame, &s->n, &s->cap, frame, t);
    if (!st && s->rank == 0) st = write_pvd(s->dir, "particles", ext, s->frame, s->t, s->n);
    if (st || !s->grid || !grid) return st;
    st = grid_file(s, frame, grid->g, grid->v, grid->owned, grid->heaviest);
    if (!st) st = remember(&s->grid_t, &s->grid_frame, &s->n_grid, &s->cap_grid, frame, t);
    if (!st && s->rank == 0) st = write_pvd(s->dir, "grid", ext, s->grid_frame, s->grid_t, s->n_grid);
    return st;
}
