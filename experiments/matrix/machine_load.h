/* How busy the machine is, for the interference columns of cells.csv
 * (issue 19: a cell timed while another process used the cores is not a
 * valid time). Linux /proc; both return -1 where it cannot be read. */
#ifndef MPM_MACHINE_LOAD_H
#define MPM_MACHINE_LOAD_H

/* CPU seconds all processes have used since boot, all cores together: the
 * non-idle fields of /proc/stat's "cpu" line (user, nice, system, irq,
 * softirq and steal, the time a hypervisor gave to another guest). */
double machine_busy_seconds(void);

/* The 1-minute load average (/proc/loadavg). */
double machine_load1(void);

#endif
