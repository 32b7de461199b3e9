/* Small dense 3x3 / 3-vector helpers. Matrices are row-major double[9]:
 * M[3*r + c]. Inline because they sit in every particle loop. */
#ifndef MPM_MAT3_H
#define MPM_MAT3_H

#include <math.h>
#include <string.h>

static inline void m3_identity(double M[9])
{
    memset(M, 0, 9 * sizeof(double));
    M[0] = M[4] = M[8] = 1.0;
}

static inline void m3_copy(double D[9], const double S[9]) { memcpy(D, S, 9 * sizeof(double)); }

/* C = A B */
static inline void m3_mul(const double A[9], const double B[9], double C[9])
{
    double T[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            T[3 * r + c] = A[3 * r] * B[c] + A[3 * r + 1] * B[3 + c] + A[3 * r + 2] * B[6 + c];
    memcpy(C, T, sizeof T);
}

/* C = A B^T */
static inline void m3_mul_bt(const double A[9], const double B[9], double C[9])
{
    double T[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            T[3 * r + c] = A[3 * r] * B[3 * c] + A[3 * r + 1] * B[3 * c + 1] + A[3 * r + 2] * B[3 * c + 2];
    memcpy(C, T, sizeof T);
}

/* C = A^T B */
static inline void m3_mul_at(const double A[9], const double B[9], double C[9])
{
    double T[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            T[3 * r + c] = A[r] * B[c] + A[3 + r] * B[3 + c] + A[6 + r] * B[6 + c];
    memcpy(C, T, sizeof T);
}

static inline void m3_transpose(const double A[9], double T[9])
{
    double S[9] = {A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8]};
    memcpy(T, S, sizeof S);
}

static inline double m3_det(const double A[9])
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* Cofactor matrix cof(A) = det(A) A^-T, valid also for singular A. */
static inline void m3_cofactor(const double A[9], double C[9])
{
    C[0] = A[4] * A[8] - A[5] * A[7];
    C[1] = A[5] * A[6] - A[3] * A[8];
    C[2] = A[3] * A[7] - A[4] * A[6];
    C[3] = A[2] * A[7] - A[1] * A[8];
    C[4] = A[0] * A[8] - A[2] * A[6];
    C[5] = A[1] * A[6] - A[0] * A[7];
    C[6] = A[1] * A[5] - A[2] * A[4];
    C[7] = A[2] * A[3] - A[0] * A[5];
    C[8] = A[0] * A[4] - A[1] * A[3];
}

/* Inverse; returns 0 if |det| is not positive (then Ainv is untouched). */
static inline int m3_inverse(const double A[9], double Ainv[9])
{
    double C[9];
    m3_cofactor(A, C);
    double det = A[0] * C[0] + A[1] * C[1] + A[2] * C[2];
    if (!(fabs(det) > 0.0)) return 0;
    double s = 1.0 / det;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) Ainv[3 * r + c] = C[3 * c + r] * s;
    return 1;
}

/* y = A x */
static inline void m3_mulv(const double A[9], const double x[3], double y[3])
{
    double t0 = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
    double t1 = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
    double t2 = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
    y[0] = t0;
    y[1] = t1;
    y[2] = t2;
}

/* y += A x */
static inline void m3_mulv_add(const double A[9], const double x[3], double y[3])
{
    y[0] += A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
    y[1] += A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
    y[2] += A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
}

static inline double m3_frob2(const double A[9])
{
    double s = 0.0;
    for (int k = 0; k < 9; ++k) s += A[k] * A[k];
    return s;
}

static inline double v3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double v3_norm(const double a[3]) { return sqrt(v3_dot(a, a)); }

static inline void v3_cross(const double a[3], const double b[3], double c[3])
{
    double t0 = a[1] * b[2] - a[2] * b[1];
    double t1 = a[2] * b[0] - a[0] * b[2];
    double t2 = a[0] * b[1] - a[1] * b[0];
    c[0] = t0;
    c[1] = t1;
    c[2] = t2;
}

/* Rotation matrix exp([w]) for a rotation vector w (radians), Rodrigues. */
static inline void m3_rotation(const double w[3], double R[9])
{
    double th = v3_norm(w);
    m3_identity(R);
    if (th == 0.0) return;
    double k[3] = {w[0] / th, w[1] / th, w[2] / th};
    double c = cos(th), s = sin(th), t = 1.0 - c;
    R[0] = c + t * k[0] * k[0];
    R[1] = t * k[0] * k[1] - s * k[2];
    R[2] = t * k[0] * k[2] + s * k[1];
    R[3] = t * k[1] * k[0] + s * k[2];
    R[4] = c + t * k[1] * k[1];
    R[5] = t * k[1] * k[2] - s * k[0];
    R[6] = t * k[2] * k[0] - s * k[1];
    R[7] = t * k[2] * k[1] + s * k[0];
    R[8] = c + t * k[2] * k[2];
}

#endif
