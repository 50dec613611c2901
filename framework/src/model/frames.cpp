#include "redres/model/frames.hpp"

namespace redres {

void point_jacobian(const RobotModel& robot, const KinematicsData& kin, int link, const Eigen::Vector3d& p,
                    Eigen::Ref<Eigen::Matrix3Xd> J) {
  J.setZero();
  for (int k = 0; k <= link; ++k) {
    const Eigen::Vector3d z = kin.axes.col(k);
    if (robot.joint(k).type == JointType::kRevolute) {
      J.col(k) = z.cross(p - kin.origins.col(k));
    } else {
      J.col(k) = z;
    }
  }
}

void frame_jacobian(const RobotModel& robot, const KinematicsData& kin, int frame, const Eigen::Vector3d& point,
                    Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> J) {
  const int link = robot.frames()[static_cast<std::size_t>(frame)].joint;
  const Eigen::Vector3d p = frame_pose(robot, kin, frame) * point;
  J.setZero();
  for (int k = 0; k <= link; ++k) {
    const Eigen::Vector3d z = kin.axes.col(k);
    if (robot.joint(k).type == JointType::kRevolute) {
      J.col(k).head<3>() = z.cross(p - kin.origins.col(k));
      J.col(k).tail<3>() = z;
    } else {
      J.col(k).head<3>() = z;
    }
  }
}

}  // namespace redres
