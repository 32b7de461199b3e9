#include "experiments/matrix/machine_load.h"

#include <stdio.h>
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
