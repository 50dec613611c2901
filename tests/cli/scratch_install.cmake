# Included by the installed-package tests: makes a scratch directory `work` outside the source and build trees
# (SOURCE_DIR, BUILD_DIR), so that a path that still pointed into them would be noticed, named after SCRATCH_NAME,
# and installs the build in BUILD_DIR into `prefix` (${work}/prefix). RUN_FAILURE_NOTE names the directory, which
# a failing test keeps for a look.
if(DEFINED ENV{TMPDIR} AND IS_DIRECTORY "$ENV{TMPDIR}")
  set(tmp "$ENV{TMPDIR}")
else()
  set(tmp /tmp)
endif()
string(RANDOM LENGTH 8 tag)
file(REAL_PATH ${tmp}/redres-${SCRATCH_NAME}-${tag} work)
foreach(tree ${SOURCE_DIR} ${BUILD_DIR})
  file(REAL_PATH ${tree} tree)
  string(FIND "${work}/" "${tree}/" at)
  if(at EQUAL 0)
    message(FATAL_ERROR "the scratch directory ${work} is inside ${tree}; set TMPDIR to a directory outside it")
  endif()
endforeach()
file(REMOVE_RECURSE ${work})
file(MAKE_DIRECTORY ${work})

set(RUN_FAILURE_NOTE "(scratch directory kept: ${work})")
include(${CMAKE_CURRENT_LIST_DIR}/run_checked.cmake)

set(prefix ${work}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
