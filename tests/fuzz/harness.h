/* floor: core */
/* Shared by the libFuzzer harnesses (tests/fuzz/fuzz_*.c): the loaders read
 * files, so each input is written to one scratch file per process, in
 * tmpfs when there is one. */
#ifndef MPM_FUZZ_HARNESS_H
#define MPM_FUZZ_HARNESS_H

#include <stddef.h>
#include <stdint.h>

/* Writes data to a scratch file named after `suffix` (e.g. ".json") and
 * returns its path (static storage), NULL on an I/O error. */
const char *fuzz_write_input(const uint8_t *data, size_t size, const char *suffix);

/* The libFuzzer entry points every harness defines. */
int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The error contract on every input: a failing status comes with a
 * recorded one-line message (else abort(), which the fuzzer reports). */
void fuzz_require_message(int status, const char *what);

/* 1 if the JSON text (a whole scene, or a bare value) sets a valid
 * Poisson-tile seed other than 1, whose tile would take seconds to make. */
int fuzz_new_tile_seed(const uint8_t *json, size_t size);

/* Environment every harness wants: one OpenMP thread (fast, deterministic
 * inputs) and the built-in scene directory. Call from LLVMFuzzerInitialize. */
void fuzz_setup(void);

#endif
