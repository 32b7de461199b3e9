/* Level-set colliders with piecewise-constant rigid motion (see collider.h).
 *
 * Rigid kinematics: with world-frame angular velocity omega and pivot
 * p(t) = pivot0 + b(t), the pose R(t) obeys dR/dt = [omega]x R, whose exact
 * solution over a phase of constant omega is R(t) = exp([omega]x tau) R0
 * (Rodrigues' formula, m3_rotation); the material velocity at x is
 * omega x (x - p(t)) + db/dt. The optional oscillation adds a closed-form
 * translation a sin(w t + p) to b(t) (and a w cos(w t + p) to db/dt), the
 * optional material velocity R(t) v_m to the velocity. */
#include "core/collider.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/mat3.h"

/* Index of the phase containing time t (phases cover [0, inf); t < 0 maps
 * to the first). */
static int find_phase(const Collider *c, double t)
{
    int k = 0;
    while (k + 1 < c->n_phases && !(t < c->phases[k].t_end)) ++k;
    return k;
}

static void pose_in_phase(const ColliderPhase *ph, double t, double R[9], double b[3])
{
    double tau = t - ph->t_start;
    double w[3] = {ph->omega[0] * tau, ph->omega[1] * tau, ph->omega[2] * tau};
    double E[9];
    m3_rotation(w, E);
    m3_mul(E, ph->R0, R);
    for (int k = 0; k < 3; ++k) b[k] = ph->b0[k] + ph->vel[k] * tau;
}

/* Adds the oscillation's displacement (and, with vel non-NULL, its velocity). */
static void add_oscillation(const Collider *c, double t, double b[3], double vel[3])
{
    if (!c->has_osc) return;
    for (int k = 0; k < 3; ++k) {
        double arg = c->osc_omega[k] * t + c->osc_phase[k];
        b[k] += c->osc_amp[k] * sin(arg);
        if (vel) vel[k] += c->osc_amp[k] * c->osc_omega[k] * cos(arg);
    }
}

/* Full pose in phase ph: the phase's rigid pose plus the oscillation. */
static void full_pose(const Collider *c, const ColliderPhase *ph, double t, double R[9], double b[3])
{
    pose_in_phase(ph, t, R, b);
    add_oscillation(c, t, b, NULL);
}

void collider_pose(const Collider *c, double t, double R[9], double b[3])
{
    full_pose(c, &c->phases[find_phase(c, t)], t, R, b);
}

int collider_active(const Collider *c, double t) { return !c->phases[find_phase(c, t)].removed; }

/* Rest-frame point of world point x: X = R^T (x - pivot0 - b) + pivot0. */
static void to_rest(const Collider *c, const double R[9], const double b[3], const double x[3], double X[3])
{
    double d[3] = {x[0] - c->pivot0[0] - b[0], x[1] - c->pivot0[1] - b[1], x[2] - c->pivot0[2] - b[2]};
    for (int k = 0; k < 3; ++k) X[k] = R[k] * d[0] + R[3 + k] * d[1] + R[6 + k] * d[2] + c->pivot0[k];
}

double collider_phi(const Collider *c, double t, const double x[3], double normal[3])
{
    const ColliderPhase *ph = &c->phases[find_phase(c, t)];
    if (ph->removed) {
        if (normal) normal[0] = normal[1] = normal[2] = 0.0;
        return HUGE_VAL;
    }
    double R[9], b[3], X[3];
    full_pose(c, ph, t, R, b);
    to_rest(c, R, b, x, X);
    double phi = level_set_sdf(&c->shape, X);
    if (normal) {
        double g[3], h = c->fd_h;
        for (int k = 0; k < 3; ++k) {
            double Xp[3] = {X[0], X[1], X[2]}, Xm[3] = {X[0], X[1], X[2]};
            Xp[k] += h;
            Xm[k] -= h;
            g[k] = (level_set_sdf(&c->shape, Xp) - level_set_sdf(&c->shape, Xm)) / (2.0 * h);
        }
        double n[3];
        m3_mulv(R, g, n);
        double len = v3_norm(n);
        if (len > 0 && isfinite(len))
            for (int k = 0; k < 3; ++k) normal[k] = n[k] / len;
        else
            normal[0] = normal[1] = normal[2] = 0.0;
    }
    return phi;
}

static void velocity_in_phase(const Collider *c, const ColliderPhase *ph, double t, const double x[3],
                              double v[3])
{
    if (ph->removed) {
        v[0] = v[1] = v[2] = 0.0;
        return;
    }
    double R[9], b[3], osc_v[3] = {0, 0, 0};
    pose_in_phase(ph, t, R, b);
    add_oscillation(c, t, b, osc_v);
    double r[3], wr[3], mv[3];
    for (int k = 0; k < 3; ++k) r[k] = x[k] - (c->pivot0[k] + b[k]);
    v3_cross(ph->omega, r, wr);
    m3_mulv(R, c->material_vel, mv);
    for (int k = 0; k < 3; ++k) v[k] = wr[k] + ph->vel[k] + osc_v[k] + mv[k];
}

void collider_velocity(const Collider *c, double t, const double x[3], double v[3])
{
    velocity_in_phase(c, &c->phases[find_phase(c, t)], t, x, v);
}

