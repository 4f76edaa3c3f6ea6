# cmake -P script behind ctest's doxygen_warning_free: runs Doxygen with the
# configured Doxyfile and fails on any warning it logs. Without Doxygen it
# prints "doxygen not found", which the test reports as skipped.
#   cmake -DDOXYGEN=<doxygen or empty> -DDOXYFILE=<build>/docs/Doxyfile
#         -DWARNINGS=<build>/docs/doxygen_warnings.log -P check_doxygen.cmake
cmake_minimum_required(VERSION 3.16)
if(NOT DOXYGEN)
  message(STATUS "doxygen not found: skipped (apt-get install doxygen, then reconfigure)")
  return()
endif()
file(REMOVE "${WARNINGS}")
execute_process(COMMAND "${DOXYGEN}" "${DOXYFILE}" RESULT_VARIABLE result
                OUTPUT_VARIABLE output ERROR_VARIABLE errors)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "doxygen ${DOXYFILE} exited with ${result}\n${output}\n${errors}")
endif()
set(logged "")
if(EXISTS "${WARNINGS}")
  file(READ "${WARNINGS}" logged)
endif()
string(STRIP "${logged}${errors}" logged)
if(NOT logged STREQUAL "")
  message(FATAL_ERROR "doxygen warned:\n${logged}")
endif()
message(STATUS "doxygen: no warnings")
