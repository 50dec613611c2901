# Installs the build in BUILD_DIR into WORK_DIR/prefix, configures SOURCE_DIR/examples against it with
# find_package(redres), builds the examples and runs the first one; then builds the out-of-tree plugin library of
# examples/custom_plugin, runs the installed `redres` on its scenario, and runs the conformance checks on it.
# Fails on any error.
file(REMOVE_RECURSE ${WORK_DIR})
include(${CMAKE_CURRENT_LIST_DIR}/run_checked.cmake)
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
# The out-of-tree plugin example, as a user runs it: copy examples/custom_plugin (and the robots its scenario
# names), build the plugin library against the installed package, and run the stock installed `redres` on the
# scenario, which names the library; then the conformance checks on the loaded plugins.
file(COPY ${SOURCE_DIR}/examples/custom_plugin DESTINATION ${WORK_DIR}/user/examples)
file(COPY ${SOURCE_DIR}/robots DESTINATION ${WORK_DIR}/user)
set(example ${WORK_DIR}/user/examples/custom_plugin)
run(${CMAKE_COMMAND} -S ${example} -B ${example}/build -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --build ${example}/build -j 2)
set(redres ${WORK_DIR}/prefix/bin/redres)
execute_process(COMMAND ${redres} run ${example}/scenario.toml --out ${WORK_DIR}/user/out --quiet
                WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "redres run on the custom plugin scenario failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${WORK_DIR}/user/out/summary.json summary)
string(JSON failures GET "${summary}" solver failures)
string(JSON engine GET "${summary}" solver engine)
if(NOT failures EQUAL 0 OR NOT engine STREQUAL "projection")
  message(FATAL_ERROR "custom plugin run: ${failures} failures, engine ${engine}")
endif()
# joint_speed_cap held: |theta_dot_1| <= 0.05 rad/s on every recorded step.
file(STRINGS ${WORK_DIR}/user/out/trajectory.csv rows)
list(GET rows 0 header)
string(REPLACE "," ";" header "${header}")
list(FIND header theta_dot_1 col)
list(REMOVE_AT rows 0)
foreach(row IN LISTS rows)
  string(REPLACE "," ";" cells "${row}")
  list(GET cells ${col} v)
  string(REGEX REPLACE "^-" "" v "${v}")
  if(v MATCHES "e-")
    continue()  # tiny
  endif()
  if(v GREATER 0.050001)  # the projection engine meets A x <= b within its tolerance (1e-6)
    message(FATAL_ERROR "joint_speed_cap violated: |theta_dot_1| = ${v}")
  endif()
endforeach()
message(STATUS "custom plugin scenario: 0 failures, |theta_dot_1| <= 0.05 on every step")
execute_process(COMMAND ${redres} --plugin ${example}/build/libredres_custom_plugins.so plugins --check
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "checks passed, 0 failed")
  message(FATAL_ERROR "redres plugins --check with the custom plugins (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${redres} --plugin ${example}/build/libredres_custom_plugins.so plugins
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT out MATCHES "range_centering" OR NOT out MATCHES "joint_speed_cap" OR NOT out MATCHES "from ")
  message(FATAL_ERROR "redres plugins does not list the loaded plugins with their library:\n${out}")
endif()
message(STATUS "custom plugins: ${out}")
