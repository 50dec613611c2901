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
# Configures SOURCE_DIR/<project> against the installed package, builds it, runs <program> and checks that its
# output matches <expected>.
function(build_and_run project build program expected label)
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/${project} -B ${WORK_DIR}/${build} -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/${build} -j 2)
  run(${WORK_DIR}/${build}/${program})
  if(NOT LAST_OUTPUT MATCHES "${expected}")
    message(FATAL_ERROR "unexpected output from the ${label}:\n${LAST_OUTPUT}")
  endif()
  message(STATUS "${label}:\n${LAST_OUTPUT}")
endfunction()

build_and_run(examples build example_01_kinematics "paper_pushrod_6dof: 6 joints, 2 task rows"
              "find_package(redres) consumer")
# The out-of-tree plugin example: one .cpp with a new constraint, used from a TOML file.
build_and_run(examples/custom_plugin plugin custom_plugin_example "200 steps, 0 failed, engine projection"
              "custom plugin example")
