/* How OpenMP's idle threads wait, chosen before the OpenMP runtime starts.
 *
 * A thread that waits for its team by spinning holds its core; when another
 * process shares the machine the thread the team waits for may be the one
 * descheduled, and a step can take many times longer (issue 31 measured 39x
 * with one other job on 2 cores). libgomp reads its settings once, when the
 * program loads, so the program sets them for itself and starts again. */
#ifndef MPM_OMP_WAIT_H
#define MPM_OMP_WAIT_H

/* The GOMP_SPINCOUNT the program runs with when the user set neither
 * OMP_WAIT_POLICY nor GOMP_SPINCOUNT: about as fast as libgomp's default on
 * an idle machine and about as robust as passive waiting beside another
 * process (results/omp-wait, scripts/omp_wait_study.sh; the README's
 * "Running benchmarks"). */
#define MPM_DEFAULT_SPINCOUNT "1000"

/* When the user left OMP_WAIT_POLICY and GOMP_SPINCOUNT unset (and
 * MPM_KEEP_OMP_WAIT is unset), sets GOMP_SPINCOUNT to the default and
 * re-executes the program with the same arguments; returns only when it
 * does not (set already, under valgrind, whose tool /proc/self/exe would
 * name, or the re-execution failed: the run goes on with OpenMP's own
 * default). */
void omp_wait_default(char **argv);

#endif
