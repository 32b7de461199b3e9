#include "core/threads.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* One count: decimal digits (surrounding blanks allowed), value in range. */
static int parse_count(const char *s, const char *end, long *out)
{
    while (s < end && (*s == ' ' || *s == '\t')) ++s;
    while (end > s && (end[-1] == ' ' || end[-1] == '\t')) --end;
    if (s == end || end - s > 9) return 0;
    long v = 0;
    for (; s < end; ++s) {
        if (*s < '0' || *s > '9') return 0;
        v = 10 * v + (*s - '0');
    }
    *out = v;
    return v >= 1 && v <= MPM_MAX_THREADS;
}

int threads_parse(const char *flag, const char *text, int *out)
{
    long v = 0;
    if (!text || !parse_count(text, text + strlen(text), &v))
        return mpm_error(MPM_EINPUT, "%s '%s': expected an integer number of threads in [1, %d]", flag,
                         text ? text : "", MPM_MAX_THREADS);
    *out = (int)v;
    return MPM_OK;
}

int threads_check_env(void)
{
    const char *env = getenv("OMP_NUM_THREADS");
    if (!env) return MPM_OK;
    const char *s = env;
    for (;;) {
        const char *comma = strchr(s, ',');
        const char *end = comma ? comma : s + strlen(s);
        long v = 0;
        if (!parse_count(s, end, &v))
            return mpm_error(MPM_EINPUT,
                             "OMP_NUM_THREADS='%s': expected a number of threads in [1, %d] (or a comma-separated "
                             "list of them)",
                             env, MPM_MAX_THREADS);
        if (!comma) break;
        s = comma + 1;
    }
    return MPM_OK;
}
