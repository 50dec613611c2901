# `redres run --animate` with the build tree's redres: a short planar run with an obstacle, and a short spatial
# run, each must write a non-empty animation.gif when ffmpeg is not on PATH (PATH holds only a python3 with
# matplotlib) and report it; `[output] animate = true` does the same; with ffmpeg on the system, the MP4 path
# too; without matplotlib, exit code 2 with the message of --plots. Skipped (the SKIP_REGULAR_EXPRESSION of the
# test) only when no python3 with matplotlib and numpy exists.
# Arguments: REDRES (the executable), SOURCE_DIR, WORK_DIR.

include(${CMAKE_CURRENT_LIST_DIR}/run_checked.cmake)

# A python3 with matplotlib and numpy: the first on PATH that has them, else Debian's.
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
  message(STATUS "redres-test-skip: no python3 with matplotlib and numpy on PATH or in /usr/bin")
  return()
endif()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/python)
file(CREATE_LINK ${python} ${WORK_DIR}/python/python3 SYMBOLIC)
set(default_path "$ENV{PATH}")
unset(ENV{REDRES_TOOLS_DIR})

# Runs redres in SOURCE_DIR with PATH = <path>; sets code, out and err in the caller.
function(redres path)
  set(ENV{PATH} "${path}")
  execute_process(COMMAND ${REDRES} ${ARGN} WORKING_DIRECTORY ${SOURCE_DIR}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  set(ENV{PATH} "${default_path}")
  set(code "${rc}" PARENT_SCOPE)
  set(out "${stdout}" PARENT_SCOPE)
  set(err "${stderr}" PARENT_SCOPE)
endfunction()

# expect_animation(<label> <path> <file> <redres arguments>...): exit code 0, <file> (in the --out directory, the
# argument after --out) exists, is not empty, starts as a GIF or an MP4 does, and stdout names it.
function(expect_animation label path file)
  redres("${path}" ${ARGN})
  list(FIND ARGN --out at)
  math(EXPR at "${at} + 1")
  list(GET ARGN ${at} dir)
  set(written ${dir}/${file})
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${label}: exit code ${code}:\n${out}\n${err}")
  endif()
  if(NOT EXISTS ${written})
    message(FATAL_ERROR "${label}: no ${written}:\n${out}\n${err}")
  endif()
  file(SIZE ${written} size)
  file(READ ${written} head LIMIT 12 HEX)
  if(file MATCHES "gif$")
    set(magic "^474946383961")  # GIF89a
  else()
    set(magic "^........66747970")  # an ISO media file: size, then 'ftyp'
  endif()
  if(size LESS 1000 OR NOT head MATCHES "${magic}")
    message(FATAL_ERROR "${label}: ${written} is not a ${file} (${size} bytes, starts ${head})")
  endif()
  if(NOT out MATCHES "animation: [^\n]*${file}")
    message(FATAL_ERROR "${label}: stdout does not name ${file}:\n${out}")
  endif()
  message(STATUS "${label}: ${written}, ${size} bytes\n${out}")
endfunction()

# Short runs: the R in steps of 0.1 s (a shorter R is more than the push-rod joints can do), 2 s of the helix.
set(planar configs/paper_r_obstacle.toml --set step=0.1)
set(spatial configs/panda_helix.toml --set duration=2 --set step=0.01 --set solver.max_task_error=0.05)
# PATH with the python3 alone: no ffmpeg, so a GIF.
expect_animation("planar --animate, no ffmpeg" ${WORK_DIR}/python animation.gif
                 run ${planar} --out ${WORK_DIR}/planar --animate)
expect_animation("spatial --animate, no ffmpeg" ${WORK_DIR}/python animation.gif
                 run ${spatial} --out ${WORK_DIR}/spatial --animate)
expect_animation("[output] animate = true, no ffmpeg" ${WORK_DIR}/python animation.gif
                 run ${planar} --set output.animate=true --out ${WORK_DIR}/planar-key)
# --plots on a robot with acceleration limits draws the commanded accelerations against them.
redres(${WORK_DIR}/python run ${spatial} --out ${WORK_DIR}/spatial-plots --plots --quiet)
if(NOT code EQUAL 0 OR NOT EXISTS ${WORK_DIR}/spatial-plots/fig_joint_accelerations.png)
  message(FATAL_ERROR "--plots on the Panda made no fig_joint_accelerations.png (${code}):\n${out}\n${err}")
endif()
# With ffmpeg on the system, an MP4, which replaces the GIF an earlier run left.
find_program(ffmpeg ffmpeg)
if(ffmpeg)
  get_filename_component(ffmpeg_dir ${ffmpeg} DIRECTORY)
  expect_animation("planar --animate, ffmpeg" "${WORK_DIR}/python:${ffmpeg_dir}" animation.mp4
                   run ${planar} --out ${WORK_DIR}/planar --animate)
  if(EXISTS ${WORK_DIR}/planar/animation.gif)
    message(FATAL_ERROR "the animation.gif of the earlier run was left beside animation.mp4")
  endif()
else()
  message(STATUS "ffmpeg is not installed: the MP4 path was not tried")
endif()

# Without matplotlib: exit code 2, the message of --plots, and the data written.
file(WRITE ${WORK_DIR}/no-matplotlib/matplotlib.py
     "raise ModuleNotFoundError(\"No module named 'matplotlib'\", name='matplotlib')\n")
set(ENV{PYTHONPATH} ${WORK_DIR}/no-matplotlib)
redres(${WORK_DIR}/python run ${planar} --out ${WORK_DIR}/no-matplotlib-out --animate)
unset(ENV{PYTHONPATH})
if(NOT code EQUAL 2 OR NOT err MATCHES "--animate: matplotlib is not installed"
   OR NOT EXISTS ${WORK_DIR}/no-matplotlib-out/frames.csv)
  message(FATAL_ERROR "no matplotlib: expected exit code 2, '--animate: matplotlib is not installed' and the data, "
                      "got ${code}:\n${out}\n${err}")
endif()
message(STATUS "no matplotlib: ${err}")

file(REMOVE_RECURSE ${WORK_DIR})
