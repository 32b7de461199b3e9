/* What one finished cell measured: its status (from the child's exit) and
 * the totals of its cell directory (frames.csv, steps.csv, run.json, read by
 * column name). */
#ifndef MPM_MATRIX_MEASURE_H
#define MPM_MATRIX_MEASURE_H

#include <stddef.h>

/* CELL_TIMEOUT: the runner killed it at cell_timeout_s; CELL_TIME_LIMIT: the
 * run stopped itself at its max_run_seconds (exit 0, the frames it finished
 * are measured, a frame it cut short is not counted). */
typedef enum { CELL_OK = 0, CELL_BAD_INPUT, CELL_FAILED, CELL_CRASHED, CELL_TIMEOUT, CELL_TIME_LIMIT, CELL_N_STATUS } CellStatus;
/* "ok", "bad-input", "failed", "crashed", "timeout", "time-limit" */
const char *cell_status_name(CellStatus s);

typedef struct {
    CellStatus status;
    int exit_code;          /* exit status, or minus the signal that ended it */
    double elapsed_s;       /* wall clock of the child, start to reaped */
    long peak_rss_kb;       /* getrusage of the child */
    double cpu_s;           /* user + system CPU seconds of the child (and its children) */
    double others_cpu_s;    /* CPU seconds the rest of the machine used meanwhile (/proc/stat busy
                               time, steal included, minus cpu_s); < 0: unknown */
    double load_start;      /* 1-minute load average when the cell started; < 0: unknown */
    int busy;               /* others_cpu_s took more than the cores the cell left free (machine_was_busy) */
} CellOutcome;

typedef struct {
    int frames, steps, timed_frames;
    long outer_iters, linear_iters;
    long inner_iters;       /* -1: frames.csv has no inner_iters column */
    double wall_s;          /* sum of frames.csv wall_s */
    double timed_wall_s;    /* the same over frames >= first_timed_frame */
    double max_frame_s;     /* the slowest timed frame */
    double max_residual;    /* the largest final residual of any step */
    double converged_fraction; /* steps whose status is "converged" */
    char worst_solve_status[16]; /* of frames.csv ("" without frames) */
    long particles;         /* the most of any step */
    double startup_s;       /* run.json startup_s; -1 when absent */
    int frames_run;         /* run.json frames (the scene's count when none was asked); 0: unknown */
    int threads_run;        /* run.json threads (OpenMP's default when none was asked); 0: unknown */
    int cut_short;          /* the run stopped at its max_run_seconds (a frame cut short, or fewer
                               frames than frames_run with the last one timed out) */
} CellMeasure;

/* Reads what the cell directory holds; missing or partial files (a crash,
 * a timeout) give what was written before. A frame the run cut short at its
 * --max-run-seconds (frames.csv complete = 0; in older files: status
 * timeout with the run limit as its reason) is not a frame: it counts in
 * wall_s only; so is a frame a failed step ended (frames.csv complete = 0,
 * status failed), which does not make the cell cut short. Never fails. */
void cell_measure(const char *dir, int first_timed_frame, CellMeasure *m);

/* The status of a child from its wait status (timed_out: the runner killed it). */
CellOutcome cell_outcome(int wait_status, int timed_out, double elapsed_s, long peak_rss_kb);


/* The measurement columns of cells.csv (names, and one row's values). */
extern const char *const cell_measure_columns;
int cell_measure_format(const CellOutcome *o, const CellMeasure *m, char *out, size_t cap);

#endif
