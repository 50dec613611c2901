#pragma once
/// @file
/// Frames and points of the chain at a configuration, from the kinematics computed once per step
/// (KinematicsData: the link frames, joint axes and origins), for tasks on any link and the collision rows: a
/// frame's pose, its 6 x n Jacobian, a riding point's 3 x n Jacobian. Nothing here computes the chain's kinematics
/// again; everything is allocation-free.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"

namespace redres {

/// The world pose of RobotModel::frames()[frame] at the configuration in `kin` (which holds the link frames).
[[nodiscard]] inline Eigen::Isometry3d frame_pose(const RobotModel& robot, const KinematicsData& kin, int frame) {
  const RobotModel::Frame& f = robot.frames()[static_cast<std::size_t>(frame)];
  return kin.link_frames[static_cast<std::size_t>(f.joint)] * f.offset;
}

/// Writes the 3 x n Jacobian of the world point `p` moving with link `link` (columns of later joints are zero):
/// revolute joint k: z_k x (p - o_k); prismatic: z_k. `kin` must hold the configuration's joint axes and origins.
void point_jacobian(const RobotModel& robot, const KinematicsData& kin, int link, const Eigen::Vector3d& p,
                    Eigen::Ref<Eigen::Matrix3Xd> J);

/// Writes the 6 x n Jacobian of the frame RobotModel::frames()[frame] (with its origin moved by `point`, in the
/// frame's own axes): rows 0-2 the point's velocity, rows 3-5 the frame's angular velocity, both in the world
/// frame: [v; omega] = J theta_dot. `kin` must hold the configuration's link frames, axes and origins
/// (compute_kinematics at kPosition or above).
void frame_jacobian(const RobotModel& robot, const KinematicsData& kin, int frame, const Eigen::Vector3d& point,
                    Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> J);

}  // namespace redres
