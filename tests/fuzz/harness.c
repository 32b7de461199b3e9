/* floor: core */
#include "tests/fuzz/harness.h"

#include "core/error.h"

#include <jansson.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

const char *fuzz_write_input(const uint8_t *data, size_t size, const char *suffix)
{
    static char path[256];
    struct stat st;
    const char *dir = stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) ? "/dev/shm" : "/tmp";
    snprintf(path, sizeof path, "%s/mpm_fuzz_%d%s", dir, (int)getpid(), suffix);
    FILE *f = fopen(path, "wb");
    if (!f) return NULL;
    size_t w = size ? fwrite(data, 1, size, f) : 0;
    if (fclose(f) != 0 || w != size) return NULL;
    return path;
}

void fuzz_setup(void)
{
    omp_set_num_threads(1); /* the built-in scenes are found beside the binary (core/scene/data_dir.h) */
}

void fuzz_require_message(int status, const char *what)
{
    if (status == MPM_OK) return;
    const char *msg = mpm_last_error();
    if (msg[0] && !strchr(msg, '\n')) return;
    fprintf(stderr, "%s: status %d without a one-line message: '%s'\n", what, status, msg);
    abort();
}

int fuzz_new_tile_seed(const uint8_t *json, size_t size)
{
    json_error_t err;
    json_t *v = json_loadb((const char *)json, size, JSON_DECODE_ANY, &err);
    if (!v) return 0;
    json_t *seed = json_is_object(v) ? json_object_get(v, "seed") : v;
    int skip = json_is_integer(seed) && json_integer_value(seed) >= 0 && json_integer_value(seed) != 1;
    json_decref(v);
    return skip;
}
