#pragma once
// Helpers shared by the tests.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <unistd.h>

#include <Eigen/Core>

#include "redres/model/robot.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

/// A path inside the source tree.
inline std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(REDRES_SOURCE_DIR) / relative;
}

/// A path inside tests/data.
inline std::filesystem::path data_path(const std::string& relative) {
  return std::filesystem::path(REDRES_TEST_DATA_DIR) / relative;
}

/// A temporary path for one test, removed if it exists: <tmp>/redres_cli_<name>_<pid>.
inline std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("redres_cli_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

/// scratch(name), made: an empty directory for one test's files.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = scratch(name);
  std::filesystem::create_directories(dir);
  return dir;
}

/// theta(0) of the paper, section 4.
inline Eigen::VectorXd paper_theta0() {
  Eigen::VectorXd t(6);
  t << M_PI / 4, M_PI / 12, M_PI / 12, M_PI / 12, M_PI / 36, M_PI / 36;
  return t;
}

/// A random configuration inside the robot's limits, away from each by `margin` of the joint's range.
inline Eigen::VectorXd random_inside(const RobotModel& robot, std::mt19937& rng, double margin = 0.0) {
  std::uniform_real_distribution<double> u(margin, 1.0 - margin);
  Eigen::VectorXd theta(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) {
    theta(j) = robot.lower_limits()(j) + u(rng) * (robot.upper_limits()(j) - robot.lower_limits()(j));
  }
  return theta;
}

/// The whole text of a file ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// theta at one row of a recorded run (its `theta_1` .. `theta_n` columns).
inline Eigen::VectorXd recorded_theta(const RobotModel& robot, const Trajectory& run, std::size_t row) {
  Eigen::VectorXd theta(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) theta(j) = run(row, run.column("theta_" + std::to_string(j + 1)));
  return theta;
}

}  // namespace redres
