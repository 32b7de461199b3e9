# Finds every third-party dependency, says which Debian package provides a
# missing one, and gives each an imported target that the floor using it
# links PRIVATE (docs/design.md, floors). The adapters' libraries (hypre,
# CHOLMOD, Trilinos ML, PETSc; adapters/adapter_list.h) are optional: each adapter's
# option (MPM_WITH_HYPRE, ...) is ON when its library is found.

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
# ranks) and the renderer (libpng). GSL, which only the tests use, is found in
# tests/CMakeLists.txt.
find_package(OpenMP COMPONENTS C)
mpm_require(OpenMP_C_FOUND "OpenMP for C" "libgomp1 (comes with gcc)")

find_package(MPI COMPONENTS C)
mpm_require(MPI_C_FOUND "MPI" "libopenmpi-dev")

find_path(JANSSON_INCLUDE_DIR jansson.h)
find_library(JANSSON_LIBRARY jansson)
mpm_require(JANSSON_LIBRARY "jansson (JSON)" "libjansson-dev")
mpm_require(JANSSON_INCLUDE_DIR "jansson headers" "libjansson-dev")
mpm_library(MPM::jansson ${JANSSON_INCLUDE_DIR} ${JANSSON_LIBRARY})

find_package(PNG)
mpm_require(PNG_FOUND "libpng" "libpng-dev")

# Optional adapters: adapters/adapter_list.h has one line per adapter (its
# name, the option that builds it, its Debian package, its library's key in
# run.json, what it is); here each adapter's library is found (a block per
# adapter, setting MPM_ADAPTER_<name>_FOUND and _LIBS), and the option made.
find_path(HYPRE_INCLUDE_DIR HYPRE.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY NAMES HYPRE)
set(MPM_ADAPTER_boomeramg_FOUND OFF)
if(HYPRE_INCLUDE_DIR AND HYPRE_LIBRARY)
  mpm_library(MPM::hypre ${HYPRE_INCLUDE_DIR} ${HYPRE_LIBRARY})
  set(MPM_ADAPTER_boomeramg_FOUND ON)
endif()
set(MPM_ADAPTER_boomeramg_LIBS MPM::hypre MPI::MPI_C OpenMP::OpenMP_C)

find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
set(MPM_ADAPTER_cholmod_FOUND OFF)
if(CHOLMOD_INCLUDE_DIR AND CHOLMOD_LIBRARY)
  mpm_library(MPM::cholmod ${CHOLMOD_INCLUDE_DIR} ${CHOLMOD_LIBRARY})
  set(MPM_ADAPTER_cholmod_FOUND ON)
endif()
set(MPM_ADAPTER_cholmod_LIBS MPM::cholmod OpenMP::OpenMP_C)

find_path(ML_INCLUDE_DIR ml_include.h PATH_SUFFIXES trilinos)
find_library(ML_LIBRARY trilinos_ml)
set(MPM_ADAPTER_ml_FOUND OFF)
if(ML_INCLUDE_DIR AND ML_LIBRARY)
  mpm_library(MPM::ml ${ML_INCLUDE_DIR} ${ML_LIBRARY})
  set(MPM_ADAPTER_ml_FOUND ON)
endif()
set(MPM_ADAPTER_ml_LIBS MPM::ml MPI::MPI_C OpenMP::OpenMP_C)

# PETSc (Debian's libpetsc-real3.18-dev: real scalars, 32-bit PetscInt, built
# with MPI): its pkg-config file first, else its headers and library where
# Debian puts them (PETSC_DIR/PETSC_ARCH, /usr/lib/petsc).
find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(PETSC QUIET PETSc)
endif()
set(MPM_ADAPTER_petsc_FOUND OFF)
if(PETSC_FOUND)
  mpm_library(MPM::petsc "${PETSC_INCLUDE_DIRS}" "${PETSC_LINK_LIBRARIES}")
  set(MPM_ADAPTER_petsc_FOUND ON)
else()
  find_path(PETSC_INCLUDE_DIR petscksp.h HINTS $ENV{PETSC_DIR}/$ENV{PETSC_ARCH}/include $ENV{PETSC_DIR}/include
            /usr/lib/petsc/include)
  find_library(PETSC_LIBRARY NAMES petsc_real petsc HINTS $ENV{PETSC_DIR}/$ENV{PETSC_ARCH}/lib $ENV{PETSC_DIR}/lib
               /usr/lib/petsc/lib)
  if(PETSC_INCLUDE_DIR AND PETSC_LIBRARY)
    mpm_library(MPM::petsc ${PETSC_INCLUDE_DIR} ${PETSC_LIBRARY})
    set(MPM_ADAPTER_petsc_FOUND ON)
  endif()
endif()
set(MPM_ADAPTER_petsc_LIBS MPM::petsc MPI::MPI_C OpenMP::OpenMP_C)

set(MPM_ADAPTERS "")
file(STRINGS ${CMAKE_CURRENT_SOURCE_DIR}/adapters/adapter_list.h mpm_adapter_lines REGEX "^ *X\\(")
string(REPLACE "\\" "" mpm_adapter_lines "${mpm_adapter_lines}") # the macro's line continuations
foreach(line ${mpm_adapter_lines})
  if(NOT line MATCHES "X\\(([a-z0-9_]+), *([A-Z0-9_]+), *\"([^\"]+)\", *\"([^\"]+)\", *\"([^\"]+)\"\\)")
    message(FATAL_ERROR "adapters/adapter_list.h: cannot read the line '${line}'")
  endif()
  set(name ${CMAKE_MATCH_1})
  if(NOT DEFINED MPM_ADAPTER_${name}_FOUND)
    message(FATAL_ERROR "adapters/adapter_list.h names the adapter ${name}, but cmake/MpmDependencies.cmake has no "
                        "block finding its library (MPM_ADAPTER_${name}_FOUND)")
  endif()
  list(APPEND MPM_ADAPTERS ${name})
  set(MPM_ADAPTER_${name}_OPTION ${CMAKE_MATCH_2})
  mpm_optional(${CMAKE_MATCH_2} MPM_ADAPTER_${name}_FOUND "${CMAKE_MATCH_5}" "${CMAKE_MATCH_3}")
endforeach()
