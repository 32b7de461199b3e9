/* Thread-count limits. More threads than MPM_MAX_THREADS only oversubscribe
 * (and a sum uses at most REDUCE_MAX_CHUNKS of them, core/reduce.h), and 0
 * threads is meaningless, so both are input errors, whether they come from
 * a flag or from OMP_NUM_THREADS. */
#ifndef MPM_THREADS_H
#define MPM_THREADS_H

#include "core/reduce.h"

enum { MPM_MAX_THREADS = REDUCE_MAX_CHUNKS };

/* Parses a thread count given by `flag` ("--threads"): an integer in
 * [1, MPM_MAX_THREADS], else MPM_EINPUT with one line naming the flag. */
int threads_parse(const char *flag, const char *text, int *out);

/* Checks OMP_NUM_THREADS when set: a comma-separated list (one count per
 * nesting level) of integers in [1, MPM_MAX_THREADS]. Call once before any
 * parallel work (OpenMP reads it at its first parallel region, and an
 * invalid value is silently replaced by the machine default). */
int threads_check_env(void);

#endif
