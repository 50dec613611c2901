# cmake -DFILE=<shared object> -P set_rpath_origin.cmake: sets its RPATH (RUNPATH) to $ORIGIN, so that it finds the
# libraries beside it (setup.py: the pip-installed extension and libredres.so.<major> in one directory). CMake edits
# the ELF file in place, which needs an RPATH entry at least as long as "$ORIGIN" already there (a build RPATH).
if(NOT FILE OR NOT EXISTS "${FILE}")
  message(FATAL_ERROR "set_rpath_origin.cmake: FILE='${FILE}' does not exist")
endif()
file(RPATH_SET FILE "${FILE}" NEW_RPATH "$ORIGIN")
