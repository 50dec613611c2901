# Installs the build in BUILD_DIR into WORK_DIR/prefix, configures SOURCE_DIR/examples against it with
# find_package(redres), builds the examples and runs the first one; then builds and runs the out-of-tree plugin
# example in examples/custom_plugin. Fails on any error.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(LAST_OUTPUT "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build -j 2)
run(${WORK_DIR}/build/example_01_kinematics)
if(NOT LAST_OUTPUT MATCHES "paper_pushrod_6dof: 6 joints, 2 task rows")
  message(FATAL_ERROR "unexpected output from the installed example:\n${LAST_OUTPUT}")
endif()
message(STATUS "find_package(redres) consumer built and ran:\n${LAST_OUTPUT}")

# The out-of-tree plugin example: one .cpp with a new constraint, used from a TOML file.
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/custom_plugin -B ${WORK_DIR}/plugin -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/plugin -j 2)
run(${WORK_DIR}/plugin/custom_plugin_example)
if(NOT LAST_OUTPUT MATCHES "200 steps, 0 failed, engine projection")
  message(FATAL_ERROR "unexpected output from the custom plugin example:\n${LAST_OUTPUT}")
endif()
message(STATUS "custom plugin example:\n${LAST_OUTPUT}")
