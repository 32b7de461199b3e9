/* The program's data folders: the built-in scenes, the experiment matrices
 * and the report scripts, found at run time relative to the running
 * executable, so a binary holds no path of the tree it was built from and
 * works installed anywhere (CMakeLists.txt, install()).
 *
 * data_dir_find("scenes", "MPM_SCENE_DIR", ...) tries, in order:
 *   1. the environment variable (when set and not empty), as given;
 *   2. EXE_DIR/share/mpmbench/scenes: a build tree, where CMake links
 *      share/mpmbench/{scenes,matrices,scripts} to the source tree's folders
 *      (so an edited scene is used at once);
 *   3. EXE_DIR/../share/mpmbench/scenes: an installed copy (bin/mpmbench
 *      beside share/mpmbench/; also the tests in BUILD/tests/).
 * EXE_DIR is the folder of /proc/self/exe (links resolved). The build tree's
 * layout is tried before the installed one because it cannot match by
 * accident: no installed program has a share/ folder beside itself, while a
 * build folder may sit next to an install prefix's share/. */
#ifndef MPM_DATA_DIR_H
#define MPM_DATA_DIR_H

#include <stddef.h>

/* Writes the first of the folders above that exists to out (cap bytes) and
 * returns 0; when none exists, writes the one the error message should name
 * (the variable's value, else the installed layout's folder) and returns
 * -1. `what` is the folder's name under share/mpmbench, `env` the variable
 * that replaces it. */
int data_dir_find(const char *what, const char *env, char *out, size_t cap);

#endif
