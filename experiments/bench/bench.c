#include "experiments/bench/bench.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/fcr4.h"
#include "core/gradient_cell.h"
#include "core/hessian_cell.h"
#include "core/step.h"
#include "core/transfer.h"
#include "core/scene/scene_load.h"
#include "core/transfer_blocked.h"
#include "experiments/bench/machine_limits.h"

typedef struct {
    Simulation *sim;
    Bsr *H;
    double *x, *y;
    double *vnew;
    double *dv, *grad; /* the line search's point and its gradient */
    ExplicitForce force;
    G2POptions g2p;
} BenchCtx;

static void run_spmv(void *ctx)
{
    BenchCtx *b = ctx;
    bsr_spmv(b->H, b->x, b->y);
}

static void run_hessvec(void *ctx)
{
    BenchCtx *b = ctx;
    problem_hessvec(&b->sim->pb, b->x, b->y);
}

/* What the solvers run: the tangent per particle block, used at once and
 * not kept (problem_assemble_fused). */
static void run_assemble(void *ctx)
{
    BenchCtx *b = ctx;
    problem_assemble_fused(&b->sim->pb, 1, b->H);
}

/* The projected tangent dP/dF of every particle at the cached F (SPEC 3). */
static void run_tangent(void *ctx)
{
    BenchCtx *b = ctx;
    problem_tangent(&b->sim->pb, 1);
}

/* One line-search trial: F(dv), SVD, psi and P per particle (SPEC 3). */
static void run_energy(void *ctx)
{
    BenchCtx *b = ctx;
    problem_energy(&b->sim->pb, b->dv);
}

/* The accepted point's gradient: the scatter of the cached P. */
static void run_gradient(void *ctx)
{
    BenchCtx *b = ctx;
    problem_gradient(&b->sim->pb, b->dv, b->grad);
}

static void run_scatter(void *ctx)
{
    BenchCtx *b = ctx;
    problem_assemble(&b->sim->pb, b->H);
}

/* The supplement's P2G (section 3, "Benchmark settings"): force from F,
 * scatter of mass, force and affine momentum, normalisation and gravity. */
static void run_p2g(void *ctx)
{
    BenchCtx *b = ctx;
    Simulation *s = b->sim;
    if (s->scene->transfer == TRANSFER_MLS) transfer_p2g_mls(&s->grid, &s->st, &s->p, &b->force);
    else transfer_p2g_apic_force(&s->grid, &s->st, &s->p, &b->force);
}

/* The same P2G through block-local arenas (core/transfer_blocked.c). */
static void run_p2g_blocked(void *ctx)
{
    BenchCtx *b = ctx;
    Simulation *s = b->sim;
    transfer_p2g_blocked(&s->grid, &s->st, &s->p, &b->force, s->scene->transfer);
}

/* The supplement's G2P: velocity and affine field, F update, advection. */
static void run_g2p(void *ctx)
{
    BenchCtx *b = ctx;
    Simulation *s = b->sim;
    transfer_g2p_opts(&s->grid, &s->st, &s->p, b->vnew, b->force.dt, &b->g2p);
}

/* Work and traffic models per particle (flops counted from the loops in
 * core/transfer.c and core/problem.c, one per add, multiply or divide;
 * bytes: the particle state each kernel must read and write at least once,
 * plus the grid arrays once per active node, spread over the particles).
 * Particle state: x 24, v 24, C 72, F 72, mass 8, vol 8, material 4 bytes. */
typedef struct {
    const char *name;
    double flops, bytes;
} KernelModel;

static KernelModel model_p2g(int mls, double nodes_per_particle)
{
    /* stress 88 (P 25, P F^T 45, times V and dt 18); per node: r 6, C r 15,
     * APIC: K grad w 15, w m 1, mass 1, momentum 12 -> 50;
     * MLS: Q = m C - c K 27 extra per particle; per node: r 6, Q r 15, mass 2, momentum 9 -> 32;
     * normalisation with gravity 7 per node */
    double per_node_grid = 7.0 * nodes_per_particle;
    KernelModel m = {mls ? "P2G (MLS fused Q_p)" : "P2G (APIC + force)", 0, 0};
    m.flops = mls ? 88.0 + 30.0 + 27.0 * 32.0 + per_node_grid : 88.0 + 27.0 * 50.0 + per_node_grid;
    /* reads x, v, C, F, mass, vol, material (212 B); grid mass and momentum written once and
     * read back and written by the normalisation (3 x 32 B per node) */
    m.bytes = 212.0 + 96.0 * nodes_per_particle;
    return m;
}

