/* floor: core */
/* Replays libFuzzer inputs through a harness without libFuzzer: every file
 * given (or found in a directory given) is passed to LLVMFuzzerTestOneInput
 * once, in name order. CTest runs it over each target's seed corpus and its
 * committed regression inputs (tests/fuzz/regressions/TARGET), so inputs
 * the fuzzer once crashed on stay fixed in the normal build. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "tests/fuzz/harness.h"

static int run_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "replay: cannot open %s\n", path);
        return 1;
    }
    size_t cap = 1 << 16, n = 0;
    uint8_t *buf = malloc(cap);
    for (size_t r; buf && (r = fread(buf + n, 1, cap - n, f)) > 0;) {
        n += r;
        if (n == cap) {
            uint8_t *q = realloc(buf, cap *= 2);
            if (!q) break;
            buf = q;
        }
    }
    fclose(f);
    if (!buf) return 1;
    LLVMFuzzerTestOneInput(buf, n);
    free(buf);
    return 0;
}

static int cmp_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

int main(int argc, char **argv)
{
    LLVMFuzzerInitialize(&argc, &argv);
    int inputs = 0, bad = 0;
    for (int a = 1; a < argc; ++a) {
        struct stat st;
        if (stat(argv[a], &st) != 0) continue; /* a target without regressions yet */
        if (!S_ISDIR(st.st_mode)) {
            bad |= run_file(argv[a]);
            ++inputs;
            continue;
        }
        DIR *d = opendir(argv[a]);
        if (!d) continue;
        char **names = NULL;
        size_t n = 0;
        for (struct dirent *e; (e = readdir(d));) {
            if (e->d_name[0] == '.') continue;
            char **q = realloc(names, sizeof *names * (n + 1));
            if (!q) break;
            names = q;
            size_t len = strlen(argv[a]) + strlen(e->d_name) + 2;
            names[n] = malloc(len);
            if (!names[n]) break;
            snprintf(names[n++], len, "%s/%s", argv[a], e->d_name);
        }
        closedir(d);
        if (n > 1) qsort(names, n, sizeof *names, cmp_names);
        for (size_t k = 0; k < n; ++k) {
            bad |= run_file(names[k]);
            ++inputs;
            free(names[k]);
        }
        free(names);
    }
    printf("replayed %d inputs\n", inputs);
    return bad || inputs == 0; /* no inputs at all means a wrong path */
}
