/* floor: scene */
/* Colliders: phase integration (bar3 top cap: 180 deg at 0.5 s, frozen
 * after 1 s), velocity field omega x r + v, removed phases, max speed,
 * normals, and parse errors. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/scene/collider_load.h"
#include "core/error.h"
#include "core/mat3.h"
#include "tests/common/testutil.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int make(const char *json, Collider *c)
{
    json_error_t e;
    json_t *j = json_loads(json, 0, &e);
    if (!j) {
        fprintf(stderr, "bad test JSON: %s\n", e.text);
        return -1;
    }
    mpm_clear_error();
    int st = collider_parse(j, "t.json", "colliders.0", NULL, 0.01, c);
    if (st) fprintf(stderr, "collider_parse failed: %s\n", mpm_last_error());
    json_decref(j);
    return st;
}

static const char *k_top_cap =
    "{\"name\":\"top_cap\",\"type\":\"sticky\","
    "\"shape\":{\"type\":\"cylinder\",\"center\":[2,3.7,2],\"radius\":0.2,\"height\":0.1,\"axis\":\"y\"},"
    "\"motion\":[{\"until\":1.0,\"angular_velocity_deg\":[0,360,0]},{\"velocity\":[0,0,0]}]}";

static void test_top_cap(void)
{
    Collider c;
    if (make(k_top_cap, &c)) {
        CHECK(0, "top cap parse");
        return;
    }
    CHECK(strcmp(c.name, "top_cap") == 0 && c.kind == COLLIDER_STICKY, "name/kind");
    CHECK(fabs(c.pivot0[0] - 2) < 1e-14 && fabs(c.pivot0[1] - 3.7) < 1e-14, "pivot = bounds centre");
    double R[9], b[3];
    /* 0.5 s at 360 deg/s = 180 deg about +y: diag(-1, 1, -1) */
    collider_pose(&c, 0.5, R, b);
    double want[9] = {-1, 0, 0, 0, 1, 0, 0, 0, -1};
    double err = 0;
    for (int k = 0; k < 9; ++k) err = fmax(err, fabs(R[k] - want[k]));
    CHECK(err < 1e-12, "180 deg at t = 0.5 (err %g)", err);
    CHECK(fabs(b[0]) + fabs(b[1]) + fabs(b[2]) == 0, "no translation");
    /* 0.25 s: 90 deg about +y maps +x to -z */
    collider_pose(&c, 0.25, R, b);
    double ex[3] = {1, 0, 0}, r[3];
    m3_mulv(R, ex, r);
    CHECK(fabs(r[2] + 1) < 1e-12 && fabs(r[0]) < 1e-12, "90 deg about +y: x -> -z");
    /* frozen after 1 s (one full turn = identity) */
    double R1[9], R2[9];
    collider_pose(&c, 1.0, R1, b);
    collider_pose(&c, 1.7, R2, b);
    err = 0;
    for (int k = 0; k < 9; ++k) err = fmax(err, fabs(R1[k] - R2[k]) + fabs(R1[k] - (k % 4 == 0)));
    CHECK(err < 1e-12, "frozen at identity after 1 s (err %g)", err);
    double x[3] = {2.1, 3.7, 2.0}, v[3];
    collider_velocity(&c, 1.5, x, v);
    CHECK(v3_norm(v) == 0, "no velocity after 1 s");
    /* velocity field before 1 s: omega x (x - pivot) */
    collider_velocity(&c, 0.3, x, v);
    double w = 2 * M_PI;
    /* omega = (0, w, 0), r = (0.1, 0, 0): omega x r = (0, 0, -0.1 w) */
    CHECK(fabs(v[0]) < 1e-12 && fabs(v[1]) < 1e-12 && fabs(v[2] + 0.1 * w) < 1e-12, "omega x r: %g %g %g", v[0],
          v[1], v[2]);
    /* phi: rigidly rotating the rest shape; a point fixed to the cap follows it */
    double X[3] = {2.15, 3.7, 2.0}, xw[3], d[3] = {0.15, 0, 0};
    collider_pose(&c, 0.125, R, b);
    m3_mulv(R, d, xw);
    for (int k = 0; k < 3; ++k) xw[k] += c.pivot0[k] + b[k];
    double n[3];
    double phi = collider_phi(&c, 0.125, xw, n);
    double phi0 = collider_phi(&c, 0.0, X, NULL);
    CHECK(fabs(phi - phi0) < 1e-12, "phi moves with the body");
    CHECK(fabs(v3_norm(n) - 1) < 1e-9, "unit normal");
    /* normal on the top face points up */
    double top[3] = {2.05, 3.76, 2.0};
    phi = collider_phi(&c, 0.6, top, n);
    CHECK(fabs(phi - 0.01) < 1e-12 && fabs(n[1] - 1) < 1e-6, "top face normal %g %g %g", n[0], n[1], n[2]);
    /* max speed over the bar's box enlarged by 4 dx (x,z in [1.91, 2.09]) */
    double lo[3] = {1.91, 2.77, 1.91}, hi[3] = {2.09, 3.73, 2.09};
    double vmax = collider_max_speed(&c, 0.5, lo, hi);
    CHECK(fabs(vmax - w * 0.09 * sqrt(2.0)) < 1e-9, "max speed %g", vmax);
    CHECK(collider_max_speed(&c, 1.2, lo, hi) == 0, "stopped");
    CHECK(collider_active(&c, 0.5) && collider_active(&c, 5), "active");
    collider_free(&c);
}

