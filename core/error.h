/* One error-reporting function for the whole program.
 *
 * Functions return an int status: MPM_OK (0) on success, MPM_EINPUT for bad
 * user input (a scene, a flag, a value), MPM_ENUMERIC for a timestep whose
 * state broke down numerically (NaN or infinite particle state, a particle
 * outside a domain without walls, a non-finite CFL speed: the run loop
 * records the step as failed and goes on by its policy) and MPM_EINTERNAL
 * for everything else. The message goes through mpm_error(), which keeps
 * the first message of the current failure so main() can print it as one
 * line; callers up the stack that know more (the file, the field) prefix it
 * with mpm_error_context() instead of replacing it:
 *
 *     mesh loader:  mpm_error(MPM_EINPUT, "%s:%d: vertex coordinate %s overflows", obj, line, tok)
 *     shape parser: return mpm_error_context(st, "%s: %s", scene_file, "objects.2.shape.file")
 *     message:      "bar3.json: objects.2.shape.file: cat.obj:17: vertex coordinate 1e999 overflows"
 *
 * Thread safety: every thread has its own message (like errno), so two
 * threads that fail independently never see each other's text. A call from
 * inside an OpenMP parallel region by a worker thread goes to one shared,
 * lock-guarded slot instead (first message wins there too), which
 * mpm_last_error() of any thread reads when its own slot is empty: a
 * worker's message is never lost. */
#ifndef MPM_ERROR_H
#define MPM_ERROR_H

enum { MPM_OK = 0, MPM_EINTERNAL = 1, MPM_EINPUT = 2, MPM_ENUMERIC = 3 };

/* Records a printf-style message and returns `status`, so callers write
 * `return mpm_error(MPM_EINPUT, "%s: field 'E' must be > 0, got %g", file, E);`
 * A message already recorded (the first, most precise one) is kept. */
int mpm_error(int status, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Prefixes the recorded message with "<context>: " and returns `status`
 * unchanged, so a caller adds what only it knows (file, then field) on the
 * way up: `if (st) return mpm_error_context(st, "%s: %s", file, path);`.
 * With no message recorded the context becomes the message. Does nothing
 * for status MPM_OK. */
int mpm_error_context(int status, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The recorded message ("" if none) and clearing it (tests and code that
 * recovers from a failure use this). */
const char *mpm_last_error(void);
void mpm_clear_error(void);

#endif