static KernelModel model_g2p(int mls, double nodes_per_particle)
{
    /* per node: r 6, v 6, B 18; APIC also grad v 18 -> 30 / 48; per particle: C 9 x 3 (blend),
     * F update 9 (I + dt G) + 45 (product), advection 6; MLS: G = 4/dx^2 B 9 more */
    KernelModel m = {mls ? "G2P (MLS, F from C_p)" : "G2P (APIC, F from grad w)", 0, 0};
    m.flops = mls ? 27.0 * 30.0 + 27.0 + 9.0 + 9.0 + 45.0 + 6.0 : 27.0 * 48.0 + 27.0 + 9.0 + 45.0 + 6.0;
    /* reads x, F (96 B), writes x, v, C, F (192 B); grid velocity read once (24 B per node) */
    m.bytes = 96.0 + 192.0 + 24.0 * nodes_per_particle;
    return m;
}

static KernelModel model_hessvec(double nodes_per_particle)
{
    /* dF = sum_i x_i a_ip^T (27 x 18), A : dF (162), scatter (27 x 18), volume scaling 18;
     * reads the tangent A (648 B), a_ip (648 B) and V; x read and y written per node (48 B) */
    KernelModel m = {"matrix-free H x", 27.0 * 18.0 + 162.0 + 27.0 * 18.0 + 18.0, 648.0 + 648.0 + 8.0 + 48.0 * nodes_per_particle};
    return m;
}

static KernelModel model_assemble(double blocks_per_particle)
{
    /* dP/dF (projected) is not counted (an SVD and eigen-projection per particle);
     * A a_t for 27 t (27 x 162), a_s^T (A a_t) for the 378 pairs s <= t (x 54);
     * reads F and a (720 B; the tangent A stays in cache), writes the matrix
     * blocks (72 B each) once */
    KernelModel m = {"assemble (dP/dF + scatter)", 27.0 * 162.0 + 378.0 * 54.0, 720.0 + 72.0 * blocks_per_particle};
    return m;
}

/* Energy (problem_energy at one dv), counted from core/problem.c, svd3.c, fcr.c:
 *  gather F = F^n + dt sum_i (v_i + dv_i) a_ip^T: 27 x (6 for u_i, 18 for u a^T) = 648;
 *  svd3: scaling 18; a Jacobi pair test 18 flops, a rotation 51 more (sqrt and
 *  divides counted as one flop each); after the sweeps (norms, sort, U, signs) 55;
 *  fixed-corotated psi and P: J 2, R = U V^T 45, cof F 27, P 39, psi 14 = 127;
 *  V_p psi 2; inertia 15 per node. The sweeps depend on F: pair tests and
 *  rotations per particle are measured on bar3's first step (about 11.5 tests,
 *  7.56 rotations, 3.8 sweeps), so the count is for that state.
 * Bytes: a_ip 648, F^n 72, node ids 108, vol, mu, lambda 24, F and P written 144;
 *  v^n, dv 48 per node. */
#define ENERGY_SVD_TESTS 11.5
#define ENERGY_SVD_ROTATIONS 7.56
static KernelModel model_energy(double nodes_per_particle, double tests, double rotations)
{
    KernelModel m = {"energy (F, SVD, psi, P)", 0, 0};
    m.flops = 648.0 + 18.0 + 18.0 * tests + 51.0 * rotations + 55.0 + 127.0 + 2.0 + 15.0 * nodes_per_particle;
    m.bytes = 648.0 + 72.0 + 108.0 + 24.0 + 144.0 + 48.0 * nodes_per_particle;
    return m;
}

/* Tangent (problem_tangent, projected), counted from core/fcr.c: the SVD as
 * in the energy (same sweep counts); J, S_k, lambda (J-1), psihat_k 19;
 * Ahat 24; m and p 18; the basis products M^kk 27 and Ahat M 135; the twist
 * and flip vectors 168; the rank-9 sum over the upper triangle 45 x 18 = 810
 * (the projection's eigen-solve runs only where Ahat is indefinite: not
 * counted). Bytes: F 72, mu, lambda 16, A written 648. */
static KernelModel model_tangent(double tests, double rotations)
{
    KernelModel m = {"tangent (SVD, dP/dF)", 0, 0};
    m.flops = 18.0 + 18.0 * tests + 51.0 * rotations + 55.0 + 19.0 + 24.0 + 18.0 + 27.0 + 135.0 + 168.0 + 810.0;
    m.bytes = 72.0 + 16.0 + 648.0;
    return m;
}

