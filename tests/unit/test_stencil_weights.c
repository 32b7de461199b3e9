/* floor: core */
/* The stencil weights and gradients rebuilt from the 1D factors
 * (stencil_weights, core/grid.h) against the quadratic B-spline evaluated
 * node by node from its piecewise definition (SPEC 1), and the node ids
 * grid_build looks up once per cell against a lookup per particle: a node
 * id wherever the weight is positive, -1 exactly where it is zero. Run on
 * a jittered lattice and on one with particles at cell centres (exact zero
 * weights). */
#include <math.h>

#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

/* N(r) of the quadratic B-spline and dN/dr, r = x/dx - node index. */
static double bspline(double r, double *dr)
{
    double a = fabs(r), sg = r < 0 ? -1.0 : 1.0;
    if (a < 0.5) {
        *dr = -2.0 * r;
        return 0.75 - a * a;
    }
    if (a < 1.5) {
        *dr = -sg * (1.5 - a);
        return 0.5 * (1.5 - a) * (1.5 - a);
    }
    *dr = 0.0;
    return 0.0;
}

static void check(int snap)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 9;
    o.dx = 0.125;
    o.snap_to_centre = snap;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    const double dx = f.g.dx;
    double worst_w = 0, worst_dw = 0, worst_sum = 0;
    int id_bad = 0, zeros = 0;
    for (size_t k = 0; k < f.p.n; ++k) {
        double w[27], dw[81], wonly[27], sum = 0;
        stencil_weights(&f.st, k, w, dw);
        stencil_weights(&f.st, k, wonly, NULL);
        const int *base = f.st.base + 3 * k;
        for (int s = 0; s < 27; ++s) {
            int off[3] = {s / 9, (s / 3) % 3, s % 3}, c[3];
            double N[3], D[3];
            for (int d = 0; d < 3; ++d) {
                c[d] = base[d] + off[d];
                N[d] = bspline(f.p.x[3 * k + d] / dx - c[d], &D[d]);
                D[d] /= dx; /* d/dx_p N(x_p/dx - i) = N'(r)/dx */
            }
            double want = N[0] * N[1] * N[2];
            double gw[3] = {D[0] * N[1] * N[2], N[0] * D[1] * N[2], N[0] * N[1] * D[2]};
            worst_w = fmax(worst_w, fabs(w[s] - want));
            for (int d = 0; d < 3; ++d) worst_dw = fmax(worst_dw, fabs(dw[3 * s + d] - gw[d]) * dx);
            if (w[s] != wonly[s]) ++id_bad;
            sum += w[s];
            int node = f.st.node[27 * k + s];
            if (w[s] > 0.0) {
                if (node != grid_lookup(&f.g, c)) ++id_bad;
            } else {
                ++zeros;
                if (node != -1) ++id_bad;
            }
        }
        worst_sum = fmax(worst_sum, fabs(sum - 1.0));
    }
    CHECK(worst_w <= 4e-16, "snap %d: weights vs the B-spline: max diff %.3e", snap, worst_w);
    CHECK(worst_dw <= 2e-15, "snap %d: gradients vs the B-spline (times dx): max diff %.3e", snap, worst_dw);
    CHECK(worst_sum <= 1e-15, "snap %d: partition of unity: max |sum w - 1| %.3e", snap, worst_sum);
    CHECK(id_bad == 0, "snap %d: %d node ids differ from a per-particle lookup", snap, id_bad);
    if (snap) CHECK(zeros > 0, "snap %d: cell centres give exact zero weights", snap);
    fixture_free(&f);
}

int main(void)
{
    check(0);
    check(1);
    return test_summary("test_stencil_weights");
}
