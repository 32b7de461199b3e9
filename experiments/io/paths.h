/* Output paths given on the command line, checked before any work (a bad
 * one used to surface only after the scene was sampled, or after a frame
 * was simulated). */
#ifndef MPM_PATHS_H
#define MPM_PATHS_H

/* An output directory given by `flag` (NULL path: not given, fine): not
 * empty, not too long, and either an existing writable directory or
 * creatable (its deepest existing ancestor is a writable directory and no
 * ancestor is a file). MPM_EINPUT with one line naming the flag otherwise. */
int paths_check_output_dir(const char *flag, const char *path);

/* mkdir -p: creates path and its missing ancestors (mode 0755); MPM_EINPUT
 * naming the component that could not be made. */
int paths_mkdir_p(const char *path);

#endif
