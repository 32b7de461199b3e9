#include "experiments/io/paths.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"

/* Room left for the file names written inside (steps.csv, frame_0001.ply). */
enum { PATH_CAP = 1024 - 64 };

int paths_check_output_dir(const char *flag, const char *path)
{
    if (!path) return MPM_OK;
    if (!path[0]) return mpm_error(MPM_EINPUT, "%s '': expected a directory name", flag);
    size_t len = strlen(path);
    if (len >= PATH_CAP) return mpm_error(MPM_EINPUT, "%s '%.60s...': path longer than %d characters", flag, path, PATH_CAP - 1);
    char buf[PATH_CAP];
    memcpy(buf, path, len + 1);
    /* the path itself, then each ancestor until one exists */
    for (;;) {
        struct stat st;
        if (stat(buf, &st) == 0) {
            int self = strcmp(buf, path) == 0;
            if (!S_ISDIR(st.st_mode))
                return self ? mpm_error(MPM_EINPUT, "%s '%s': exists and is not a directory", flag, path)
                            : mpm_error(MPM_EINPUT, "%s '%s': '%s' is not a directory", flag, path, buf);
            if (access(buf, W_OK | X_OK) != 0)
                return self ? mpm_error(MPM_EINPUT, "%s '%s': directory is not writable", flag, path)
                            : mpm_error(MPM_EINPUT, "%s '%s': cannot create it in '%s' (not writable)", flag, path,
                                        buf);
            return MPM_OK;
        }
        if (errno != ENOENT && errno != ENOTDIR) return mpm_error(MPM_EINPUT, "%s '%s': %s", flag, path, strerror(errno));
        /* strip the last component (and trailing slashes) */
        size_t n = strlen(buf);
        while (n > 1 && buf[n - 1] == '/') buf[--n] = '\0';
        char *slash = strrchr(buf, '/');
        if (!slash) { /* a relative name: its parent is the working directory */
            buf[0] = '.';
            buf[1] = '\0';
        } else if (slash == buf) {
            buf[1] = '\0';
        } else {
            *slash = '\0';
        }
    }
}

int paths_mkdir_p(const char *path)
{
    char buf[1200];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) return mpm_error(MPM_EINPUT, "%s: path too long", path);
    for (char *s = buf + 1; *s; ++s) {
        if (*s != '/') continue;
        *s = '\0';
        if (mkdir(buf, 0755) != 0 && errno != EEXIST) return mpm_error(MPM_EINPUT, "%s: cannot create directory", buf);
        *s = '/';
    }
    if (mkdir(buf, 0755) != 0 && errno != EEXIST) return mpm_error(MPM_EINPUT, "%s: cannot create directory", buf);
    return MPM_OK;
}