double collider_max_speed(const Collider *c, double t, const double lo[3], const double hi[3])
{
    const ColliderPhase *ph = &c->phases[find_phase(c, t)];
    if (ph->removed) return 0.0;
    if (c->cfl_speed >= 0.0) return c->cfl_speed;
    for (int k = 0; k < 3; ++k)
        if (!(lo[k] <= hi[k])) return 0.0; /* an empty box (no particles yet): no material there */
    /* Current world bounds of the collider: the rest bounds' corners posed. */
    double slo[3], shi[3], blo[3], bhi[3];
    level_set_bounds(&c->shape, slo, shi);
    int bounded = level_set_is_bounded(&c->shape);
    double box_lo[3], box_hi[3];
    memcpy(box_lo, lo, sizeof box_lo);
    memcpy(box_hi, hi, sizeof box_hi);
    if (bounded) {
        double R[9], b[3];
        full_pose(c, ph, t, R, b);
        for (int k = 0; k < 3; ++k) blo[k] = HUGE_VAL, bhi[k] = -HUGE_VAL;
        for (int corner = 0; corner < 8; ++corner) {
            double X[3], d[3], w[3];
            for (int k = 0; k < 3; ++k) X[k] = (corner >> k) & 1 ? shi[k] : slo[k];
            for (int k = 0; k < 3; ++k) d[k] = X[k] - c->pivot0[k];
            m3_mulv(R, d, w);
            for (int k = 0; k < 3; ++k) {
                double xw = w[k] + c->pivot0[k] + b[k];
                blo[k] = fmin(blo[k], xw);
                bhi[k] = fmax(bhi[k], xw);
            }
        }
        int overlap = 1;
        double ilo[3], ihi[3];
        for (int k = 0; k < 3; ++k) {
            ilo[k] = fmax(lo[k], blo[k]);
            ihi[k] = fmin(hi[k], bhi[k]);
            if (ilo[k] > ihi[k]) overlap = 0;
        }
        if (overlap) {
            memcpy(box_lo, ilo, sizeof ilo);
            memcpy(box_hi, ihi, sizeof ihi);
        }
    }
    double vmax = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        double x[3], v[3];
        for (int k = 0; k < 3; ++k) x[k] = (corner >> k) & 1 ? box_hi[k] : box_lo[k];
        velocity_in_phase(c, ph, t, x, v);
        double s = v3_norm(v);
        if (s > vmax || isnan(s)) vmax = s; /* NaN propagates: the caller refuses it */
        if (isnan(vmax)) break;
    }
    return vmax;
}

/* The HOT authors' evalMaxSpeed (SPEC 12): besides the corners of the box
 * above, each corner of the collider's own posed bounding box counts when
 * ANY of its coordinates lies within [lo, hi] on that axis (the code tests
 * any where all was meant), so the collider's far corners usually count.
 * Their capped-cylinder level set bounds the cylinder by its circumscribed
 * sphere (shape_reference_bounds); on bar3 this gives the reference's
 * 1.83 m/s and dt 0.0024565 s. */
double collider_max_speed_reference(const Collider *c, double t, const double lo[3], const double hi[3])
{
    const ColliderPhase *ph = &c->phases[find_phase(c, t)];
    if (ph->removed) return 0.0;
    if (c->cfl_speed >= 0.0) return c->cfl_speed;
    double vmax = collider_max_speed(c, t, lo, hi);
    if (!level_set_is_bounded(&c->shape) || isnan(vmax)) return vmax;
    double slo[3], shi[3], R[9], b[3];
    level_set_reference_bounds(&c->shape, slo, shi);
    full_pose(c, ph, t, R, b);
    for (int corner = 0; corner < 8; ++corner) {
        double X[3], d[3], x[3], v[3];
        for (int k = 0; k < 3; ++k) X[k] = (corner >> k) & 1 ? shi[k] : slo[k];
        for (int k = 0; k < 3; ++k) d[k] = X[k] - c->pivot0[k];
        m3_mulv(R, d, x);
        int any = 0;
        for (int k = 0; k < 3; ++k) {
            x[k] += c->pivot0[k] + b[k];
            any |= x[k] >= lo[k] && x[k] <= hi[k];
        }
        if (!any) continue;
        velocity_in_phase(c, ph, t, x, v);
        double sp = v3_norm(v);
        if (sp > vmax || isnan(sp)) vmax = sp; /* NaN propagates: the caller refuses it */
        if (isnan(vmax)) break;
    }
    return vmax;
}

int collider_friction(const double normal[3], const double v_col[3], double mu, double jn, double v[3])
{
    if (!(jn > 0.0) || !(mu > 0.0)) return 0;
    double rel[3] = {v[0] - v_col[0], v[1] - v_col[1], v[2] - v_col[2]};
    double vn = v3_dot(rel, normal);
    double t[3] = {rel[0] - vn * normal[0], rel[1] - vn * normal[1], rel[2] - vn * normal[2]};
    double speed = v3_norm(t), drop = mu * jn;
    double keep = speed > drop ? 1.0 - drop / speed : 0.0;
    for (int d = 0; d < 3; ++d) v[d] = v_col[d] + vn * normal[d] + keep * t[d];
    return keep > 0.0 ? 1 : 2;
}

void collider_free(Collider *c)
{
    if (!c) return;
    level_set_free(&c->shape);
    free(c->phases);
    memset(c, 0, sizeof *c);
}

void collider_init_poses(Collider *c)
{
    m3_identity(c->phases[0].R0);
    memset(c->phases[0].b0, 0, sizeof c->phases[0].b0);
    for (int k = 0; k + 1 < c->n_phases; ++k) {
        ColliderPhase *a = &c->phases[k], *b = &c->phases[k + 1];
        pose_in_phase(a, a->t_end, b->R0, b->b0);
    }
}
