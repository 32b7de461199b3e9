/* floor: driver */
/* needs: MPM_WITH_CHOLMOD */
/* Solver agreement under MLS-MPM (SPEC 9; issue 21): every preset that
 * iterates to a tolerance converges on the first step of stretched-box and
 * of bar3 (E_mid 1e9) at the smoke matrix's coarse scales with
 * transfer = mls, never raises the energy, and agrees with a tight pn-cholmod
 * solve within the two-sided a-posteriori bound of the APIC test
 * (tests/conformance/test_solvers.c, checks in tests/common/agreement.c):
 *     r_k / 2 - r* <= |dv_k - dv*|_H <= 2 r_k + r*,  r = |g|_{H^-1}.
 * Everything downstream of the MLS gradient substitute (CN rule, Galerkin
 * hierarchy, outer methods, inverse approximations) is thereby exercised on
 * the MLS Hessian. The reference is exact Newton: pn-pcg at 1e-13 ended in a
 * line-search stall at round-off (|g|_H^-1 2.7e-8) on stretched-box once the
 * Hessian's last bits changed (the AVX2 cell kernel): its convergence there
 * was luck. */
#include "core/error.h"
#include "tests/common/agreement.h"
#include "tests/common/testutil.h"

int main(void)
{
    static const AgreementCase cases[] = {
        {.scene = "stretched-box", .scale = 3.6, .transfer = TRANSFER_MLS, .reference = "pn-cholmod", .eps_ref = 1e-13,
         .eps = 1e-9, .min_outer = 2},
        {.scene = "bar3", .scale = 4.3, .transfer = TRANSFER_MLS, .reference = "pn-cholmod", .eps_ref = 1e-13,
         .eps = 1e-9, .min_outer = 2},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) agreement_check(&cases[k]);
    return test_summary("test_solvers_mls");
}
