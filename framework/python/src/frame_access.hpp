#pragma once
// The robot's named frames for Python (StepContext and redres.Kinematics): their names, and a frame's pose and
// Jacobian read from kinematics already computed (model/frames.hpp), looked up by name. These allocate their
// results (Python gets copies); the C++ step's own path does not go through them.

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/model/frames.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"

namespace redres::python {

/// RobotModel::frames()' names, in order.
inline std::vector<std::string> frame_names(const RobotModel& robot) {
  std::vector<std::string> names;
  names.reserve(robot.frames().size());
  for (const auto& f : robot.frames()) names.push_back(f.name);
  return names;
}

/// The index of the frame `name`; an unknown name throws std::invalid_argument (Python: ValueError) naming it and
/// listing the robot's frames.
inline int frame_index(const RobotModel& robot, const std::string& name, const char* who) {
  const int index = robot.find_frame(name);
  if (index < 0) {
    std::string known;
    for (const auto& f : robot.frames()) known += (known.empty() ? "'" : ", '") + f.name + "'";
    throw std::invalid_argument(std::string(who) + ": robot '" + robot.name() + "' has no frame '" + name +
                                "'; its frames are " + known);
  }
  return index;
}

/// The world pose (4 x 4) of the frame `name` in `kin` (kPosition or above).
inline Eigen::Matrix4d frame_pose_of(const RobotModel& robot, const KinematicsData& kin, const std::string& name,
                                     const char* who) {
  return frame_pose(robot, kin, frame_index(robot, name, who)).matrix();
}

/// The 6 x n Jacobian [v; omega] of the frame `name` with its origin moved by `point` (in the frame's axes; zeros
/// when absent). A point that is not a 3-vector throws std::invalid_argument (Python: ValueError).
inline Eigen::MatrixXd frame_jacobian_of(const RobotModel& robot, const KinematicsData& kin, const std::string& name,
                                         const std::optional<Eigen::VectorXd>& point, const char* who) {
  const int index = frame_index(robot, name, who);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  if (point) {
    if (point->size() != 3) {
      throw std::invalid_argument(std::string(who) + ": point has " + std::to_string(point->size()) +
                                  " entries, expected 3 (a point in the frame's own axes)");
    }
    p = *point;
  }
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, robot.dof());
  frame_jacobian(robot, kin, index, p, J);
  return J;
}

/// Every joint's link frame in `kin` (4 x 4 each).
inline std::vector<Eigen::Matrix4d> link_frames_of(const KinematicsData& kin) {
  std::vector<Eigen::Matrix4d> frames;
  frames.reserve(kin.link_frames.size());
  for (const auto& frame : kin.link_frames) frames.push_back(frame.matrix());
  return frames;
}

}  // namespace redres::python
