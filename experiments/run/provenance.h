/* Provenance: how a number was made, written into every run.json and once
 * per matrix run (DIR/provenance.json). A JSON object with
 *   build: version, git commit and dirty flag of the source tree when the
 *          binary was built (cmake/MpmBuildInfo.cmake), compiler, flags,
 *          build type;
 *   checkout (with_checkout only): the git top folder, commit and dirty
 *          flag of the checkout the program runs in (the working
 *          directory's), which differ from build's when the binary is stale;
 *   host, os, cpu_model, cores_online, physical_cores, omp_max_threads,
 *   threads (the run's), environment (OMP_WAIT_POLICY, OMP_NUM_THREADS,
 *   OMP_PROC_BIND, OMP_PLACES: "" when unset), libraries (hypre, CHOLMOD,
 *   OpenBLAS, MPI, jansson), start_time (UTC, ISO 8601). */
#ifndef MPM_PROVENANCE_H
#define MPM_PROVENANCE_H

#include <jansson.h>
#include <stddef.h>

/* "mpmbench VERSION (git COMMIT[, modified])": the version and the git state
 * of the source tree the binary was built from. */
void provenance_version(char *out, size_t n);

/* A new object (NULL only when out of memory). threads <= 0: not recorded. */
json_t *provenance_json(int threads, int with_checkout);

#endif
