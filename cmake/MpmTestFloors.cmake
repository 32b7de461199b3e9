# The libraries a test or fuzz harness links (tests/CMakeLists.txt says why):
# the floor it names in its "/* floor: ... */" line, and the third-party
# libraries whose headers its #include lines name.

# floor name -> its library (which links the floors below it)
set(mpm_floor_library_core mpm_core)
set(mpm_floor_library_scene mpm_scene)
set(mpm_floor_library_solvers mpm_solvers)
set(mpm_floor_library_adapters mpm_adapters)
set(mpm_floor_library_driver mpm_driver)
set(mpm_floor_library_app mpm_app)
# third-party header (a regex matched after "#include <") -> its library
set(mpm_third_party "gsl/;GSL::gsl" "png\\.h;PNG::PNG" "jansson\\.h;MPM::jansson" "mpi\\.h;MPI::MPI_C")

# Sets `floors_out` to the floors SRC names and `libs_out` to the libraries
# it links for them and for the third-party headers it includes.
function(mpm_floor_libraries src floors_out libs_out)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${src}) # a changed line reconfigures
  file(STRINGS ${src} floor_line REGEX "^/\\* floor: [a-z ]+ \\*/")
  if(NOT floor_line)
    message(FATAL_ERROR "${src}: no \"/* floor: ... */\" line naming the floor it tests "
                        "(core, scene, solvers, adapters, driver, app; tests/CMakeLists.txt)")
  endif()
  string(REGEX REPLACE "^/\\* floor: ([a-z ]+) \\*/.*" "\\1" floors "${floor_line}")
  string(REPLACE " " ";" floors "${floors}")
  set(libs "")
  foreach(f ${floors})
    if(NOT DEFINED mpm_floor_library_${f})
      message(FATAL_ERROR "${src}: unknown floor '${f}' (core, scene, solvers, adapters, driver, app)")
    endif()
    list(APPEND libs ${mpm_floor_library_${f}})
  endforeach()
  file(STRINGS ${src} includes REGEX "^#include <")
  list(LENGTH mpm_third_party n)
  math(EXPR last "${n} - 1")
  foreach(i RANGE 0 ${last} 2)
    math(EXPR j "${i} + 1")
    list(GET mpm_third_party ${i} pattern)
    list(GET mpm_third_party ${j} lib)
    if(includes MATCHES "#include <${pattern}")
      list(APPEND libs ${lib})
    endif()
  endforeach()
  set(${floors_out} "${floors}" PARENT_SCOPE)
  set(${libs_out} "${libs}" PARENT_SCOPE)
endfunction()
