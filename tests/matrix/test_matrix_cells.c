/* floor: app */
/* Experiment-matrix internals (experiments/matrix_*.c):
 *  - numbers print as the shortest text that reads back as the same double;
 *  - CSV fields with commas, quotes and newlines survive csv_put + csv_parse,
 *    short rows are padded, columns are found by name;
 *  - a child's wait status maps to ok / bad-input / failed / crashed /
 *    timeout;
 *  - MPI launcher variables are recognised (and nothing else);
 *  - cell ids: the canonical serialisation is pinned (a change renames every
 *    cell of every result directory), the id is its FNV-1a hash, and neither
 *    reordering the axes, adding a value nor restating a default renames a
 *    cell; identical effective settings give one cell; rules select cells;
 *  - cells.csv: a cut-short last row is dropped, a new header remaps the
 *    rows by column name (filling new columns), ids are found, and the
 *    expected time of a cell falls back from (scene, solver, scale) to
 *    (scene, solver) to the solver. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "experiments/io/machine_load.h"
#include "experiments/matrix/matrix_cells.h"
#include "experiments/matrix/matrix_child.h"
#include "experiments/io/csv_table.h"
#include "experiments/matrix/matrix_measure.h"
#include "experiments/matrix/matrix_results.h"
#include "experiments/io/paths.h"
#include "tests/common/testutil.h"

static char g_dir[256];

static int load_text(const char *text, Matrix *m, MatrixCells *c)
{
    static int k = 0;
    char path[320];
    snprintf(path, sizeof path, "%s/m%d.json", g_dir, k++);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    fclose(f);
    mpm_clear_error();
    int st = matrix_load(path, m);
    if (!st) st = matrix_expand(m, c);
    if (st) fprintf(stderr, "  (%s)\n", mpm_last_error());
    return st;
}

static const MatrixCell *find(const MatrixCells *c, const char *scene, const char *solver, double eps)
{
    for (int i = 0; i < c->n; ++i)
        if (!strcmp(c->cells[i].run.scene, scene) && !strcmp(c->cells[i].run.solver, solver) && c->cells[i].run.eps == eps)
            return &c->cells[i];
    return NULL;
}

static uint64_t fnv(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL; /* FNV-1a 64 offset basis and prime */
    while (*s) h = (h ^ (unsigned char)*s++) * 0x100000001b3ULL;
    return h;
}

static void test_numbers(void)
{
    const double v[] = {1e5, 1e-7, 0.1, 1.86, 1.0 / 3.0, 2.5e-300, 123456789.123, 1e11};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i) {
        char t[64];
        matrix_format_number(v[i], t, sizeof t);
        CHECK(strtod(t, NULL) == v[i], "%.17g printed as %s", v[i], t);
    }
    char t[64];
    matrix_format_number(1e5, t, sizeof t);
    CHECK(!strcmp(t, "1e+05"), "1e5 -> %s", t);
    matrix_format_number(1.86, t, sizeof t);
    CHECK(!strcmp(t, "1.86"), "1.86 -> %s", t);
}

static void test_csv(void)
{
    const char *fields[] = {"plain", "a,b", "say \"hi\"", "two\nlines", ""};
    char line[512];
    size_t len = 0;
    line[0] = '\0';
    for (int i = 0; i < 5; ++i) {
        if (i) line[len++] = ',';
        line[len] = '\0';
        CHECK(csv_put(line, sizeof line, &len, fields[i]) == 0, "put %d", i);
    }
    char doc[1200];
    snprintf(doc, sizeof doc, "c0,c1,c2,c3,c4\n%s\nshort,row\n\nlast,x,y,z,w", line);
    CsvTable t;
    CHECK(csv_parse(doc, strlen(doc), &t) == MPM_OK, "parse");
    CHECK(t.n_cols == 5 && t.n_rows == 3, "%d columns, %d rows", t.n_cols, t.n_rows);
    for (int i = 0; i < 5 && t.n_rows > 0; ++i)
        CHECK(!strcmp(csv_get(&t, 0, i), fields[i]), "field %d: '%s'", i, csv_get(&t, 0, i));
    CHECK(!strcmp(csv_get(&t, 1, 1), "row") && !strcmp(csv_get(&t, 1, 4), ""), "short row padded");
    CHECK(!strcmp(csv_get(&t, 2, csv_col(&t, "c4")), "w"), "last line without newline, column by name");
    CHECK(csv_col(&t, "nope") == -1 && !strcmp(csv_get(&t, 0, -1), ""), "missing column");
    csv_free(&t);
    char small[8];
    size_t n0 = 0;
    CHECK(csv_put(small, sizeof small, &n0, "much too long") == -1, "overflow refused");
}

