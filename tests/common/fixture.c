/* floor: core */
#include "tests/common/fixture.h"

#include <math.h>
#include <string.h>

#include "core/mat3.h"
#include "core/transfer.h"
#include "tests/common/testutil.h"

void fixture_default(FixtureOptions *o)
{
    memset(o, 0, sizeof *o);
    o->per_axis = 6;
    o->dx = 0.1;
    o->spacing = 0.05;
    o->F_noise = 0.1;
    o->v_noise = 0.5;
    o->C_noise = 0.5;
    o->dt = 1e-2;
    o->seed = 12345;
}

int fixture_build(Fixture *f, const FixtureOptions *o)
{
    memset(f, 0, sizeof *f);
    unsigned long long rs = o->seed;
    f->dt = o->dt;
    for (int m = 0; m < 2; ++m) {
        Material *mat = &f->mats[m];
        snprintf(mat->name, sizeof mat->name, "m%d", m);
        mat->E = m == 0 ? 1e4 : 3e6;
        mat->nu = m == 0 ? 0.3 : 0.4;
        mat->density = 1000;
        material_derive(mat);
    }
    double origin = 1.0;
    double vol = o->spacing * o->spacing * o->spacing;
    for (int i = 0; i < o->per_axis; ++i)
        for (int j = 0; j < o->per_axis; ++j)
            for (int k = 0; k < o->per_axis; ++k) {
                double x[3] = {origin + (i + 0.5 + 0.3 * test_uniform(&rs, -1, 1)) * o->spacing,
                               origin + (j + 0.5 + 0.3 * test_uniform(&rs, -1, 1)) * o->spacing,
                               origin + (k + 0.5 + 0.3 * test_uniform(&rs, -1, 1)) * o->spacing};
                if (o->snap_to_centre) {
                    int d = (int)test_uniform(&rs, 0, 3) % 3;
                    x[d] = (floor(x[d] / o->dx) + 0.5) * o->dx;
                }
                double v[3];
                for (int d = 0; d < 3; ++d) v[d] = o->v_noise * test_uniform(&rs, -1, 1);
                int mat = o->two_materials ? (i >= o->per_axis / 2) : 0;
                int st = particles_push(&f->p, x, v, 1000.0 * vol, vol, mat);
                if (st) return st;
                size_t n = f->p.n - 1;
                double *F = f->p.F + 9 * n, *C = f->p.C + 9 * n;
                for (int e = 0; e < 9; ++e) {
                    F[e] += o->F_noise * test_uniform(&rs, -1, 1);
                    C[e] = o->C_noise * test_uniform(&rs, -1, 1);
                }
                if (o->inverted_fraction_pct > 0 && test_uniform(&rs, 0, 100) < o->inverted_fraction_pct)
                    for (int c = 0; c < 3; ++c) F[c] = -F[c]; /* reflect: det < 0 */
            }
    int st = grid_build(&f->g, &f->st, &f->p, o->dx);
    if (st) return st;
    if (o->mls) {
        stencils_use_mls_gradients(&f->st, &f->p, o->dx);
        transfer_p2g_mls(&f->g, &f->st, &f->p, NULL);
    } else {
        transfer_p2g(&f->g, &f->st, &f->p);
    }
    return problem_prepare(&f->pb, &f->g, &f->st, &f->p, f->mats, 2, o->dt, o->gravity);
}

void fixture_free(Fixture *f)
{
    problem_free(&f->pb);
    grid_free(&f->g);
    stencils_free(&f->st);
    particles_free(&f->p);
}