/* Gradient at the cached P, by cells (core/gradient_cell.c): per particle
 * Q = dt V_p P F^nT (54); per node grad w_ip from its tensor factors (4),
 * Q grad w (15) and the cell sum (3) -> 27 x 22; per cell the scatter (3 a
 * node, 81 over the cell's particles); inertia and gravity 9 per node.
 * Bytes: P, F^n 144, the factors of w 144, vol and base 20, node ids 108 a
 * cell; dv and mass read, the gradient written (56 per node). */
static KernelModel model_gradient(double nodes_per_particle, double particles_per_cell)
{
    KernelModel m = {"gradient (scatter of P)", 0, 0};
    m.flops = 54.0 + 27.0 * 22.0 + 81.0 / particles_per_cell + 9.0 * nodes_per_particle;
    m.bytes = 144.0 + 144.0 + 20.0 + 108.0 / particles_per_cell + 56.0 * nodes_per_particle;
    return m;
}

typedef struct {
    double stream_gbs, peak_machine, peak_build;
    size_t np;
    int threads;
} Limits;

static void report(const Limits *L, KernelModel m, double t, double spread, const char *key)
{
    double pps = (double)L->np / t;
    double gbs = m.bytes * pps / 1e9, gfl = m.flops * pps / 1e9;
    printf("%-28s %10.3f ms (+%4.1f%%) %10.3g p/s %7.0f B/p %7.2f GB/s %5.1f%% STREAM %7.0f flop/p %7.2f GF/s "
           "%5.1f%% peak (%5.1f%% build peak)\n",
           m.name, 1e3 * t, 100.0 * spread, pps, m.bytes, gbs, 100.0 * gbs / L->stream_gbs, m.flops, gfl,
           100.0 * gfl / L->peak_machine, 100.0 * gfl / L->peak_build);
    printf("%s_particles_per_s=%.4g\n%s_bytes_per_particle=%.0f\n%s_gbs=%.3f\n%s_stream_fraction=%.4f\n"
           "%s_flops_per_particle=%.0f\n%s_gflops=%.3f\n%s_peak_fraction=%.4f\n%s_build_peak_fraction=%.4f\n"
           "%s_spread=%.4f\n",
           key, pps, key, m.bytes, key, gbs, key, gbs / L->stream_gbs, key, m.flops, key, gfl, key,
           gfl / L->peak_machine, key, gfl / L->peak_build, key, spread);
}

/* What the kernels' measurements share: the timed state, the scene, the
 * machine's limits and the sizes the models scale with. */
typedef struct {
    BenchCtx *ctx;
    const Scene *scene;
    Limits L;
    size_t mat_bytes;   /* the Hessian's storage */
    double npp;         /* active nodes per particle */
    double min_s;       /* seconds of repetitions per timing */
} Bench;

static int bench_spmv(Bench *b, const char *name)
{
    BenchCtx *bc = b->ctx;
    int n = bc->sim->pb.n_nodes;
    double spread = 0, ts, stream_gbs;
    /* minimal traffic: matrix arrays once, x and y once */
    double bytes = (double)b->mat_bytes + 2.0 * 24.0 * n;
    double t = machine_best_time(run_spmv, bc, b->min_s, &spread);
    double spmv_gbs = bytes / t / 1e9;
    printf("%-28s %10.3f ms %11.2f GB/s\n", "block-CSR SpMV", 1e3 * t, spmv_gbs);
    /* STREAM triad over a working set of the same size */
    int status = machine_stream_triad((size_t)(bytes / 24.0), b->min_s, &ts, &stream_gbs);
    if (status) return status;
    printf("%-28s %10.3f ms %11.2f GB/s\n", "STREAM triad (same size)", 1e3 * ts, stream_gbs);
    double tm = machine_best_time(run_hessvec, bc, b->min_s, NULL);
    double mf_gbs_equiv = bytes / tm / 1e9;
    printf("%-28s %10.3f ms %11.2fx SpMV time\n", "matrix-free H x", 1e3 * tm, tm / t);
    (void)name; /* its figures have keys of their own */
    printf("spmv_gbs=%.3f\nstream_gbs=%.3f\nspmv_stream_ratio=%.3f\nstream_dram_gbs=%.3f\n"
           "spmv_stream_dram_ratio=%.3f\nhessvec_over_spmv_time=%.3f\n",
           spmv_gbs, stream_gbs, spmv_gbs / stream_gbs, b->L.stream_gbs, spmv_gbs / b->L.stream_gbs,
           spmv_gbs / mf_gbs_equiv);
    return MPM_OK;
}