static void test_translate_and_remove(void)
{
    /* Boxes pusher: sphere down at 0.3 m/s until 52/24 s, then removed */
    Collider c;
    if (make("{\"shape\":{\"type\":\"sphere\",\"center\":[2.5,4.2,2],\"radius\":0.1},"
             "\"motion\":[{\"until\":2.1666666666666665,\"velocity\":[0,-0.3,0]},{\"removed\":true}]}",
             &c)) {
        CHECK(0, "pusher parse");
        return;
    }
    double x[3] = {2.5, 4.2 - 0.3, 2}, v[3];
    CHECK(fabs(collider_phi(&c, 1.0, x, NULL) + 0.1) < 1e-12, "centre moved down by 0.3 m");
    collider_velocity(&c, 1.0, x, v);
    CHECK(fabs(v[1] + 0.3) < 1e-15 && v[0] == 0 && v[2] == 0, "translation velocity");
    CHECK(collider_active(&c, 2.0) && !collider_active(&c, 2.2) && !collider_active(&c, 100), "removed");
    double n[3] = {1, 1, 1};
    CHECK(isinf(collider_phi(&c, 2.2, x, n)) && v3_norm(n) == 0, "inactive phi");
    double lo[3] = {2, 3, 1.5}, hi[3] = {3, 4, 2.5};
    CHECK(fabs(collider_max_speed(&c, 1.0, lo, hi) - 0.3) < 1e-15, "translation speed");
    CHECK(collider_max_speed(&c, 3.0, lo, hi) == 0, "removed speed");
    collider_free(&c);

    /* chain end link: translate then rotate about the moving pivot; pose continuous */
    if (make("{\"shape\":{\"type\":\"torus\",\"center\":[1.03,1.3,1.3],\"major_radius\":0.2,\"minor_radius\":0.04,"
             "\"axis\":\"z\"},\"motion\":[{\"until\":2,\"velocity\":[-0.2,0,0]},"
             "{\"until\":8,\"angular_velocity_deg\":[-250,0,0]},{}]}",
             &c)) {
        CHECK(0, "chain link parse");
        return;
    }
    double R[9], b[3];
    collider_pose(&c, 2.0, R, b);
    CHECK(fabs(b[0] + 0.4) < 1e-12, "moved to x = 0.63");
    collider_pose(&c, 8.0, R, b);
    /* -1500 deg = -60 deg mod 360 about x */
    double w[3] = {-1500.0 * M_PI / 180.0, 0, 0}, Rw[9];
    m3_rotation(w, Rw);
    double err = 0;
    for (int k = 0; k < 9; ++k) err = fmax(err, fabs(R[k] - Rw[k]));
    CHECK(err < 1e-12 && fabs(b[0] + 0.4) < 1e-12, "frozen at -1500 deg (err %g)", err);
    /* velocity about the moved pivot (0.63, 1.3, 1.3) */
    double x2[3] = {0.63, 1.5, 1.3};
    collider_velocity(&c, 3.0, x2, v);
    /* omega = (-250 deg/s, 0, 0), r = (0, 0.2, 0): omega x r = (0, 0, -250deg * 0.2) */
    CHECK(fabs(v[2] + 250.0 * M_PI / 180.0 * 0.2) < 1e-12 && fabs(v[1]) < 1e-12, "rotation about moving pivot");
    collider_free(&c);
}

static void test_errors(void)
{
    struct {
        const char *json, *needle;
    } cases[] = {
        {"{\"shape\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},\"type\":\"sticki\"}", "colliders.0.type"},
        {"{\"type\":\"sticky\"}", "colliders.0.shape: missing"},
        {"{\"shape\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},\"motion\":[{\"velocity\":[1,0,0]},"
         "{\"until\":2}]}",
         "colliders.0.motion.0.until"},
        {"{\"shape\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},\"motion\":[{\"until\":2},{\"until\":1}]}",
         "colliders.0.motion.1.until"},
        {"{\"shape\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},\"motion\":[{\"until\":1,\"spin\":3}]}",
         "colliders.0.motion.0.spin"},
        {"{\"shape\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1},\"motion\":[{\"velocity\":[1,0]}]}",
         "colliders.0.motion.0.velocity"},
        {"{\"shape\":{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":0},\"motion\":[]}", "colliders.0.shape.radius"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        json_error_t e;
        json_t *j = json_loads(cases[k].json, 0, &e);
        Collider c;
        mpm_clear_error();
        int st = collider_parse(j, "t.json", "colliders.0", NULL, 0.01, &c);
        CHECK(st == MPM_EINPUT, "case %zu: status %d", k, st);
        CHECK(strstr(mpm_last_error(), cases[k].needle) != NULL, "case %zu: '%s' lacks '%s'", k, mpm_last_error(),
              cases[k].needle);
        json_decref(j);
    }
}

int main(void)
{
    test_top_cap();
    test_translate_and_remove();
    test_errors();
    return test_summary("test_collider");
}
