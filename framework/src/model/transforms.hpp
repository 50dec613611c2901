#pragma once
/// @file
/// The elementary transforms that robot descriptions are converted into (private to the framework).

#include <Eigen/Geometry>

namespace redres {

/// Rotation by `a` about z.
[[nodiscard]] inline Eigen::Isometry3d rot_z(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()));
}
/// Rotation by `a` about x.
[[nodiscard]] inline Eigen::Isometry3d rot_x(double a) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()));
}
/// Translation by (x, y, z).
[[nodiscard]] inline Eigen::Isometry3d trans(double x, double y, double z) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(x, y, z);
  return t;
}

}  // namespace redres
