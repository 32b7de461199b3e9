/* The stiffness of one grid cell: the particles whose base node is the same
 * share all 27 stencil nodes, so their Hessian contributions (SPEC 3,
 *   K_st[a][c] = sum_p s_p sum_{b,d} A_p[(a,b),(c,d)] a_ps(b) a_pt(d))
 * are summed in a dense cell buffer before the scatter into block-CSR
 * (core/problem.c). Per particle B_ps = s_p A_p a_ps (3 x 9, for all 27 s
 * at once), then the pair blocks K_st = sum_p B_ps a_pt as one small
 * matrix product over the cell's particles, its accumulators in registers.
 *
 * Layout of K: K[(9 s + ac) HESSIAN_CELL_LD + t] is entry ac = 3a + c of
 * block (s, t). Written for t >= 4 floor(s/4) (the upper triangle in
 * blocks of four columns); the rest is not touched.
 *
 * Two builds of one source: AVX2+FMA where the CPU has them (chosen at run
 * time, so the portable -march=x86-64-v2 binary uses them) and the build's
 * own instructions. They agree to round-off (FMA rounds once). */
#ifndef MPM_HESSIAN_CELL_H
#define MPM_HESSIAN_CELL_H

#define HESSIAN_CELL_LD 28 /* 27 stencil columns padded to a multiple of 4 */
#define HESSIAN_CELL_SIZE (27 * 9 * HESSIAN_CELL_LD)

enum { HESSIAN_CELL_AUTO = 0, HESSIAN_CELL_PORTABLE = 1 };

/* K = sum over the n particles p (consecutive: tangent A + 81 p, a-vectors
 * a + 81 p, HOT's a_ip = F^nT grad w_ip, scale s_p = scale vol[p]).
 * kernel: HESSIAN_CELL_AUTO (fastest the CPU runs) or HESSIAN_CELL_PORTABLE. */
void hessian_cell(int n, const double *A, const double *a, const double *vol, double scale, double *K, int kernel);

/* Instruction set the AUTO kernel uses on this CPU: "avx2+fma" or "portable". */
const char *hessian_cell_isa(void);

#endif