static void test_outcome(void)
{
    int st;
    st = 0 << 8;
    CHECK(cell_outcome(st, 0, 1, 0).status == CELL_OK, "exit 0");
    st = 2 << 8;
    CHECK(cell_outcome(st, 0, 1, 0).status == CELL_BAD_INPUT, "exit 2");
    st = 1 << 8;
    CHECK(cell_outcome(st, 0, 1, 0).status == CELL_FAILED, "exit 1");
    st = 11; /* WTERMSIG 11 */
    CellOutcome o = cell_outcome(st, 0, 1, 0);
    CHECK(WIFSIGNALED(st) && o.status == CELL_CRASHED && o.exit_code == -11, "SIGSEGV: %d %d", o.status, o.exit_code);
    st = 9;
    CHECK(cell_outcome(st, 1, 1, 0).status == CELL_TIMEOUT, "killed by the runner");
    CHECK(!strcmp(cell_status_name(CELL_BAD_INPUT), "bad-input") && !strcmp(cell_status_name(CELL_TIMEOUT), "timeout") &&
              !strcmp(cell_status_name(CELL_TIME_LIMIT), "time-limit"),
          "names");
    /* busy: other processes' CPU over (cores - threads + 0.1) x elapsed */
    CHECK(!machine_was_busy(0.19, 2.0, 2, 2) && machine_was_busy(0.21, 2.0, 2, 2), "2 threads on 2 cores: a tenth of a core is busy");
    CHECK(!machine_was_busy(2.19, 2.0, 1, 2) && machine_was_busy(2.21, 2.0, 1, 2), "1 thread on 2 cores: the free core may be used");
    CHECK(machine_was_busy(0.3, 2.0, 0, 2) && !machine_was_busy(-1.0, 2.0, 2, 2) && !machine_was_busy(5.0, 0.0, 2, 2),
          "threads unknown: no core free; unknown load or no time: not busy");
    CHECK(!machine_was_busy(0.04, 0.01, 2, 2) && machine_was_busy(0.06, 0.01, 2, 2),
          "a short window: others' time under the counters' resolution is not busy");
}

/* cell_measure on a hand-made cell directory: a frame the run's time limit
 * cut short (complete 0, or in files older than that column, status timeout
 * with the run limit as its reason) is not a frame; a frame a failure ended
 * is not one either, but the cell was not cut short by a limit. */
static void test_measure_cut_short(void)
{
    char dir[300], path[400];
    snprintf(dir, sizeof dir, "%s/cut", g_dir);
    mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    FILE *f = fopen(path, "w");
    fprintf(f, "frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,complete,reason\n"
               "0,2,4,8,1.0,1e-8,converged,1,\"\"\n1,2,4,8,3.0,1e-8,converged,1,\"\"\n"
               "2,1,9,90,0.5,1e-3,timeout,0,\"time limit --max-run-seconds 4 reached in PCG\"\n");
    fclose(f);
    CellMeasure m;
    cell_measure(dir, 1, &m);
    CHECK(m.frames == 2 && m.timed_frames == 1 && m.cut_short, "cut frame not counted: %d %d %d", m.frames,
          m.timed_frames, m.cut_short);
    CHECK(m.timed_wall_s == 3.0 && m.max_frame_s == 3.0 && m.wall_s == 4.5, "times: %g %g %g", m.timed_wall_s,
          m.max_frame_s, m.wall_s);
    CHECK(!strcmp(m.worst_solve_status, "timeout") && m.outer_iters == 8, "worst status kept, iterations of frames");
    f = fopen(path, "w"); /* the format before the complete column */
    fprintf(f, "frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,reason\n"
               "0,2,4,8,1.0,1e-8,timeout,\"time limit --max-step-seconds 1 reached\"\n"
               "1,1,9,90,0.5,1e-3,timeout,\"time limit --max-run-seconds 4 reached in PCG\"\n");
    fclose(f);
    cell_measure(dir, 0, &m);
    CHECK(m.frames == 1 && m.timed_wall_s == 1.0 && m.cut_short, "old format: step limit is a frame, run limit is not");
    f = fopen(path, "w"); /* a step failed in frame 1 and the run stopped: not a time limit */
    fprintf(f, "frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,complete,reason\n"
               "0,2,4,8,1.0,1e-8,converged,1,\"\"\n"
               "1,1,3,40,0.5,1e+2,failed,0,\"pcg: r^T M^-1 r = -6.08 (preconditioner not SPD?)\"\n");
    fclose(f);
    cell_measure(dir, 0, &m);
    CHECK(m.frames == 1 && !m.cut_short && !strcmp(m.worst_solve_status, "failed"),
          "a failed frame is not cut short by the time limit: frames %d cut_short %d worst %s", m.frames, m.cut_short,
          m.worst_solve_status);
}

