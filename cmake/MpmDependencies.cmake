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

find_package(PNG)
mpm_require(PNG_FOUND "libpng" "libpng-dev")

add_library(mpm_deps INTERFACE)
target_include_directories(mpm_deps INTERFACE ${JANSSON_INCLUDE_DIR} ${CHOLMOD_INCLUDE_DIR}
                           ${HYPRE_INCLUDE_DIR})
target_link_libraries(mpm_deps INTERFACE OpenMP::OpenMP_C MPI::MPI_C GSL::gsl
                      ${JANSSON_LIBRARY} ${CHOLMOD_LIBRARY} ${HYPRE_LIBRARY} PNG::PNG)
add_library(MPM::deps ALIAS mpm_deps)
