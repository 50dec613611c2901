# Precompiled headers (-DREDRES_PCH=ON; off by default). About two thirds of the time a small redres file takes to
# compile is spent parsing the same headers (the standard library, Eigen, toml++ and redres's own core: a path plugin
# of 40 lines is 160,000 lines once preprocessed). With REDRES_PCH each target parses them once, into a precompiled
# header, and every file of the target starts from it. Measured on the whole release build, it saves about a tenth of
# the compile time (the large files' time goes into instantiating and optimising templates, not parsing), so CI and
# the presets build without it: every file then compiles on its own, which keeps its #include lines complete. The
# sources include what they use either way (the layering check reads their #include lines).
option(REDRES_PCH "Precompile the headers most files include (about 10 % shorter builds)" OFF)

# What the library's files and the plugins share: the standard headers most of them include, Eigen, toml++, and the
# plugin interface with everything it includes (the configuration schemas, the robot model, the kinematics, the
# QP builder).
set(REDRES_PCH_LIBRARY_HEADERS
  <algorithm> <array> <cmath> <cstdint> <filesystem> <functional> <limits> <map> <memory> <optional> <set>
  <sstream> <stdexcept> <string> <string_view> <utility> <vector>
  <Eigen/Core> <Eigen/Geometry> <toml++/toml.h>
  "${PROJECT_SOURCE_DIR}/framework/include/redres/control/plugin.hpp")

# The test programs': the library's set, GoogleTest and rapidcheck, and the headers most tests include (the
# controller, scenarios and their runs, robot files).
set(REDRES_PCH_TEST_HEADERS
  ${REDRES_PCH_LIBRARY_HEADERS} <fstream> <random>
  <gtest/gtest.h> <rapidcheck.h> <rapidcheck/gtest.h>
  "${PROJECT_SOURCE_DIR}/framework/include/redres/control/controller.hpp"
  "${PROJECT_SOURCE_DIR}/framework/include/redres/parsers/robot_toml.hpp"
  "${PROJECT_SOURCE_DIR}/framework/include/redres/run/scenario.hpp"
  "${PROJECT_SOURCE_DIR}/framework/include/redres/run/simulation.hpp")

# redres_precompile(TARGET HEADERS...): TARGET's files start from a precompiled header of HEADERS.
function(redres_precompile target)
  if(REDRES_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# redres_precompile_like(TARGET FROM): TARGET uses FROM's precompiled header (the two compile with the same flags).
function(redres_precompile_like target from)
  if(REDRES_PCH)
    target_precompile_headers(${target} REUSE_FROM ${from})
  endif()
endfunction()
