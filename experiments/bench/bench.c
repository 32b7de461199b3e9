#include "experiments/bench/bench.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/step.h"
#include "core/transfer.h"

/* Repeats fn until at least min_s seconds have passed (and at least 3
 * times); returns the best single time (STREAM convention). */
typedef void (*BenchFn)(void *ctx);
static double best_time(BenchFn fn, void *ctx, double min_s)
{
    double best = 1e300, start = omp_get_wtime();
    int reps = 0;
    while (reps < 3 || omp_get_wtime() - start < min_s) {
        double t0 = omp_get_wtime();
        fn(ctx);
        double t = omp_get_wtime() - t0;
        if (t < best) best = t;
        if (++reps > 100000) break;
    }
    return best;
}

typedef struct {
    Simulation *sim;
    Bsr *H;
    double *x, *y;
    double *a, *b, *c;
    size_t len;
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

static void run_triad(void *ctx)
{
    BenchCtx *b = ctx;
    double *restrict a = b->a;
    const double *restrict bb = b->b, *restrict cc = b->c;
    const double s = 3.0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < b->len; ++i) a[i] = bb[i] + s * cc[i];
}

/* Best time and bandwidth (24 bytes per entry) of the triad over len doubles
 * per array; the arrays live only for the measurement. */
static int triad(BenchCtx *bc, size_t len, double min_s, double *t, double *gbs)
{
    bc->len = len;
    bc->a = malloc(sizeof(double) * len);
    bc->b = malloc(sizeof(double) * len);
    bc->c = malloc(sizeof(double) * len);
    int status = MPM_OK;
    if (!bc->a || !bc->b || !bc->c) {
        status = mpm_error(MPM_EINTERNAL, "out of memory in bench (triad of %zu doubles)", len);
    } else {
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < len; ++i) {
            bc->a[i] = 0.0;
            bc->b[i] = 1.0;
            bc->c[i] = 2.0;
        }
        *t = best_time(run_triad, bc, min_s);
        *gbs = 24.0 * len / *t / 1e9;
    }
    free(bc->a), free(bc->b), free(bc->c);
    bc->a = bc->b = bc->c = NULL;
    return status;
}

static void run_assemble(void *ctx)
{
    BenchCtx *b = ctx;
    problem_tangent(&b->sim->pb, 1);
    problem_assemble(&b->sim->pb, b->H);
}

static void run_scatter(void *ctx)
{
    BenchCtx *b = ctx;
    problem_assemble(&b->sim->pb, b->H);
}

static void run_p2g(void *ctx)
{
    BenchCtx *b = ctx;
    transfer_p2g(&b->sim->grid, &b->sim->st, &b->sim->p);
}

