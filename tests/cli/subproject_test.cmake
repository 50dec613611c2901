# redres as a sub-project: a parent that does add_subdirectory(SOURCE_DIR) gets the library and the CLI but, by
# default, none of our tests, benchmarks or examples (REDRES_BUILD_* default to PROJECT_IS_TOP_LEVEL). Configures
# such a parent in WORK_DIR with GENERATOR and checks the targets it defines. Fails on any error.
file(REMOVE_RECURSE ${WORK_DIR})
file(WRITE ${WORK_DIR}/parent/CMakeLists.txt
     "cmake_minimum_required(VERSION 3.22)\n"
     "project(redres_parent LANGUAGES CXX)\n"
     "add_subdirectory(\"${SOURCE_DIR}\" redres)\n")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/parent -B ${WORK_DIR}/build -G "${GENERATOR}"
                        -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring a parent project of redres failed (${rc}):\n${out}\n${err}")
endif()
# The generator's list of targets (Unix Makefiles and Ninja both answer `--target help`).
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build --target help
                RESULT_VARIABLE rc OUTPUT_VARIABLE targets ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "listing the parent's targets failed (${rc}):\n${targets}\n${err}")
endif()
foreach(wanted redres_framework redres_cli)
  if(NOT targets MATCHES "(^|[ \n])${wanted}[:\n ]")
    message(FATAL_ERROR "the parent project has no ${wanted} target:\n${targets}")
  endif()
endforeach()
foreach(unwanted redres_tests redres_bench example_)
  if(targets MATCHES "(^|[ \n])${unwanted}")
    message(FATAL_ERROR "the parent project builds redres's ${unwanted}* by default:\n${targets}")
  endif()
endforeach()
if(EXISTS ${WORK_DIR}/build/redres/CTestTestfile.cmake)
  message(FATAL_ERROR "the parent project gets redres's ctest entries by default")
endif()
message(STATUS "a parent project of redres gets redres_framework and redres_cli, and no tests, benchmarks or examples")
file(REMOVE_RECURSE ${WORK_DIR})
