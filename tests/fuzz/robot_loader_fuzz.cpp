// libFuzzer target: the robot loader and the kinematics (docs/fuzzing.md).
//
// The input is a robot TOML file. It is written into the scratch directory (fuzz_util.hpp, where the repository's
// URDF files and CSV tables resolve as they do beside robots/) and loaded with load_robot(path), the entry point of
// `redres robot` and of every scenario. A robot that loads is evaluated at a few configurations inside its limits:
// forward kinematics, the Jacobian and every derived quantity (both kinematics paths), the velocity-limit laws, and
// the distances between the collision shapes of the link pairs checked for self-collision (robot_evaluation.hpp).
//
// Exceptions derived from std::exception are the loader's answers to bad input and are expected. Crashes, sanitizer
// reports, leaks, timeouts and out-of-memory are findings; so is a non-finite f or J at a finite configuration of a
// robot that loaded (the loader bounds every length and position).

#include <cstdint>
#include <exception>

#include "fuzz_util.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "robot_evaluation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = redres::fuzz::scratch().write("input.toml", data, size);
  try {
    const redres::RobotModel robot = redres::load_robot(file);
    redres::fuzz::evaluate_robot(robot);
  } catch (const std::exception&) {
    // Bad input, reported as a ConfigError, UrdfError, std::invalid_argument, ...
  }
  return 0;
}
