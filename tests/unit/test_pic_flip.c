/* floor: core */
/* The PIC/FLIP transfer (Stomakhin et al. 2013; Gast et al. 2015 section
 * 6.1 step 5) against references computed here from the stencil weights:
 *  - alpha = 0 is PIC: v_p = sum w v_i^{n+1} (to round-off), C_p = 0, and x_p
 *    and F_p equal those of the APIC G2P bit for bit;
 *  - alpha = 1 is FLIP: v_p = v_p^n + sum w (v_i^{n+1} - v_i^n);
 *  - alpha = 0.95 is the blend alpha v_FLIP + (1 - alpha) v_PIC;
 *  - positions move with the PIC velocity whatever alpha is, and not at all
 *    with advect = 0;
 *  - transfer_g2p (the default path) equals transfer_g2p_opts with APIC. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/transfer.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

static void copy_into(Particles *dst, const Particles *src)
{
    memset(dst, 0, sizeof *dst);
    particles_copy(dst, src);
}

/* max_k |a_k - b_k| over 3n entries, relative to max |b| */
static double vec_err(const double *a, const double *b, size_t len)
{
    double e = 0, m = 1e-300;
    for (size_t k = 0; k < len; ++k) {
        e = fmax(e, fabs(a[k] - b[k]));
        m = fmax(m, fabs(b[k]));
    }
    return e / m;
}

int main(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 9;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    size_t np = f.p.n;
    int n = f.g.n;
    double dt = 3e-3;
    /* v^{n+1} = v^n + a random increment */
    double *vnew = malloc(sizeof(double) * 3 * (size_t)n);
    unsigned long long rs = 4242;
    for (int i = 0; i < 3 * n; ++i) vnew[i] = f.g.v[i] + test_uniform(&rs, -0.7, 0.7);
    /* references from the stencil */
    double *pic = calloc(3 * np, sizeof(double)), *flip = calloc(3 * np, sizeof(double)),
           *blend = calloc(3 * np, sizeof(double)), *xpic = calloc(3 * np, sizeof(double));
    for (size_t k = 0; k < np; ++k) {
        double inc[3] = {0, 0, 0}, wk[27];
        stencil_weights(&f.st, k, wk, NULL);
        for (int s = 0; s < 27; ++s) {
            int i = f.st.node[27 * k + s];
            if (i < 0) continue;
            double w = wk[s];
            for (int d = 0; d < 3; ++d) {
                pic[3 * k + d] += w * vnew[3 * i + d];
                inc[d] += w * (vnew[3 * i + d] - f.g.v[3 * i + d]);
            }
        }
        for (int d = 0; d < 3; ++d) {
            flip[3 * k + d] = f.p.v[3 * k + d] + inc[d];
            blend[3 * k + d] = 0.95 * flip[3 * k + d] + 0.05 * pic[3 * k + d];
            xpic[3 * k + d] = f.p.x[3 * k + d] + dt * pic[3 * k + d];
        }
    }
    Particles apic, p0, p1, pb, still, dflt;
    copy_into(&apic, &f.p);
    copy_into(&p0, &f.p);
    copy_into(&p1, &f.p);
    copy_into(&pb, &f.p);
    copy_into(&still, &f.p);
    copy_into(&dflt, &f.p);
    G2POptions oa = {TRANSFER_APIC, 1.0, 0.0, 1};
    G2POptions o0 = {TRANSFER_PIC_FLIP, 1.0, 0.0, 1}, o1 = {TRANSFER_PIC_FLIP, 1.0, 1.0, 1},
               ob = {TRANSFER_PIC_FLIP, 1.0, 0.95, 1}, os = {TRANSFER_PIC_FLIP, 1.0, 0.95, 0};
    transfer_g2p_opts(&f.g, &f.st, &apic, vnew, dt, &oa);
    transfer_g2p_opts(&f.g, &f.st, &p0, vnew, dt, &o0);
    transfer_g2p_opts(&f.g, &f.st, &p1, vnew, dt, &o1);
    transfer_g2p_opts(&f.g, &f.st, &pb, vnew, dt, &ob);
    transfer_g2p_opts(&f.g, &f.st, &still, vnew, dt, &os);
    transfer_g2p(&f.g, &f.st, &dflt, vnew, dt, 1.0);

    double e0 = vec_err(p0.v, pic, 3 * np), e1 = vec_err(p1.v, flip, 3 * np), eb = vec_err(pb.v, blend, 3 * np);
    printf("alpha 0 vs PIC %.2e, alpha 1 vs FLIP %.2e, alpha 0.95 vs the blend %.2e (relative)\n", e0, e1, eb);
    CHECK(e0 < 1e-14, "alpha = 0 is PIC: %g", e0);
    CHECK(e1 < 1e-14, "alpha = 1 is FLIP: %g", e1);
    CHECK(eb < 1e-14, "alpha = 0.95 blend: %g", eb);
    CHECK(vec_err(p1.v, pic, 3 * np) > 1e-3, "FLIP must differ from PIC here");
    CHECK(memcmp(p0.v, apic.v, sizeof(double) * 3 * np) == 0, "alpha = 0 velocity equals the APIC G2P's (bitwise)");
    int c_zero = 1;
    for (size_t k = 0; k < 9 * np; ++k) c_zero &= p0.C[k] == 0.0 && p1.C[k] == 0.0 && pb.C[k] == 0.0;
    CHECK(c_zero, "PIC/FLIP stores C_p = 0");
    CHECK(memcmp(p0.F, apic.F, sizeof(double) * 9 * np) == 0 && memcmp(pb.F, apic.F, sizeof(double) * 9 * np) == 0,
          "the F update does not depend on the transfer (bitwise)");
    CHECK(memcmp(p0.x, apic.x, sizeof(double) * 3 * np) == 0 && memcmp(p1.x, apic.x, sizeof(double) * 3 * np) == 0,
          "positions move with the PIC velocity for every alpha (bitwise)");
    CHECK(vec_err(pb.x, xpic, 3 * np) < 1e-15, "x_p += dt v_PIC");
    CHECK(memcmp(still.x, f.p.x, sizeof(double) * 3 * np) == 0, "advect = 0 leaves positions alone");
    CHECK(memcmp(still.v, pb.v, sizeof(double) * 3 * np) == 0, "advect = 0: same velocities");
    CHECK(memcmp(dflt.x, apic.x, sizeof(double) * 3 * np) == 0 && memcmp(dflt.v, apic.v, sizeof(double) * 3 * np) == 0 &&
              memcmp(dflt.C, apic.C, sizeof(double) * 9 * np) == 0 && memcmp(dflt.F, apic.F, sizeof(double) * 9 * np) == 0,
          "transfer_g2p is transfer_g2p_opts with APIC and advection");
    particles_free(&apic);
    particles_free(&p0);
    particles_free(&p1);
    particles_free(&pb);
    particles_free(&still);
    particles_free(&dflt);
    free(pic);
    free(flip);
    free(blend);
    free(xpic);
    free(vnew);
    fixture_free(&f);
    return test_summary("test_pic_flip");
}