static int bench_hessvec(Bench *b, const char *name)
{
    double spread = 0;
    double t = machine_best_time(run_hessvec, b->ctx, b->min_s, &spread);
    report(&b->L, model_hessvec(b->npp), t, spread, name);
    return MPM_OK;
}

static int bench_assemble(Bench *b, const char *name)
{
    BenchCtx *bc = b->ctx;
    size_t np = b->L.np;
    double spread = 0;
    double t = machine_best_time(run_assemble, bc, b->min_s, &spread);
    report(&b->L, model_assemble((double)bc->H->nnzb / (double)np), t, spread, name);
    printf("%s_kernel_isa=%s\n", name, hessian_cell_isa());
    problem_tangent(&bc->sim->pb, 1); /* the scatter alone reads stored tangents */
    double t2 = machine_best_time(run_scatter, bc, b->min_s, NULL);
    printf("%-28s %10.3f ms %10.3g p/s\nscatter_particles_per_s=%.4g\n", "assemble (scatter only)", 1e3 * t2,
           np / t2, np / t2);
    return MPM_OK;
}

static int bench_tangent(Bench *b, const char *name)
{
    double spread = 0;
    double t = machine_best_time(run_tangent, b->ctx, b->min_s, &spread);
    report(&b->L, model_tangent(ENERGY_SVD_TESTS, ENERGY_SVD_ROTATIONS), t, spread, name);
    printf("%s_kernel_isa=%s\n", name, fcr4_isa());
    return MPM_OK;
}

static int bench_energy(Bench *b, const char *name)
{
    BenchCtx *bc = b->ctx;
    int n = bc->sim->pb.n_nodes;
    double spread = 0;
    /* a trial point off the initial guess, as a line search's: dv0 + 1e-3 x */
    for (int i = 0; i < 3 * n; ++i) bc->y[i] = 1e-3 * bc->x[i];
    problem_project(&bc->sim->pb, bc->y);
    for (int i = 0; i < 3 * n; ++i) bc->dv[i] += bc->y[i];
    double t = machine_best_time(run_energy, bc, b->min_s, &spread);
    report(&b->L, model_energy(b->npp, ENERGY_SVD_TESTS, ENERGY_SVD_ROTATIONS), t, spread, name);
    printf("%s_kernel_isa=%s\n", name, fcr4_isa());
    return MPM_OK;
}

static int bench_gradient(Bench *b, const char *name)
{
    BenchCtx *bc = b->ctx;
    size_t np = b->L.np;
    const int *base = bc->sim->st.base;
    double spread = 0;
    problem_energy(&bc->sim->pb, bc->dv); /* the cache at dv */
    double t = machine_best_time(run_gradient, bc, b->min_s, &spread);
    size_t cells = np > 0; /* runs of one base node */
    for (size_t k = 1; k < np; ++k) cells += memcmp(base + 3 * k, base + 3 * (k - 1), 3 * sizeof(int)) != 0;
    report(&b->L, model_gradient(b->npp, cells ? (double)np / (double)cells : 1.0), t, spread, name);
    printf("%s_kernel_isa=%s\n%s_particles_per_cell=%.2f\n", name, gradient_cell_isa(), name,
           cells ? (double)np / (double)cells : 0.0);
    return MPM_OK;
}

static int bench_p2g(Bench *b, const char *name)
{
    int mls = b->scene->transfer == TRANSFER_MLS;
    double spread = 0;
    double t = machine_best_time(run_p2g, b->ctx, b->min_s, &spread);
    report(&b->L, model_p2g(mls, b->npp), t, spread, name);
    KernelModel mb = model_p2g(mls, b->npp);
    mb.name = mls ? "P2G blocked (MLS)" : "P2G blocked (APIC + force)";
    t = machine_best_time(run_p2g_blocked, b->ctx, b->min_s, &spread);
    char key[64];
    snprintf(key, sizeof key, "%s_blocked", name);
    report(&b->L, mb, t, spread, key);
    return MPM_OK;
}

static int bench_g2p(Bench *b, const char *name)
{
    double spread = 0;
    double t = machine_best_time(run_g2p, b->ctx, b->min_s, &spread);
    report(&b->L, model_g2p(b->scene->transfer == TRANSFER_MLS, b->npp), t, spread, name);
    return MPM_OK;
}

#define KERNEL_NAME(kernel) #kernel,
#define KERNEL_RUN(kernel) bench_##kernel,
const char *const bench_operands[] = {BENCH_KERNELS(KERNEL_NAME) "all", NULL};
static int (*const kernel_run[])(Bench *b, const char *name) = {BENCH_KERNELS(KERNEL_RUN)};
enum { N_KERNELS = sizeof kernel_run / sizeof kernel_run[0] };

