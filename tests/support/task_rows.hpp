#pragma once
// For the tests of task rows (the end-effector task at both orders): a shipped robot with other task rows, and J_dot v
// by central differences.

#include <string>

#include <Eigen/Core>

#include "redres/config/toml_reader.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "test_util.hpp"

namespace redres::testing {

// The robot file `file` (relative to the source tree) with its `task = "position"` replaced by `task = <task>`, e.g.
// "\"pose\"" or "[\"x\", \"z\"]".
inline RobotModel robot_with_task(const std::string& file, const std::string& task) {
  std::string text = read_text(source_path(file));
  const std::string position = "task = \"position\"";
  text.replace(text.find(position), position.size(), "task = " + task);
  return load_robot(TableReader::root(parse_toml_string(text, file)));
}

// J_dot v at theta: the derivative of the task rows' J along v, by central differences.
inline Eigen::VectorXd jdot_v(const RobotModel& robot, const Eigen::VectorXd& theta, const Eigen::VectorXd& v) {
  KinematicsData kp(robot), km(robot);
  const double h = 1e-6;
  compute_kinematics(robot, theta + h * v, kp, KinematicsLevel::kJacobian);
  compute_kinematics(robot, theta - h * v, km, KinematicsLevel::kJacobian);
  return (kp.J - km.J) * v / (2.0 * h);
}

}  // namespace redres::testing