static void test_launcher_env(void)
{
    const char *yes[] = {"OMPI_COMM_WORLD_SIZE=2", "PMIX_RANK=1", "PMI_SIZE=2", "OMPI_MCA_ess=^singleton",
                         "HYDRA_CONTROL_FD=3", "I_MPI_HYDRA_TOPOLIB=x"};
    const char *no[] = {"OMP_NUM_THREADS=2", "OMP_WAIT_POLICY=passive", "PATH=/usr/bin", "HOME=/root", "MPM_SCENE_DIR=x"};
    for (size_t i = 0; i < sizeof yes / sizeof yes[0]; ++i) CHECK(matrix_is_launcher_env(yes[i]), "%s", yes[i]);
    for (size_t i = 0; i < sizeof no / sizeof no[0]; ++i) CHECK(!matrix_is_launcher_env(no[i]), "%s", no[i]);
}

static void test_ids(void)
{
    Matrix a, b, c, d;
    MatrixCells ca, cb, cc, cd;
    CHECK(load_text("{\"name\": \"a\", \"defaults\": {\"frames\": 2, \"scale\": 3},"
                    " \"axes\": {\"scene\": [\"drop\"], \"solver\": [\"hot\", \"pn-pcg\"],"
                    " \"sets\": {\"stiff\": [{\"materials.soft.E\": 1e5}]}}}",
                    &a, &ca) == MPM_OK,
          "matrix a");
    /* axes reordered, a value added to eps and solver, the default eps restated as an axis */
    CHECK(load_text("{\"name\": \"b\", \"axes\": {\"sets\": {\"stiff\": [{\"materials.soft.E\": 1e5}]},"
                    " \"eps\": [1e-8, 1e-7], \"solver\": [\"lbfgs-h\", \"pn-pcg\", \"hot\"], \"scene\": [\"drop\"]},"
                    " \"defaults\": {\"scale\": 3, \"frames\": 2}}",
                    &b, &cb) == MPM_OK,
          "matrix b");
    CHECK(ca.n == 2 && cb.n == 6, "%d and %d cells", ca.n, cb.n);
    for (int i = 0; i < ca.n; ++i) {
        const MatrixCell *x = &ca.cells[i], *y = find(&cb, x->run.scene, x->run.solver, x->run.eps);
        CHECK(y && !strcmp(x->id, y->id) && !strcmp(x->canonical, y->canonical), "%s/%s keeps id %s", x->run.scene,
              x->run.solver, x->id);
    }
    const MatrixCell *hot = find(&ca, "drop", "hot", 1e-7);
    CHECK(hot != NULL, "drop/hot");
    if (hot) {
        const char *want = "{\"armijo\":false,\"eps\":1e-07,\"first_timed_frame\":0,\"frames\":2,"
                           "\"history\":false,\"particles\":false,\"scale\":3,\"scene\":\"drop\","
                           "\"set\":{\"materials.soft.E\":\"1e+05\"},\"solver\":\"hot\",\"solver_opts\":{},"
                           "\"threads\":0}";
        CHECK(!strcmp(hot->canonical, want), "canonical form\n  got  %s\n  want %s", hot->canonical, want);
        char id[16];
        snprintf(id, sizeof id, "%012llx", (unsigned long long)(fnv(hot->canonical) & 0xffffffffffffULL));
        CHECK(!strcmp(id, hot->id), "id %s = FNV-1a of the canonical form (%s)", hot->id, id);
    }
    /* the same effective settings twice (a repeated value, a per-scene setting equal to the default) run once */
    CHECK(load_text("{\"name\": \"c\", \"defaults\": {\"frames\": 2, \"scale\": 3},"
                    " \"axes\": {\"scene\": [\"drop\"], \"solver\": [\"hot\", \"hot\"], \"eps\": [1e-7, 1e-07],"
                    " \"sets\": {\"stiff\": {\"one\": {\"materials.soft.E\": 1e5}, \"same\": {\"materials.soft.E\": 100000}}}},"
                    " \"scenes\": {\"drop\": {\"scale\": 3}}}",
                    &c, &cc) == MPM_OK,
          "matrix c");
    CHECK(cc.n == 2, "duplicates collapse: %d cells (1e5 and 100000 are two texts)", cc.n);
    /* rules: include keeps matching cells, exclude drops them */
    CHECK(load_text("{\"name\": \"d\", \"defaults\": {\"frames\": 1}, \"axes\": {\"scene\": [\"drop\", \"stretched-box\"],"
                    " \"solver\": [\"hot\", \"pn-pcg\", \"lbfgs-h\"], \"eps\": [1e-7, 1e-8]},"
                    " \"include\": [{\"scene\": \"drop\"}, {\"solver\": [\"hot\", \"pn-pcg\"]}],"
                    " \"exclude\": [{\"solver\": \"pn-pcg\", \"eps\": 1e-8}]}",
                    &d, &cd) == MPM_OK,
          "matrix d");
    /* drop: 3 solvers x 2 eps = 6, minus pn-pcg/1e-8 = 5; stretched-box: hot, pn-pcg x 2 eps = 4, minus 1 = 3 */
    CHECK(cd.n == 8, "rules leave %d cells", cd.n);
    CHECK(!find(&cd, "drop", "pn-pcg", 1e-8) && find(&cd, "drop", "lbfgs-h", 1e-8) &&
              !find(&cd, "stretched-box", "lbfgs-h", 1e-7) && find(&cd, "stretched-box", "hot", 1e-8),
          "the right cells");
    Matrix *ms[] = {&a, &b, &c, &d};
    MatrixCells *cs[] = {&ca, &cb, &cc, &cd};
    for (int i = 0; i < 4; ++i) {
        matrix_cells_free(cs[i]);
        matrix_free(ms[i]);
    }
}