int bench_run(const char *what, const RunConfig *cfg)
{
    const char *solver_opts[RUN_MAX_LIST + 1];
    SessionConfig sc;
    run_session_config(cfg, &sc, solver_opts);
    sc.solver = NULL; /* the kernels, not a solver */
    Session ses;
    int status = session_open(&sc, &ses);
    if (status) return status;
    const int threads = ses.threads;
    const Scene *scene = &ses.scene;
    Simulation *sim = &ses.sim;
    Bsr H = {0};
    BenchCtx bc = {0};
    if ((status = step_begin(sim))) goto done;
    StepProblem *pb = &sim->pb;
    int n = pb->n_nodes;
    size_t np = sim->p.n;
    double *dv = bc.dv = malloc(sizeof(double) * 3 * (size_t)n);
    bc.grad = malloc(sizeof(double) * 3 * (size_t)n);
    bc.x = malloc(sizeof(double) * 3 * (size_t)n);
    bc.y = malloc(sizeof(double) * 3 * (size_t)n);
    bc.vnew = malloc(sizeof(double) * 3 * (size_t)n);
    if (!dv || !bc.grad || !bc.x || !bc.y || !bc.vnew) {
        status = mpm_error(MPM_EINTERNAL, "out of memory in bench");
        goto done;
    }
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    problem_tangent(pb, 1);
    if ((status = problem_assemble(pb, &H))) goto done;
    for (int i = 0; i < 3 * n; ++i) bc.x[i] = 1.0 + 1e-3 * (i % 17);
    for (int i = 0; i < 3 * n; ++i) bc.vnew[i] = sim->grid.v[i] + 1e-3 * ((i % 7) - 3);
    bc.sim = sim;
    bc.H = &H;
    bc.force.dt = sim->dt;
    bc.force.mats = scene->materials;
    memcpy(bc.force.gravity, scene->gravity, sizeof bc.force.gravity);
    bc.g2p = (G2POptions){.kind = scene->transfer, .apic_ratio = scene->apic_ratio, .flip_alpha = scene->flip_alpha,
                          .advect = 1};
    int all = !strcmp(what, "all");
    double min_s = 1.0;
    const char *tname = transfer_kind_name(scene->transfer);

    printf("bench on %s (transfer %s): %zu particles, %d active nodes, %lld blocks (%.1f per row), %d thread%s\n",
           scene->name, tname, np, n, (long long)H.nnzb, (double)H.nnzb / n, threads, threads == 1 ? "" : "s");
    size_t mat_bytes = bsr_bytes(&H);
    printf("  Hessian storage: %.1f MB, %.0f bytes per active node\n", mat_bytes / 1e6, (double)mat_bytes / n);

    /* machine limits in this process: DRAM triad (3 x 128 MB) and the FMA peak */
    Limits L = {.np = np, .threads = threads};
    double ts;
    if ((status = machine_stream_triad((size_t)16 << 20, min_s, &ts, &L.stream_gbs))) goto done;
    FlopPeak peak;
    machine_flop_peak(min_s, &peak);
    L.peak_machine = peak.gflops_machine;
    L.peak_build = peak.gflops_build;
    printf("%-28s %10.3f ms %11.2f GB/s\n", "STREAM triad (384 MB)", 1e3 * ts, L.stream_gbs);
    printf("%-28s %11.2f GFLOP/s (%s); %.2f GFLOP/s with the build's instructions\n", "floating-point peak",
           peak.gflops_machine, peak.isa, peak.gflops_build);
    Bench b = {.ctx = &bc, .scene = scene, .L = L, .mat_bytes = mat_bytes, .npp = (double)n / (double)np,
               .min_s = min_s};
    for (int k = 0; k < N_KERNELS; ++k)
        if ((all || !strcmp(what, bench_operands[k])) && (status = kernel_run[k](&b, bench_operands[k]))) goto done;
    printf("particles=%zu\nactive_nodes=%d\nhessian_blocks=%lld\nhessian_bytes_per_node=%.1f\n", np, n,
           (long long)H.nnzb, (double)mat_bytes / n);
    printf("transfer=%s\nstream_dram_gbs=%.3f\npeak_gflops=%.3f\npeak_isa=%s\nbuild_peak_gflops=%.3f\nthreads=%d\n",
           tname, L.stream_gbs, L.peak_machine, peak.isa, L.peak_build, threads);
done:
    free(bc.dv);
    free(bc.grad);
    free(bc.x);
    free(bc.y);
    free(bc.vnew);
    bsr_free(&H);
    session_close(&ses);
    return status;
}
