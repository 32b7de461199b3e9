/* floor: app */
/* The stress measure of the ParaView output (experiments/run/vtk.h): the von
 * Mises stress of the fixed-corotated Cauchy stress. For F = diag(s) the
 * Cauchy stress is diagonal, sigma_i = 2 mu (s_i - 1) s_i / J + lambda (J - 1)
 * (P = 2 mu (F - I) + lambda (J - 1) J F^-T with R = I), so von Mises is
 * sqrt(((s1-s2)^2 + (s2-s3)^2 + (s3-s1)^2) / 2) of those; it is invariant
 * under F -> Q F V^T for rotations Q, V (the stress rotates, its invariants
 * do not), and zero for a pure rotation and for a uniform scaling (pressure
 * only). */
#include "core/mat3.h"
#include "experiments/run/vtk.h"
#include "tests/common/testutil.h"

#include <math.h>

static double expected_diag(const double s[3], double mu, double lambda)
{
    double J = s[0] * s[1] * s[2], sig[3];
    for (int i = 0; i < 3; ++i) sig[i] = 2 * mu * (s[i] - 1) * s[i] / J + lambda * (J - 1);
    return sqrt(0.5 * ((sig[0] - sig[1]) * (sig[0] - sig[1]) + (sig[1] - sig[2]) * (sig[1] - sig[2]) +
                       (sig[2] - sig[0]) * (sig[2] - sig[0])));
}

int main(void)
{
    unsigned long long rng = 4242;
    const double mu = 3.8e4, lambda = 5.8e4;
    for (int trial = 0; trial < 50; ++trial) {
        double s[3], F[9] = {0}, w1[3], w2[3], Q[9], V[9], T[9], G[9];
        for (int k = 0; k < 3; ++k) {
            s[k] = test_uniform(&rng, 0.5, 1.6);
            F[4 * k] = s[k];
            w1[k] = test_uniform(&rng, -3, 3);
            w2[k] = test_uniform(&rng, -3, 3);
        }
        double want = expected_diag(s, mu, lambda), got = vtk_von_mises(F, mu, lambda);
        CHECK(fabs(got - want) <= 1e-10 * want, "diag(%g %g %g): %.12g vs %.12g", s[0], s[1], s[2], got, want);
        m3_rotation(w1, Q);
        m3_rotation(w2, V);
        m3_mul(Q, F, T);
        m3_mul_bt(T, V, G);
        double rot = vtk_von_mises(G, mu, lambda);
        CHECK(fabs(rot - want) <= 1e-9 * want, "rotated: %.12g vs %.12g", rot, want);
        double scaled[9] = {s[0], 0, 0, 0, s[0], 0, 0, 0, s[0]};
        CHECK(vtk_von_mises(scaled, mu, lambda) <= 1e-9 * mu, "uniform scaling: %g", vtk_von_mises(scaled, mu, lambda));
        CHECK(vtk_von_mises(Q, mu, lambda) <= 1e-9 * mu, "pure rotation: %g", vtk_von_mises(Q, mu, lambda));
    }
    return test_summary("test_vtk_stress");
}
