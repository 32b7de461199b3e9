# Finds every third-party dependency and says which Debian package provides a
# missing one. All of them end up behind the MPM::deps interface target.

function(mpm_require found what package)
  if(NOT ${found})
    message(FATAL_ERROR "mpmbench needs ${what}: install the Debian package '${package}' "
                        "(sudo apt-get install ${package}) or run scripts/setup.sh")
  endif()
endfunction()

find_package(OpenMP COMPONENTS C)
mpm_require(OpenMP_C_FOUND "OpenMP for C" "libgomp1 (comes with gcc)")

find_package(MPI COMPONENTS C)
mpm_require(MPI_C_FOUND "MPI" "libopenmpi-dev")

find_package(GSL)
mpm_require(GSL_FOUND "GSL" "libgsl-dev")

find_path(JANSSON_INCLUDE_DIR jansson.h)
find_library(JANSSON_LIBRARY jansson)
mpm_require(JANSSON_LIBRARY "jansson (JSON)" "libjansson-dev")
mpm_require(JANSSON_INCLUDE_DIR "jansson headers" "libjansson-dev")

find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
mpm_require(CHOLMOD_INCLUDE_DIR "CHOLMOD headers" "libsuitesparse-dev")
mpm_require(CHOLMOD_LIBRARY "CHOLMOD" "libsuitesparse-dev")

find_path(HYPRE_INCLUDE_DIR HYPRE.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY NAMES HYPRE)
mpm_require(HYPRE_INCLUDE_DIR "hypre headers" "libhypre-dev")
mpm_require(HYPRE_LIBRARY "hypre" "libhypre-dev")

# Trilinos ML (adapters/ml.c: the ml inverse approximation, presets pn-ml-pcg
# and lbfgs-ml): optional, on when found.
find_path(ML_INCLUDE_DIR ml_include.h PATH_SUFFIXES trilinos)
find_library(ML_LIBRARY trilinos_ml)
if(ML_INCLUDE_DIR AND ML_LIBRARY)
  set(MPM_ML_FOUND ON)
else()
  set(MPM_ML_FOUND OFF)
endif()
option(MPM_WITH_ML "Build the Trilinos ML adapter (presets pn-ml-pcg, lbfgs-ml)" ${MPM_ML_FOUND})
if(MPM_WITH_ML)
  mpm_require(ML_INCLUDE_DIR "Trilinos ML headers (MPM_WITH_ML=ON)" "libtrilinos-ml-dev")
  mpm_require(ML_LIBRARY "Trilinos ML (MPM_WITH_ML=ON)" "libtrilinos-ml-dev")
elseif(NOT MPM_ML_FOUND)
  message(STATUS "Trilinos ML not found: building without the ml presets (install the Debian package "
                 "'libtrilinos-ml-dev' or run scripts/setup.sh to get them)")
endif()

find_package(PNG)
mpm_require(PNG_FOUND "libpng" "libpng-dev")

add_library(mpm_deps INTERFACE)
target_include_directories(mpm_deps INTERFACE ${JANSSON_INCLUDE_DIR} ${CHOLMOD_INCLUDE_DIR}
                           ${HYPRE_INCLUDE_DIR})
target_link_libraries(mpm_deps INTERFACE OpenMP::OpenMP_C MPI::MPI_C GSL::gsl
                      ${JANSSON_LIBRARY} ${CHOLMOD_LIBRARY} ${HYPRE_LIBRARY} PNG::PNG)
if(MPM_WITH_ML)
  target_include_directories(mpm_deps INTERFACE ${ML_INCLUDE_DIR})
  target_link_libraries(mpm_deps INTERFACE ${ML_LIBRARY})
  target_compile_definitions(mpm_deps INTERFACE MPM_WITH_ML=1)
endif()
add_library(MPM::deps ALIAS mpm_deps)
