/* floor: scene */
/* The Hessian cell kernel (core/hessian_cell.c):
 *  - against the plain triple sum K_st = sum_p s_p a_ps^T A_p a_pt on random
 *    particles, for particle counts across the kernel's chunk of 8 (1, 7, 8,
 *    9, 17), both builds (AVX2+FMA where the CPU has it, and portable), to
 *    1e-14 relative to the largest entry;
 *  - the assembled Hessian of a scene's first step (bar3) with the AUTO and
 *    the PORTABLE kernel: entrywise within 1e-14 of the largest entry (they
 *    differ by FMA rounding only). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/hessian_cell.h"
#include "core/problem.h"
#include "tests/common/fixture.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static double urand(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

static void test_against_reference(int n, int kernel)
{
    unsigned long long rs = 17 + (unsigned long long)n;
    double *A = malloc(sizeof(double) * 81 * (size_t)n), *a = malloc(sizeof(double) * 81 * (size_t)n);
    double *vol = malloc(sizeof(double) * (size_t)n);
    double *K = malloc(sizeof(double) * HESSIAN_CELL_SIZE);
    for (int p = 0; p < n; ++p) {
        double *Ap = A + 81 * p;
        for (int r = 0; r < 9; ++r) /* symmetric, as dP/dF is */
            for (int c = r; c < 9; ++c) Ap[9 * r + c] = Ap[9 * c + r] = 1e3 * urand(&rs);
        for (int e = 0; e < 81; ++e) a[81 * p + e] = 10.0 * urand(&rs);
        a[81 * p + 3 * 13] = a[81 * p + 3 * 13 + 1] = a[81 * p + 3 * 13 + 2] = 0.0; /* a zero gradient */
        vol[p] = 1e-3 * (1.5 + urand(&rs));
    }
    double scale = 0.7;
    for (int e = 0; e < HESSIAN_CELL_SIZE; ++e) K[e] = NAN; /* untouched entries stay NaN */
    hessian_cell(n, A, a, vol, scale, K, kernel);
    double err = 0.0, mx = 0.0;
    int missing = 0;
    for (int s = 0; s < 27; ++s)
        for (int t = s; t < 27; ++t)
            for (int al = 0; al < 3; ++al)
                for (int c = 0; c < 3; ++c) {
                    double ref = 0.0;
                    for (int p = 0; p < n; ++p) {
                        const double *Ap = A + 81 * p, *as = a + 81 * p + 3 * s, *at = a + 81 * p + 3 * t;
                        double v = 0.0;
                        for (int b = 0; b < 3; ++b)
                            for (int d = 0; d < 3; ++d) v += Ap[9 * (3 * al + b) + 3 * c + d] * as[b] * at[d];
                        ref += scale * vol[p] * v;
                    }
                    double got = K[(9 * s + 3 * al + c) * HESSIAN_CELL_LD + t];
                    if (!isfinite(got)) ++missing;
                    err = fmax(err, fabs(got - ref));
                    mx = fmax(mx, fabs(ref));
                }
    CHECK(missing == 0, "n=%d kernel=%d: %d upper entries not written", n, kernel, missing);
    CHECK(err <= 1e-14 * mx, "n=%d kernel=%d: max error %.3e of max entry %.3e (%.2e relative)", n, kernel, err, mx,
          err / mx);
    free(A), free(a), free(vol), free(K);
}

static void test_kernels_agree_on_scene(void)
{
    SceneStep ss;
    int st = scene_step_open(&ss, "bar3", 5.0);
    CHECK(st == 0, "open bar3");
    if (st) {
        scene_step_close(&ss);
        return;
    }
    StepProblem *pb = &ss.sim.pb;
    int n = pb->n_nodes;
    double *dv = malloc(sizeof(double) * 3 * (size_t)n);
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    problem_tangent(pb, 1);
    Bsr H1 = {0}, H2 = {0};
    pb->cell_kernel = HESSIAN_CELL_AUTO;
    CHECK(problem_assemble(pb, &H1) == 0, "assemble (auto)");
    pb->cell_kernel = HESSIAN_CELL_PORTABLE;
    CHECK(problem_assemble(pb, &H2) == 0, "assemble (portable)");
    pb->cell_kernel = HESSIAN_CELL_AUTO;
    CHECK(H1.nnzb == H2.nnzb, "same pattern");
    double err = 0.0, mx = 0.0;
    for (int64_t e = 0; e < 9 * H1.nnzb; ++e) {
        err = fmax(err, fabs(H1.val[e] - H2.val[e]));
        mx = fmax(mx, fabs(H1.val[e]));
    }
    printf("bar3 (%zu particles, %lld blocks): %s kernel against portable: max difference %.3e of max entry %.3e\n",
           pb->n_particles, (long long)H1.nnzb, hessian_cell_isa(), err, mx);
    CHECK(err <= 1e-14 * mx, "AUTO (%s) and PORTABLE kernels: max difference %.3e of max entry %.3e",
          hessian_cell_isa(), err, mx);
    bsr_free(&H1);
    bsr_free(&H2);
    free(dv);
    scene_step_close(&ss);
}

int main(void)
{
    static const int counts[] = {1, 7, 8, 9, 17};
    for (int kernel = HESSIAN_CELL_AUTO; kernel <= HESSIAN_CELL_PORTABLE; ++kernel)
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; ++i) test_against_reference(counts[i], kernel);
    test_kernels_agree_on_scene();
    return test_summary("test_hessian_cell");
}
