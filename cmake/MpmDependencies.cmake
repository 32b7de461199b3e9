# Finds every third-party dependency, says which Debian package provides a
# missing one, and gives each an imported target that the floor using it
# links PRIVATE (docs/design.md, floors). hypre and CHOLMOD are optional:
# MPM_WITH_HYPRE and MPM_WITH_CHOLMOD are ON when the library is found.

function(mpm_require found what package)
  if(NOT ${found})
    message(FATAL_ERROR "mpmbench needs ${what}: install the Debian package '${package}' "
                        "(sudo apt-get install ${package}) or run scripts/setup.sh")
  endif()
endfunction()

# An imported target NAME for a library found as an include dir and a file.
function(mpm_library name include_dir library)
  add_library(${name} INTERFACE IMPORTED)
  set_target_properties(${name} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${include_dir}"
                                           INTERFACE_LINK_LIBRARIES "${library}")
endfunction()

# option(MPM_WITH_<X>) defaulting to whether the library was found; ON without
# the library is an error, OFF says which package would turn it on.
function(mpm_optional option found what package)
  option(${option} "Build the ${what} adapter (Debian package ${package})" ${${found}})
  if(${option} AND NOT ${found})
    message(FATAL_ERROR "${option}=ON but ${what} was not found: install the Debian package '${package}' "
                        "or configure with -D${option}=OFF")
  elseif(NOT ${option})
    message(STATUS "${option}=OFF: the ${what} adapter and its presets are left out "
                   "(install the Debian package '${package}' and configure with -D${option}=ON)")
  endif()
endfunction()

# Required by the core and solvers (OpenMP), the scene loader and the app
# (jansson), the matrix runner (MPI: a study under mpirun hands cells to
# ranks) and the renderer (libpng); GSL by the tests only.
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
mpm_library(MPM::jansson ${JANSSON_INCLUDE_DIR} ${JANSSON_LIBRARY})

find_package(PNG)
mpm_require(PNG_FOUND "libpng" "libpng-dev")

# Optional adapters.
find_path(HYPRE_INCLUDE_DIR HYPRE.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY NAMES HYPRE)
if(HYPRE_INCLUDE_DIR AND HYPRE_LIBRARY)
  mpm_library(MPM::hypre ${HYPRE_INCLUDE_DIR} ${HYPRE_LIBRARY})
  set(MPM_HYPRE_FOUND ON)
else()
  set(MPM_HYPRE_FOUND OFF)
endif()
mpm_optional(MPM_WITH_HYPRE MPM_HYPRE_FOUND "hypre BoomerAMG" "libhypre-dev")

find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
if(CHOLMOD_INCLUDE_DIR AND CHOLMOD_LIBRARY)
  mpm_library(MPM::cholmod ${CHOLMOD_INCLUDE_DIR} ${CHOLMOD_LIBRARY})
  set(MPM_CHOLMOD_FOUND ON)
else()
  set(MPM_CHOLMOD_FOUND OFF)
endif()
mpm_optional(MPM_WITH_CHOLMOD MPM_CHOLMOD_FOUND "CHOLMOD" "libsuitesparse-dev")
