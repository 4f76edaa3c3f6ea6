# cmake -P script: builds and runs tests/downstream/main.cpp the way a user of
# sphshell would, in WORK_DIR. CONSUMER says how:
#   find_package    install into a scratch prefix, move it, find_package(sphshell)
#   pkg-config      install and move likewise, compile with `pkg-config --cflags sphshell`
#   add_subdirectory  vendor the source tree with add_subdirectory (no install)
#   include-only    compile against -I<source>/include and Eigen alone (no CMake)
#   find_package-mpi  install and move, find_package(sphshell COMPONENTS mpi), build the
#                   MPI consumer tests/mpi/downstream and run it with MPIEXEC (a list)
#   find_package-without-mpi  install and move; the plain consumer, configured as if
#                   MPI were absent (CMAKE_DISABLE_FIND_PACKAGE_MPI), must still build
#   install         only install into a scratch prefix and move it to WORK_DIR/moved-prefix,
#                   for the consumers given it as PREFIX (one install shared by several checks)
# What the consumer compiles: find_package-simd and include-only include the
# whole library (the umbrella header), which shows that every installed header
# compiles for a user (for SSE2 alone, a set the rest of the suite may not
# compile for), and every header of a source tree without the generated version
# header; the other checks show how the package is found and what its target or
# .pc file passes (include directories, Eigen, definitions, flags, MPI), which
# the core headers show as well (main.cpp, SPHSHELL_DOWNSTREAM_CORE_ONLY), at a
# fraction of the compile time.
# PREFIX: an installed and moved prefix (made by CONSUMER=install) that the
# find_package* (but find_package-simd) and pkg-config consumers use instead of
# installing one of their own.
#   cmake -DCONSUMER=<mode> -DSOURCE_DIR=<sphshell> -DWORK_DIR=<dir> -DGENERATOR=<gen>
#         -DCXX_COMPILER=<c++> -DEXPECTED_VERSION=<x.y.z> [-DPKG_CONFIG=<pkg-config>]
#         [-DEIGEN_INCLUDE_DIRS=<dirs>] -P check_package.cmake
cmake_minimum_required(VERSION 3.16)
if(NOT DEFINED CONSUMER)
  set(CONSUMER find_package)
endif()
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run_step)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK_DIR}
                  RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  message("${output}")
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "step failed (${result}): ${ARGN}")
  endif()
  set(step_output "${output}" PARENT_SCOPE)
endfunction()

set(compiler_flags "")
if(CXX_COMPILER MATCHES "(g\\+\\+|clang\\+\\+)")
  set(compiler_flags -Wall -Wextra -Wpedantic)
endif()

# find_package and find_package-simd: the consumer, built without a flag of its
# own, must target the set the package chose, by default (AUTO) for the first,
# pinned to SSE2 for the second.
set(simd_option "")
if(CONSUMER STREQUAL "find_package-simd")
  set(simd_option -DSPHSHELL_SIMD=SSE2)
endif()

set(moved_prefix ${WORK_DIR}/moved-prefix)
if(CONSUMER STREQUAL "find_package-simd" OR CONSUMER STREQUAL "install"
   OR (NOT PREFIX AND (CONSUMER MATCHES "^find_package" OR CONSUMER STREQUAL "pkg-config")))
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/sphshell-build -G ${GENERATOR}
           -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
           -DSPHSHELL_BUILD_TESTS=OFF -DSPHSHELL_BUILD_EXAMPLES=OFF -DSPHSHELL_BUILD_BENCHMARKS=OFF
           -DCMAKE_INSTALL_PREFIX=${WORK_DIR}/prefix ${simd_option})
  run_step(${CMAKE_COMMAND} --install ${WORK_DIR}/sphshell-build)
  # Relocatability: the consumer sees the prefix only through CMAKE_PREFIX_PATH
  # or PKG_CONFIG_PATH, after the installed tree has been moved.
  file(RENAME ${WORK_DIR}/prefix ${moved_prefix})
  if(CONSUMER STREQUAL "install")
    return()
  endif()
elseif(PREFIX)
  if(NOT EXISTS ${PREFIX}/share/sphshell/cmake/sphshellConfig.cmake)
    message(FATAL_ERROR "PREFIX ${PREFIX} holds no installed sphshell (its fixture, CONSUMER=install, did not run or failed)")
  endif()
  set(moved_prefix ${PREFIX})
endif()

