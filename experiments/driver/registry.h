/* The registry: which outer methods, inverse approximations and named
 * presets exist (docs/design.md, floors: the only file that knows every
 * implementation, adapters included). It is data: one line per part, one
 * line per preset.
 *
 * A solver spec (`--solver SPEC`, a matrix cell's solver) is one of
 *   PRESET                         a named preset, e.g. pn-pcg, hot
 *   PRESET:k=v,...                 a preset with options on top
 *   OUTER:INVERSE[:k=v,...]        any composition, e.g. lbfgs:sgs,
 *                                  pn:mg:embedding=quadratic
 * Options apply in order: the preset's, the spec's, then the user's
 * (`--solver-opt`); a later value for the same key wins. */
#ifndef MPM_REGISTRY_H
#define MPM_REGISTRY_H

#include "solvers/solver.h"

/* A preset is data: a name for a composition with options. */
typedef struct {
    const char *name;
    const char *description;
    const char *outer;    /* registered outer method */
    const char *inverse;  /* registered inverse approximation */
    const char *options;  /* "key=value,key=value" (overridable) */
} SolverPreset;

/* The presets of this build: a preset whose inverse approximation is an
 * adapter left out of the build (MPM_WITH_<LIBRARY>=OFF) is absent; naming
 * it is an error that says which option builds it. */
int registry_preset_count(void);
const SolverPreset *registry_preset(int i);
const SolverPreset *registry_find_preset(const char *name); /* NULL when unknown */

int registry_outer_count(void);
const OuterMethodOps *registry_outer(int i);
const OuterMethodOps *registry_find_outer(const char *name);

/* The optional adapters (adapters/adapter_list.h), built or not: adapter i's
 * library as run.json's provenance names it ("hypre") and its version ("not
 * built" when this build left the adapter out). */
int registry_adapter_count(void);
void registry_adapter_library(int i, const char **key, const char **version);

int registry_inverse_count(void);
const InvApproxOps *registry_inverse(int i);
const InvApproxOps *registry_find_inverse(const char *name);

/* A spec resolved to its parts, with every option in effect collected. */
typedef struct {
    char name[96];        /* the preset's name, or the spec as given */
    const SolverPreset *preset; /* NULL for OUTER:INVERSE */
    const OuterMethodOps *outer;
    const InvApproxOps *inverse;
    SolverOptions opts;
} SolverSpec;

/* Resolves SPEC and collects the options (user options `opts` last). Bad
 * syntax, an unknown name or a malformed option: MPM_EINPUT, one line. */
int solver_spec_parse(const char *spec, const char *const *opts, int n_opts, SolverSpec *out);
/* Creates the solver SPEC describes (parse + solver_create). */
int solver_from_spec(const char *spec, const char *const *opts, int n_opts, Solver **out);
/* Validates SPEC with its options completely (names, option keys, values,
 * integer ranges, capability fit) without a step problem, by creating and
 * destroying the solver: MPM_OK, or MPM_EINPUT with one line. For the
 * experiment-matrix runner to check every cell before running any. */
int solver_spec_check(const char *spec, const char *const *opts, int n_opts);

/* Writes the listing of `mpmbench list solvers`: presets (one a line, name
 * first, then a blank line), outer methods, inverse approximations with their
 * capabilities, line searches and stopping rules. */
void registry_print(FILE *f);

/* Writes one line per preset of this build: its name, the hash of its
 * resolved definition (solvers/solver_definition.h) and the definition on
 * one line ("outer=pn inverse=block-jacobi linesearch=halving ..."): what
 * `mpmbench list definitions` prints, and what a study's run.json files are
 * compared with to tell whether the study is current. */
int registry_print_definitions(FILE *f);
/* The same for the given specs, each line named by its spec. */
int registry_print_spec_definitions(FILE *f, const char *const *specs, int n);

/* The communication of a scene split over MPI ranks (core/dist/comm_ops.h)
 * from the adapter that provides it (PETSc's: adapters/petsc_comm.h);
 * MPM_EINPUT naming the option that builds it when this build has none. */
#include "core/dist/comm_ops.h"
int registry_comm_open(CommOps *ops);

#endif
