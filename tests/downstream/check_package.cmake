# cmake -P script: install sphshell into WORK_DIR/prefix, build the downstream
# project against it and run it.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run_step)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK_DIR}
                  RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  message("${output}")
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "step failed (${result}): ${ARGN}")
  endif()
endfunction()

run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/sphshell-build -G ${GENERATOR}
         -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
         -DSPHSHELL_BUILD_TESTS=OFF -DSPHSHELL_BUILD_EXAMPLES=OFF -DSPHSHELL_BUILD_BENCHMARKS=OFF
         -DCMAKE_INSTALL_PREFIX=${WORK_DIR}/prefix)
run_step(${CMAKE_COMMAND} --install ${WORK_DIR}/sphshell-build)
# Relocatability: the consumer sees the prefix only through CMAKE_PREFIX_PATH,
# after the installed tree has been moved.
file(RENAME ${WORK_DIR}/prefix ${WORK_DIR}/moved-prefix)
run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/downstream -B ${WORK_DIR}/downstream-build
         -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
         -DCMAKE_PREFIX_PATH=${WORK_DIR}/moved-prefix)
run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/downstream-build)
run_step(${WORK_DIR}/downstream-build/downstream)
