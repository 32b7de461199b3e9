/* floor: driver */
/* Boundary conditions (SPEC 2 item 3): with no elastic and no body force, a
 * sticky node ends the step with exactly the prescribed velocity, a slip
 * node loses exactly the normal component of its velocity relative to the
 * collider and keeps its tangential velocity, and free nodes keep theirs.
 * Also: the BC-projected assembled Hessian has identity rows at sticky nodes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/mat3.h"
#include "experiments/driver/registry.h"
#include "solvers/solver.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

int main(void)
{
    FixtureOptions o;
    fixture_default(&o);
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    StepProblem *pb = &f.pb;
    /* switch elasticity off: the minimiser is then dv = dt g = 0 on free nodes */
    for (size_t k = 0; k < f.p.n; ++k) pb->mu[k] = pb->lambda[k] = 0.0;
    const double vs[3] = {0.3, -0.1, 0.2};
    const double nrm[3] = {0.0, 1.0, 0.0}, vslip[3] = {5.0, 0.25, -7.0};
    for (int i = 0; i < pb->n_nodes; ++i) {
        if (i % 5 == 0) problem_set_dirichlet(pb, i, vs, NULL);
        else if (i % 5 == 1) problem_set_dirichlet(pb, i, vslip, nrm);
    }
    problem_finish_dirichlet(pb);
    int n = pb->n_nodes;
    double *dv = calloc(3 * (size_t)n, sizeof(double));
    problem_initial_guess(pb, dv);
    Solver *s = NULL;
    CHECK(solver_from_spec("pn-pcg", NULL, 0, &s) == 0, "solver pn-pcg: %s", mpm_last_error());
    SolveSettings set;
    solve_settings_default(&set);
    SolveStats st;
    CHECK(solver_solve(s, pb, &set, dv, &st, NULL, NULL, NULL) == 0, "solve");
    CHECK(st.status == SOLVE_CONVERGED, "converged (status %d)", st.status);
    double worst_sticky = 0, worst_slip_n = 0, worst_slip_t = 0, worst_free = 0;
    for (int i = 0; i < n; ++i) {
        const double *vn = f.g.v + 3 * i;
        double v1[3] = {vn[0] + dv[3 * i], vn[1] + dv[3 * i + 1], vn[2] + dv[3 * i + 2]};
        if (i % 5 == 0) {
            for (int d = 0; d < 3; ++d) worst_sticky = fmax(worst_sticky, fabs(v1[d] - vs[d]));
        } else if (i % 5 == 1) {
            worst_slip_n = fmax(worst_slip_n, fabs(v3_dot(v1, nrm) - v3_dot(vslip, nrm)));
            worst_slip_t = fmax(worst_slip_t, fmax(fabs(v1[0] - vn[0]), fabs(v1[2] - vn[2])));
        } else {
            for (int d = 0; d < 3; ++d) worst_free = fmax(worst_free, fabs(v1[d] - vn[d]));
        }
    }
    CHECK(worst_sticky < 1e-14, "sticky nodes take the collider velocity (err %.3e)", worst_sticky);
    CHECK(worst_slip_n < 1e-14, "slip nodes: normal velocity = collider's (err %.3e)", worst_slip_n);
    CHECK(worst_slip_t < 1e-12, "slip nodes keep their tangential velocity (err %.3e)", worst_slip_t);
    CHECK(worst_free < 1e-12, "free nodes keep their velocity (err %.3e)", worst_free);

    /* projected Hessian: identity rows/cols at sticky nodes */
    problem_energy(pb, dv);
    problem_tangent(pb, 1);
    Bsr H = {0};
    problem_assemble(pb, &H);
    int ok = 1;
    for (int i = 0; i < n; ++i)
        for (int64_t k = H.row_ptr[i]; k < H.row_ptr[i + 1]; ++k) {
            int j = H.col[k];
            if (i % 5 != 0 && j % 5 != 0) continue;
            for (int e = 0; e < 9; ++e) {
                double want = (i == j && e % 4 == 0) ? 1.0 : 0.0;
                if (H.val[9 * k + e] != want) ok = 0;
            }
        }
    CHECK(ok, "sticky rows and columns of the BC-projected Hessian are identity/zero");
    bsr_free(&H);
    solver_destroy(s);
    free(dv);
    fixture_free(&f);
    return test_summary("test_bc");
}
