/* floor: core */
/* P2G/G2P with APIC conserve mass, linear and angular momentum when no force
 * acts (Jiang et al. 2015): P2G -> G2P (dt = 0, grid velocities unchanged) ->
 * P2G gives back the same grid momentum and angular momentum. The grid
 * numbering and the particle-block colouring are also checked. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/mat3.h"
#include "core/transfer.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

static void grid_moments(const Grid *g, double *mass, double P[3], double L[3])
{
    *mass = 0;
    memset(P, 0, 3 * sizeof(double));
    memset(L, 0, 3 * sizeof(double));
    for (int i = 0; i < g->n; ++i) {
        double x[3] = {g->coord[3 * i] * g->dx, g->coord[3 * i + 1] * g->dx, g->coord[3 * i + 2] * g->dx};
        double mv[3] = {g->mass[i] * g->v[3 * i], g->mass[i] * g->v[3 * i + 1], g->mass[i] * g->v[3 * i + 2]};
        double c[3];
        v3_cross(x, mv, c);
        *mass += g->mass[i];
        for (int d = 0; d < 3; ++d) {
            P[d] += mv[d];
            L[d] += c[d];
        }
    }
}

int main(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 10;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    double pm = 0, pP[3] = {0};
    for (size_t k = 0; k < f.p.n; ++k) {
        pm += f.p.mass[k];
        for (int d = 0; d < 3; ++d) pP[d] += f.p.mass[k] * f.p.v[3 * k + d];
    }
    double m0, P0[3], L0[3];
    grid_moments(&f.g, &m0, P0, L0);
    CHECK(rel_diff(m0, pm, 1e-300) < 1e-13, "mass: grid %.15e particles %.15e", m0, pm);
    for (int d = 0; d < 3; ++d) CHECK(fabs(P0[d] - pP[d]) < 1e-13 * (fabs(pm) + 1), "P2G linear momentum %d", d);
    /* G2P with dt = 0 keeps positions; then P2G again */
    double *vgrid = malloc(sizeof(double) * 3 * (size_t)f.g.n);
    memcpy(vgrid, f.g.v, sizeof(double) * 3 * (size_t)f.g.n);
    transfer_g2p(&f.g, &f.st, &f.p, vgrid, 0.0, 1.0);
    transfer_p2g(&f.g, &f.st, &f.p);
    double m1, P1[3], L1[3];
    grid_moments(&f.g, &m1, P1, L1);
    double Lscale = fabs(L0[0]) + fabs(L0[1]) + fabs(L0[2]);
    for (int d = 0; d < 3; ++d) {
        CHECK(fabs(P1[d] - P0[d]) < 1e-12 * (fabs(P0[d]) + pm), "linear momentum %d: %.15e vs %.15e", d, P1[d], P0[d]);
        CHECK(fabs(L1[d] - L0[d]) < 1e-11 * Lscale, "angular momentum %d: %.15e vs %.15e", d, L1[d], L0[d]);
    }
    /* node ids: coordinates unique and lookups consistent */
    int ok = 1;
    for (int i = 0; i < f.g.n && ok; ++i)
        if (grid_lookup(&f.g, f.g.coord + 3 * i) != i) ok = 0;
    CHECK(ok, "grid_lookup(coord(i)) == i");
    /* every active node has positive mass */
    int pos = 1;
    for (int i = 0; i < f.g.n; ++i)
        if (!(f.g.mass[i] > 0)) pos = 0;
    CHECK(pos, "all active nodes have positive mass");
    free(vgrid);
    fixture_free(&f);
    return test_summary("test_transfer");
}
