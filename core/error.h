/* One error-reporting function for the whole program.
 *
 * Functions return an int status: MPM_OK (0) on success, MPM_EINPUT for bad
 * user input (a scene, a flag, a value) and MPM_EINTERNAL for everything
 * else. The message goes through mpm_error(), which keeps the first message
 * of the current failure so main() can print it as one line. */
#ifndef MPM_ERROR_H
#define MPM_ERROR_H

enum { MPM_OK = 0, MPM_EINTERNAL = 1, MPM_EINPUT = 2, MPM_ENUMERIC = 3 };

/* Records a printf-style message and returns `status`, so callers write
 * `return mpm_error(MPM_EINPUT, "%s: field 'E' must be > 0, got %g", file, E);` */
int mpm_error(int status, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The recorded message ("" if none) and clearing it (tests use this). */
const char *mpm_last_error(void);
void mpm_clear_error(void);

#endif