if(CONSUMER STREQUAL "find_package" OR CONSUMER STREQUAL "find_package-simd")
  # The set the installed package records (its config file), whichever
  # install (this check's own or the shared one) made it.
  file(STRINGS ${moved_prefix}/share/sphshell/cmake/sphshellConfig.cmake chosen REGEX "^set\\(sphshell_SIMD ")
  string(REGEX REPLACE "^set\\(sphshell_SIMD ([A-Z0-9_]*)\\).*" "\\1" chosen "${chosen}")
  if(chosen STREQUAL "" OR (CONSUMER STREQUAL "find_package-simd" AND NOT chosen STREQUAL "SSE2"))
    message(FATAL_ERROR "the package's SPHSHELL_SIMD resolved to '${chosen}'")
  endif()
  set(expected_simd -DEXPECTED_SIMD=${chosen})
  set(core_only ON)
  if(CONSUMER STREQUAL "find_package-simd")
    set(core_only OFF)
  endif()
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/downstream -B ${WORK_DIR}/downstream-build
           -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
           -DCMAKE_PREFIX_PATH=${moved_prefix} -DEXPECTED_VERSION=${EXPECTED_VERSION}
           ${expected_simd} -DCORE_ONLY=${core_only})
  run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/downstream-build)
  run_step(${WORK_DIR}/downstream-build/downstream)
elseif(CONSUMER STREQUAL "find_package-mpi")
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/mpi/downstream -B ${WORK_DIR}/downstream-build
           -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
           -DCMAKE_PREFIX_PATH=${moved_prefix} -DEXPECTED_VERSION=${EXPECTED_VERSION})
  run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/downstream-build)
  run_step(${MPIEXEC} ${WORK_DIR}/downstream-build/downstream_mpi)
elseif(CONSUMER STREQUAL "find_package-without-mpi")
  if(NOT EXISTS ${moved_prefix}/share/sphshell/cmake/sphshellMpiTargets.cmake)
    message(FATAL_ERROR "the installed package has no MPI layer: nothing to check without it")
  endif()
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/downstream -B ${WORK_DIR}/downstream-build
           -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_DISABLE_FIND_PACKAGE_MPI=ON
           -DCMAKE_PREFIX_PATH=${moved_prefix} -DEXPECTED_VERSION=${EXPECTED_VERSION} -DCORE_ONLY=ON)
  run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/downstream-build)
  run_step(${WORK_DIR}/downstream-build/downstream)
elseif(CONSUMER STREQUAL "pkg-config")
  if(NOT PKG_CONFIG)
    message(FATAL_ERROR "pkg-config not found (scripts/install_dependencies.sh installs it)")
  endif()
  set(ENV{PKG_CONFIG_PATH} ${moved_prefix}/share/pkgconfig)
  run_step(${PKG_CONFIG} --modversion sphshell)
  string(STRIP "${step_output}" version)
  if(NOT version STREQUAL EXPECTED_VERSION)
    message(FATAL_ERROR "pkg-config --modversion sphshell gives '${version}', expected ${EXPECTED_VERSION}")
  endif()
  run_step(${PKG_CONFIG} --cflags sphshell)
  string(STRIP "${step_output}" cflags)
  # The include directory must be the moved prefix's, found from the .pc
  # file's place, not the prefix it was installed to.
  file(REAL_PATH ${moved_prefix}/include moved_include)
  separate_arguments(cflag_list UNIX_COMMAND "${cflags}")
  set(found_include OFF)
  foreach(flag IN LISTS cflag_list)
    if(flag MATCHES "^-I(.+)$")
      set(directory "${CMAKE_MATCH_1}")
      if(EXISTS "${directory}")
        file(REAL_PATH "${directory}" directory)
        if(directory STREQUAL moved_include)
          set(found_include ON)
        endif()
      endif()
    endif()
  endforeach()
  if(NOT found_include)
    message(FATAL_ERROR "pkg-config --cflags sphshell ('${cflags}') does not name ${moved_include}")
  endif()
  run_step(${CXX_COMPILER} -std=c++17 ${compiler_flags} ${cflag_list}
           "-DSPHSHELL_EXPECTED_VERSION=\"${EXPECTED_VERSION}\"" -DSPHSHELL_DOWNSTREAM_CORE_ONLY
           ${SOURCE_DIR}/tests/downstream/main.cpp -o ${WORK_DIR}/downstream)
  run_step(${WORK_DIR}/downstream)
elseif(CONSUMER STREQUAL "add_subdirectory")
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/downstream/subdirectory -B ${WORK_DIR}/downstream-build
           -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
           -DSPHSHELL_SOURCE_DIR=${SOURCE_DIR} -DEXPECTED_VERSION=${EXPECTED_VERSION})
  run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/downstream-build)
  run_step(${WORK_DIR}/downstream-build/downstream)
elseif(CONSUMER STREQUAL "include-only")
  set(include_flags -I${SOURCE_DIR}/include)
  foreach(directory IN LISTS EIGEN_INCLUDE_DIRS)
    list(APPEND include_flags -I${directory})
  endforeach()
  run_step(${CXX_COMPILER} -std=c++17 ${compiler_flags} ${include_flags} -DSPHSHELL_INCLUDE_ONLY
           ${SOURCE_DIR}/tests/downstream/main.cpp -o ${WORK_DIR}/downstream)
  run_step(${WORK_DIR}/downstream)
else()
  message(FATAL_ERROR "unknown CONSUMER ${CONSUMER}")
endif()
