#include "experiments/io/machine_load.h"

#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>

double machine_busy_seconds(void)
{
    FILE *f = fopen("/proc/stat", "r");
    if (!f) return -1.0;
    unsigned long long user = 0, nice = 0, sys = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
    int n = fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &user, &nice, &sys, &idle, &iowait, &irq, &softirq,
                   &steal);
    fclose(f);
    long tick = sysconf(_SC_CLK_TCK);
    if (n < 4 || tick <= 0) return -1.0;
    /* idle and iowait are the time nothing ran */
    return (double)(user + nice + sys + irq + softirq + steal) / (double)tick;
}

double machine_load1(void)
{
    FILE *f = fopen("/proc/loadavg", "r");
    if (!f) return -1.0;
    double load = -1.0;
    if (fscanf(f, "%lf", &load) != 1) load = -1.0;
    fclose(f);
    return load;
}

int machine_was_busy(double others_cpu_s, double elapsed_s, int threads, int cores)
{
    if (others_cpu_s < 0 || elapsed_s <= 0 || cores <= 0) return 0;
    int spare = threads > 0 && threads < cores ? cores - threads : 0;
    /* /proc/stat counts in clock ticks (10 ms a core): below a few ticks
     * others' time is the counters' rounding, not load */
    return others_cpu_s > elapsed_s * (spare + 0.1) && others_cpu_s > MACHINE_LOAD_RESOLUTION_S;
}

double process_cpu_seconds(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return -1.0;
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
           1e-6 * (double)ru.ru_stime.tv_usec;
}
