/* Quadratic B-spline interpolation kernel (SPEC 1; Stomakhin et al. 2013).
 * Base node floor(x/dx - 0.5) per axis; the 3 nodes base, base+1, base+2
 * carry the weights; gradients include the 1/dx factor. */
#ifndef MPM_KERNEL_H
#define MPM_KERNEL_H

#include <math.h>

/* 1D weights N and derivatives dN (w.r.t. x, 1/dx included) at a particle. */
static inline int bspline2_1d(double x, double inv_dx, double N[3], double dN[3])
{
    double s = x * inv_dx;
    int base = (int)floor(s - 0.5);
    double fx = s - (double)base; /* in [0.5, 1.5) */
    double d0 = 1.5 - fx, d1 = fx - 1.0, d2 = fx - 0.5;
    N[0] = 0.5 * d0 * d0;
    N[1] = 0.75 - d1 * d1;
    N[2] = 0.5 * d2 * d2;
    dN[0] = -d0 * inv_dx;
    dN[1] = -2.0 * d1 * inv_dx;
    dN[2] = d2 * inv_dx;
    return base;
}

/* The MLS-MPM substitute of the 1D gradient factor (Hu et al. 2018
 * supplement section 2, D_p = dx^2/4 I): G[k] = 4/dx^2 (x_k - x) N[k]
 * with x_k = (base + k) dx, i.e. 4/dx (k - fx) N[k], fx = x/dx - base.
 * N as from bspline2_1d at the same x. */
static inline void mls_factor_1d(double x, double inv_dx, int base, const double N[3], double G[3])
{
    double fx = x * inv_dx - (double)base;
    for (int k = 0; k < 3; ++k) G[k] = 4.0 * inv_dx * ((double)k - fx) * N[k];
}

/* Stencil slot k in [0,27) <-> offsets (a,b,c) in {0,1,2}^3, c fastest. */
static inline int stencil_slot(int a, int b, int c) { return 9 * a + 3 * b + c; }

#endif
