/* floor: app */
/* libFuzzer harness: the experiment-matrix file loader (experiments/
 * matrix_file.h, issue 12). Each input is a whole matrix file; it must load
 * or fail with one recorded message, never crash, leak or hang. The scenes
 * it names are only looked up, not sampled, so inputs stay fast. */
#include <stdint.h>
#include <stdlib.h>

#include "core/error.h"
#include "experiments/matrix/matrix_file.h"
#include "tests/fuzz/harness.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_setup();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 65536) return 0;
    const char *path = fuzz_write_input(data, size, ".json");
    if (!path) return 0;
    Matrix m;
    mpm_clear_error();
    int st = matrix_load(path, &m);
    fuzz_require_message(st, "matrix_load");
    matrix_free(&m); /* freeable on failure too */
    return 0;
}