static int fill(void *ctx, const char *id, const char *column, char *out, size_t cap)
{
    (void)ctx;
    if (strcmp(column, "stiff")) return 0;
    snprintf(out, cap, "label-of-%s", id);
    return 1;
}

static void test_cells_file(void)
{
    char dir[320], path[400];
    snprintf(dir, sizeof dir, "%s/res", g_dir);
    CHECK(paths_mkdir_p(dir) == MPM_OK, "mkdir");
    snprintf(path, sizeof path, "%s/cells.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f) return;
    fputs("id,scene,solver,scale,elapsed_s\n"
          "a1,bar3,hot,2,10\n"
          "a2,bar3,hot,2,20\n"
          "a3,bar3,hot,3,100\n"
          "a4,drop,pn-pcg,1,7\n"
          "a5,drop,pn-pcg,1,\"8\"\n"
          "a6,drop,hot,1,1", f); /* the last row was cut short by a crash */
    fclose(f);
    CellsFile cf;
    CHECK(cells_file_open(dir, "id,scene,solver,scale,elapsed_s", 0, NULL, NULL, &cf) == MPM_OK, "read-only open");
    CHECK(cells_file_has(&cf, "a5") && !cells_file_has(&cf, "a6"), "a cut row does not count as done (read-only)");
    cells_file_close(&cf);
    CHECK(cells_file_open(dir, "id,scene,solver,stiff,scale,elapsed_s", 1, fill, NULL, &cf) == MPM_OK, "open");
    CHECK(cells_file_has(&cf, "a1") && cells_file_has(&cf, "a5") && !cells_file_has(&cf, "a6") && !cells_file_has(&cf, "b"),
          "ids");
    CHECK(fabs(cells_file_estimate(&cf, "bar3", "hot", "2") - 15.0) < 1e-12, "same scene, solver, scale: mean");
    CHECK(fabs(cells_file_estimate(&cf, "bar3", "hot", "9") - 130.0 / 3) < 1e-12, "same scene and solver");
    CHECK(fabs(cells_file_estimate(&cf, "boxes", "pn-pcg", "1") - 7.5) < 1e-12, "same solver");
    CHECK(cells_file_estimate(&cf, "bar3", "lbfgs-h", "2") == -1.0, "unknown");
    CHECK(cells_file_append(&cf, "b1,bar3,hot,x,2,5") == MPM_OK, "append");
    cells_file_close(&cf);
    CsvTable t;
    CHECK(csv_read(path, &t) == MPM_OK, "reread");
    CHECK(t.n_cols == 6 && t.n_rows == 6, "%d columns, %d rows (cut row gone, one appended)", t.n_cols, t.n_rows);
    CHECK(!strcmp(csv_get(&t, 0, csv_col(&t, "stiff")), "label-of-a1") && !strcmp(csv_get(&t, 4, csv_col(&t, "elapsed_s")), "8"),
          "remapped by name, new column filled");
    CHECK(!strcmp(csv_get(&t, 5, 0), "b1"), "appended row last");
    csv_free(&t);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/test_matrix_cells.XXXXXX");
    if (!mkdtemp(g_dir)) return 1;
    test_numbers();
    test_csv();
    test_outcome();
    test_measure_cut_short();
    test_launcher_env();
    test_ids();
    test_cells_file();
    char cmd[320];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", g_dir);
    return test_summary("test_matrix_cells");
}
