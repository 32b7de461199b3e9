/* floor: core */
/* P2G through block-local arenas (core/transfer_blocked.c) against the plain
 * kernels of core/transfer.c on a jittered two-material lattice spanning
 * many 4x4x4 blocks: the MLS fused P2G and the APIC P2G with the explicit
 * force of the transfer benchmark, and both without force (the implicit
 * step's P2G). The grids agree node by node to 1e-13 relative to the
 * largest entry (only the grouping of the sums differs), at 1 and 2 threads. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/transfer_blocked.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

#define TOL 1e-13

static double max_abs(size_t n, const double *a)
{
    double m = 0;
    for (size_t k = 0; k < n; ++k) m = fmax(m, fabs(a[k]));
    return m;
}

static double max_diff(size_t n, const double *a, const double *b)
{
    double m = 0;
    for (size_t k = 0; k < n; ++k) m = fmax(m, fabs(a[k] - b[k]));
    return m;
}

static void compare(int mls, int with_force, int threads)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 24; /* 13,824 particles over a 12^3-node region: dozens of blocks of every colour */
    o.dx = 0.1;
    o.two_materials = 1;
    o.mls = mls;
    o.F_noise = 0.2;
    Fixture f;
    int st = fixture_build(&f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return;
    omp_set_num_threads(threads);
    ExplicitForce force = {.dt = 1e-3, .mats = f.mats, .gravity = {0, -9.8, 0}};
    const ExplicitForce *fp = with_force ? &force : NULL;
    const size_t n = (size_t)f.g.n;
    double *m0 = malloc(sizeof(double) * n), *v0 = malloc(sizeof(double) * 3 * n);
    if (mls) transfer_p2g_mls(&f.g, &f.st, &f.p, fp);
    else transfer_p2g_apic_force(&f.g, &f.st, &f.p, fp);
    memcpy(m0, f.g.mass, sizeof(double) * n);
    memcpy(v0, f.g.v, sizeof(double) * 3 * n);
    transfer_p2g_blocked(&f.g, &f.st, &f.p, fp, mls ? TRANSFER_MLS : TRANSFER_APIC);
    double em = max_diff(n, m0, f.g.mass) / max_abs(n, m0), ev = max_diff(3 * n, v0, f.g.v) / max_abs(3 * n, v0);
    printf("%s%s, %d threads, %zu particles, %zu nodes, %d particle blocks: mass %.2e, velocity %.2e\n",
           mls ? "MLS" : "APIC", with_force ? " + force" : "", threads, f.p.n, n, f.st.pcolor.n_blocks, em, ev);
    CHECK(f.st.pcolor.n_blocks >= 27, "the lattice spans many blocks (%d)", f.st.pcolor.n_blocks);
    CHECK(em <= TOL && ev <= TOL, "%s%s at %d threads: blocked P2G differs by %.3e (mass), %.3e (velocity)",
          mls ? "MLS" : "APIC", with_force ? " + force" : "", threads, em, ev);
    free(m0), free(v0);
    fixture_free(&f);
}

int main(void)
{
    for (int threads = 1; threads <= 2; ++threads)
        for (int mls = 0; mls <= 1; ++mls)
            for (int force = 0; force <= 1; ++force) compare(mls, force, threads);
    return test_summary("test_transfer_blocked");
}
