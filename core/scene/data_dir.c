/* The program's data folders (data_dir.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "core/scene/data_dir.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

/* Cuts the last component off path (in place); 0, or -1 when it has none. */
static int cut_last(char *path)
{
    char *slash = strrchr(path, '/');
    if (!slash) return -1;
    *slash = '\0';
    return 0;
}

int data_dir_find(const char *what, const char *env, char *out, size_t cap)
{
    const char *v = env ? getenv(env) : NULL;
    if (v && v[0]) {
        snprintf(out, cap, "%s", v);
        return is_dir(out) ? 0 : -1;
    }
    char exe[4096]; /* the executable, then its folder, then that folder's parent */
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0 || (size_t)n >= sizeof exe - 1) {
        snprintf(out, cap, "share/mpmbench/%s", what); /* no /proc: nothing better to name */
        return -1;
    }
    exe[n] = '\0';
    cut_last(exe);
    snprintf(out, cap, "%s/share/mpmbench/%s", exe, what);
    if (is_dir(out)) return 0;
    cut_last(exe);
    snprintf(out, cap, "%s/share/mpmbench/%s", exe, what);
    return is_dir(out) ? 0 : -1;
}
