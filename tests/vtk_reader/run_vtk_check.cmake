# Runs an example that writes ParaView frames, then reads them with VTK's own
# reader: a fracture run (CASE fracture, the default: square_plate and
# check_frames.py) or a rigid-body impact (CASE impact: mass_impact and
# check_body_frames.py). The first interpreter of CANDIDATES that can
# `import vtk` is used (ParaView's pvpython, Debian's python3 with
# python3-vtk9, ...); with none the test prints "SKIP: no Python with VTK" and
# ctest counts it as skipped.
#   cmake -DEXAMPLE=<example> -DWORK_DIR=<dir> -DSCRIPT=<check script>
#         -DCANDIDATES="a;b" -DENCODING=zlib|binary [-DCASE=impact] -P run_vtk_check.cmake
cmake_minimum_required(VERSION 3.16)
set(python "")
foreach(candidate IN LISTS CANDIDATES)
  if(NOT candidate)
    continue()
  endif()
  execute_process(COMMAND "${candidate}" -c "import vtk" RESULT_VARIABLE result OUTPUT_QUIET ERROR_QUIET)
  if(result EQUAL 0)
    set(python "${candidate}")
    break()
  endif()
endforeach()
if(NOT python)
  message("SKIP: no Python with VTK among '${CANDIDATES}' (Debian: apt-get install python3-vtk9)")
  return()
endif()
message(STATUS "VTK reader: ${python}")

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
if(CASE STREQUAL "impact")
  # A coarse plate and 1 ms: the striker is on the plate from the second frame on.
  set(side 0.2)
  set(thickness 0.002)
  set(radius 0.0125)
  execute_process(COMMAND "${EXAMPLE}" --n 15 --end-time 1e-3 --side ${side} --thickness ${thickness}
                          --striker-radius ${radius} --output frames --frames
                  WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE result
                  OUTPUT_FILE "${WORK_DIR}/stdout.txt" ERROR_VARIABLE errors)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "${EXAMPLE} failed (${result}): ${errors}")
  endif()
  execute_process(COMMAND "${python}" "${SCRIPT}" "${WORK_DIR}/frames" "${WORK_DIR}/frames/history.csv"
                          ${side} ${thickness} ${radius}
                  RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "VTK's reader found problems in the body frames (above)")
  endif()
  return()
endif()
set(end_time 1.5e-3)
set(n 21)
math(EXPR stress_points "(${n} - 1) * (${n} - 1)")
execute_process(COMMAND "${EXAMPLE}" --case fracture --n ${n} --pressure 12e6 --end-time ${end_time} --output frames --frames
                WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE result
                OUTPUT_FILE "${WORK_DIR}/stdout.txt" ERROR_VARIABLE errors)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "${EXAMPLE} failed (${result}): ${errors}")
endif()
execute_process(COMMAND "${python}" "${SCRIPT}" "${WORK_DIR}/frames" "${WORK_DIR}/stdout.txt" ${end_time}
                        ${stress_points} ${ENCODING}
                RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "VTK's reader found problems in the frames (above)")
endif()
