/* The optional third-party adapters: one line each, the only place their
 * facts are written. CMake reads these lines (cmake/MpmDependencies.cmake:
 * the option that builds an adapter, the package named when its library is
 * missing), the registry reads them through MPM_ADAPTERS below (an absent
 * adapter's presets name the option and package that build it) and so does
 * the provenance (each library's version, "not built" when absent). Adding an
 * adapter: its file adapters/NAME.c defining inv_NAME_ops, one line here,
 * its library's find block in cmake/MpmDependencies.cmake, its presets in
 * experiments/driver/registry.c.
 *
 * X(NAME, CMAKE_OPTION, "Debian package", "library key in run.json", "what") */
#ifndef MPM_ADAPTER_LIST_H
#define MPM_ADAPTER_LIST_H

#define MPM_ADAPTERS(X)                                                                     \
    X(boomeramg, MPM_WITH_HYPRE, "libhypre-dev", "hypre", "hypre BoomerAMG")               \
    X(cholmod, MPM_WITH_CHOLMOD, "libsuitesparse-dev", "cholmod", "CHOLMOD")               \
    X(ml, MPM_WITH_ML, "libtrilinos-ml-dev", "trilinos_ml", "Trilinos ML")                 \
    X(petsc, MPM_WITH_PETSC, "libpetsc-real3.18-dev", "petsc", "PETSc")

#endif
