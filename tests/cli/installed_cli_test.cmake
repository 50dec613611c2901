# The installed `redres` on its own. Installs the build in BUILD_DIR into a scratch prefix outside the source and
# build trees, copies one scenario and its robot from the installed share/redres into a scratch directory, and runs
# `redres run SCENARIO --out DIR --plots` there with REDRES_TOOLS_DIR unset, so that nothing can come from
# SOURCE_DIR or BUILD_DIR: checks the data and the figures. Then checks that figures that cannot be made (no
# python3 on PATH, no matplotlib, a failing python3) are an error with exit code 2 and a message on stderr.
# The scratch directory is removed when the test passes and kept, for a look, when it fails.

set(SCRATCH_NAME installed-cli)
include(${CMAKE_CURRENT_LIST_DIR}/scratch_install.cmake)
set(redres ${prefix}/bin/redres)

# The installed binary names neither tree (the build's RPATH is rewritten on install; the build tree's path starts
# with the source tree's in the presets' layout, so one search covers both).
file(STRINGS ${redres} strings LENGTH_MINIMUM 8)
foreach(tree ${SOURCE_DIR} ${BUILD_DIR})
  foreach(s IN LISTS strings)
    string(FIND "${s}" "${tree}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "the installed ${redres} names ${tree}: ${s}")
    endif()
  endforeach()
endforeach()

# One scenario with its robot, from the installed data, laid out as the scenario expects (robot = "../robots/...").
set(data ${work}/data)
file(COPY ${prefix}/share/redres/configs/planar_4link_circle.toml DESTINATION ${data}/configs)
file(COPY ${prefix}/share/redres/robots/planar_4link.toml DESTINATION ${data}/robots)

# The figures need a python3 with matplotlib and numpy: the first on PATH that has them, else Debian's (where
# scripts/install_deps.sh puts them). It goes first on redres's PATH through a directory that holds only it.
string(REPLACE ":" ";" path_dirs "$ENV{PATH}")
set(python "")
foreach(dir IN LISTS path_dirs ITEMS /usr/bin)
  if(dir AND EXISTS ${dir}/python3)
    execute_process(COMMAND ${dir}/python3 -c "import matplotlib, numpy" RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
    if(rc EQUAL 0)
      set(python ${dir}/python3)
      break()
    endif()
  endif()
endforeach()
if(NOT python)
  message(FATAL_ERROR "no python3 with matplotlib and numpy on PATH or in /usr/bin: "
                      "apt-get install python3-matplotlib python3-numpy")
endif()
file(MAKE_DIRECTORY ${work}/python)
file(CREATE_LINK ${python} ${work}/python/python3 SYMBOLIC)
set(default_path "$ENV{PATH}")

# Runs the installed redres in the scratch data directory with PATH = <path>; a short run (1 s, 100 steps) keeps
# the test quick. Sets code, out and err in the caller.
unset(ENV{REDRES_TOOLS_DIR})
function(redres path)
  set(ENV{PATH} "${path}")
  execute_process(COMMAND ${redres} ${ARGN} WORKING_DIRECTORY ${data}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  set(ENV{PATH} "${default_path}")
  set(code "${rc}" PARENT_SCOPE)
  set(out "${stdout}" PARENT_SCOPE)
  set(err "${stderr}" PARENT_SCOPE)
endfunction()
set(scenario configs/planar_4link_circle.toml --set duration=1 --set step=0.01)

# The installed prefix alone makes the figures.
redres("${work}/python:${default_path}" run ${scenario} --out out --plots)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "redres run --plots from ${prefix} failed (${code}):\n${out}\n${err}\n"
                      "(scratch directory kept: ${work})")
endif()
foreach(f trajectory.csv summary.json fig3_profiles.png fig4_task.png fig6_joint_angles.png
        fig7_joint_velocities.png fig9b_position_error.png)
  if(NOT EXISTS ${data}/out/${f})
    message(FATAL_ERROR "redres run --plots wrote no ${f}:\n${out}\n${err}\n(scratch directory kept: ${work})")
  endif()
  if(f MATCHES "\\.png$")
    file(READ ${data}/out/${f} magic LIMIT 8 HEX)
    if(NOT magic STREQUAL "89504e470d0a1a0a")
      message(FATAL_ERROR "${data}/out/${f} is not a PNG file (scratch directory kept: ${work})")
    endif()
  endif()
endforeach()
message(STATUS "installed redres run --plots:\n${out}")

# Figures that cannot be made are an error: exit code 2 and a message on stderr that says why.
# expect_plot_error(<label> <PATH> <stderr regex> <redres arguments>...)
function(expect_plot_error label path expected)
  redres("${path}" ${ARGN})
  if(NOT code EQUAL 2 OR NOT err MATCHES "${expected}")
    message(FATAL_ERROR "${label}: expected exit code 2 and '${expected}' on stderr, got ${code}:\n"
                        "stdout:\n${out}\nstderr:\n${err}\n(scratch directory kept: ${work})")
  endif()
  message(STATUS "${label}: ${err}")
endfunction()
file(MAKE_DIRECTORY ${work}/empty)
expect_plot_error("no python3 on PATH" ${work}/empty "python3 not found on PATH"
                  run ${scenario} --out no-python --plots)
expect_plot_error("[output] plots = true, no python3 on PATH" ${work}/empty "python3 not found on PATH"
                  run ${scenario} --set output.plots=true --out no-python)
expect_plot_error("compare, no python3 on PATH" ${work}/empty "python3 not found on PATH"
                  compare ${scenario} --out no-python)
# matplotlib hidden from the working python3 by a module of that name that fails to import, as a missing one does.
file(WRITE ${work}/no-matplotlib/matplotlib.py
     "raise ModuleNotFoundError(\"No module named 'matplotlib'\", name='matplotlib')\n")
set(ENV{PYTHONPATH} ${work}/no-matplotlib)
expect_plot_error("no matplotlib" "${work}/python:${default_path}" "matplotlib is not installed"
                  run ${scenario} --out no-matplotlib --plots)
unset(ENV{PYTHONPATH})
file(WRITE ${work}/failing/python3 "#!/bin/sh\nexit 1\n")
file(CHMOD ${work}/failing/python3 PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
expect_plot_error("a python3 that fails" ${work}/failing "plotting failed: .*exited with code 1"
                  run ${scenario} --out failing --plots)

file(REMOVE_RECURSE ${work})
