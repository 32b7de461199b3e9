/* How busy the machine is while something is timed: a run (run.json's
 * machine_load, its summary) or a matrix cell (cells.csv's interference
 * columns). A time taken while other processes used the cores it needed is
 * not a valid time. Linux /proc; the readers return -1 where it cannot be
 * read. */
#ifndef MPM_MACHINE_LOAD_H
#define MPM_MACHINE_LOAD_H

/* CPU seconds all processes have used since boot, all cores together: the
 * non-idle fields of /proc/stat's "cpu" line (user, nice, system, irq,
 * softirq and steal, the time a hypervisor gave to another guest). */
double machine_busy_seconds(void);

/* The 1-minute load average (/proc/loadavg). */
double machine_load1(void);

/* Did other processes take CPU the timed work needed? others_cpu_s: their
 * CPU seconds during elapsed_s; threads: the work's threads (<= 0: every
 * core); cores: the machine's. More than the cores the work left free plus
 * a tenth of a core on average is busy: with OpenMP threads even a small
 * share of a core taken by another process can slow the work many times (a
 * descheduled thread holds up its team at every barrier). Unknown values
 * (< 0), and others' time below MACHINE_LOAD_RESOLUTION_S (the counters'
 * rounding over a short window), are not busy. */
#define MACHINE_LOAD_RESOLUTION_S 0.05
int machine_was_busy(double others_cpu_s, double elapsed_s, int threads, int cores);

/* CPU seconds this process has used (all its threads, user and system). */
double process_cpu_seconds(void);

#endif