int bench_run(const char *what, const RunConfig *cfg)
{
    int status;
    if (cfg->threads > 0) omp_set_num_threads(cfg->threads);
    int threads = omp_get_max_threads();
    Scene scene;
    if ((status = run_scene_load(cfg, &scene))) return status;
    Simulation sim;
    Bsr H = {0};
    BenchCtx bc = {0};
    if ((status = sim_init(&sim, &scene))) goto done;
    if ((status = step_begin(&sim))) goto done;
    StepProblem *pb = &sim.pb;
    int n = pb->n_nodes;
    size_t np = sim.p.n;
    double *dv = malloc(sizeof(double) * 3 * (size_t)n);
    bc.x = malloc(sizeof(double) * 3 * (size_t)n);
    bc.y = malloc(sizeof(double) * 3 * (size_t)n);
    if (!dv || !bc.x || !bc.y) {
        free(dv);
        status = mpm_error(MPM_EINTERNAL, "out of memory in bench");
        goto done;
    }
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    free(dv);
    problem_tangent(pb, 1);
    if ((status = problem_assemble(pb, &H))) goto done;
    for (int i = 0; i < 3 * n; ++i) bc.x[i] = 1.0 + 1e-3 * (i % 17);
    bc.sim = &sim;
    bc.H = &H;
    int all = !strcmp(what, "all");
    double min_s = 1.0;

    printf("bench on %s: %zu particles, %d active nodes, %lld blocks (%.1f per row), %d threads\n", scene.name, np, n,
           (long long)H.nnzb, (double)H.nnzb / n, threads);
    size_t mat_bytes = bsr_bytes(&H);
    printf("  Hessian storage: %.1f MB, %.0f bytes per active node\n", mat_bytes / 1e6, (double)mat_bytes / n);
    printf("%-28s %14s %14s\n", "kernel", "time [ms]", "throughput");
    double spmv_gbs = 0, stream_gbs = 0, stream_dram_gbs = 0, asm_pps = 0, scatter_pps = 0, p2g_pps = 0, mf_gbs_equiv = 0;
    if (all || !strcmp(what, "spmv")) {
        /* minimal traffic: matrix arrays once, x and y once */
        double bytes = (double)mat_bytes + 2.0 * 24.0 * n;
        double t = best_time(run_spmv, &bc, min_s);
        spmv_gbs = bytes / t / 1e9;
        printf("%-28s %14.3f %11.2f GB/s\n", "block-CSR SpMV", 1e3 * t, spmv_gbs);
        /* STREAM triad over a working set of the same size, then one far
         * beyond any cache (3 x 128 MB): the DRAM bandwidth */
        double ts;
        if ((status = triad(&bc, (size_t)(bytes / 24.0), min_s, &ts, &stream_gbs))) goto done;
        printf("%-28s %14.3f %11.2f GB/s\n", "STREAM triad (same size)", 1e3 * ts, stream_gbs);
        if ((status = triad(&bc, (size_t)16 << 20, min_s, &ts, &stream_dram_gbs))) goto done;
        printf("%-28s %14.3f %11.2f GB/s\n", "STREAM triad (384 MB)", 1e3 * ts, stream_dram_gbs);
        double tm = best_time(run_hessvec, &bc, min_s);
        mf_gbs_equiv = bytes / tm / 1e9;
        printf("%-28s %14.3f %11.2fx SpMV time\n", "matrix-free H x", 1e3 * tm, tm / t);
    }
    if (all || !strcmp(what, "assemble")) {
        double t = best_time(run_assemble, &bc, min_s);
        asm_pps = np / t;
        printf("%-28s %14.3f %11.3g p/s\n", "assemble (dP/dF + scatter)", 1e3 * t, asm_pps);
        double t2 = best_time(run_scatter, &bc, min_s);
        scatter_pps = np / t2;
        printf("%-28s %14.3f %11.3g p/s\n", "assemble (scatter only)", 1e3 * t2, scatter_pps);
    }
    if (all || !strcmp(what, "p2g")) {
        double t = best_time(run_p2g, &bc, min_s);
        p2g_pps = np / t;
        printf("%-28s %14.3f %11.3g p/s\n", "P2G (APIC)", 1e3 * t, p2g_pps);
    }
    printf("particles=%zu\nactive_nodes=%d\nhessian_blocks=%lld\nhessian_bytes_per_node=%.1f\n", np, n,
           (long long)H.nnzb, (double)mat_bytes / n);
    if (spmv_gbs > 0) {
        printf("spmv_gbs=%.3f\nstream_gbs=%.3f\nspmv_stream_ratio=%.3f\nstream_dram_gbs=%.3f\n"
               "spmv_stream_dram_ratio=%.3f\nhessvec_over_spmv_time=%.3f\n",
               spmv_gbs, stream_gbs, spmv_gbs / stream_gbs, stream_dram_gbs, spmv_gbs / stream_dram_gbs,
               spmv_gbs / mf_gbs_equiv);
    }
    if (asm_pps > 0) printf("assemble_particles_per_s=%.4g\nscatter_particles_per_s=%.4g\n", asm_pps, scatter_pps);
    if (p2g_pps > 0) printf("p2g_particles_per_s=%.4g\n", p2g_pps);
    printf("threads=%d\n", threads);
done:
    free(bc.x);
    free(bc.y);
    bsr_free(&H);
    sim_free(&sim);
    scene_free(&scene);
    return status;
}
