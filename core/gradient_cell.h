/* The elastic part of the energy's gradient (SPEC 3), one grid cell at a
 * time: the particles whose base node is the same share their 27 stencil
 * nodes, so their forces
 *   f_s = sum_p s_p P_p a_ps = sum_p (s_p P_p F_p^nT) grad w_ps
 * are summed in a small dense buffer before one scatter per cell
 * (core/problem.c). grad w_ps comes from its tensor factors (core/grid.h
 * f1d), 144 bytes a particle instead of a_ps's 648, and Q_p = s_p P_p F_p^nT
 * is formed once per particle.
 *
 * Layout of f: f[(3 (3a + b) + r) 4 + c] is component r at stencil slot
 * s = 9a + 3b + c (c < 3; entry 3 of each four is padding).
 *
 * Two builds of one source, like core/hessian_cell.c: AVX2+FMA where the
 * CPU has them (chosen at run time) and the build's own instructions. They
 * agree to round-off (FMA rounds once). */
#ifndef MPM_GRADIENT_CELL_H
#define MPM_GRADIENT_CELL_H

#define GRADIENT_CELL_SIZE 108 /* 9 (a, b) x 3 components x 4 */

enum { GRADIENT_CELL_AUTO = 0, GRADIENT_CELL_PORTABLE = 1 };

/* f = sum over the n consecutive particles p (P + 9p, F^n Fn + 9p, factors
 * f1d + 18p, s_p = scale vol[p]). kernel: GRADIENT_CELL_AUTO or _PORTABLE. */
void gradient_cell(int n, const double *P, const double *Fn, const double *f1d, const double *vol, double scale,
                   double *f, int kernel);

/* Instruction set the AUTO kernel uses on this CPU: "avx2+fma" or "portable". */
const char *gradient_cell_isa(void);

#endif
