#include "redres/collision_rows.hpp"

#include <cmath>

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

void damper_row(const Damper& damper, double d, const Eigen::Vector3d& n, const Eigen::Matrix3Xd& D,
                const Eigen::Vector3d& v_b, Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> A_row, double& b) {
  if (d > damper.influence_distance) {
    A_row.setZero();
    b = 1.0;
    return;
  }
  // Column by column: a product expression here would go through a temporary (an allocation per row).
  for (Eigen::Index c = 0; c < D.cols(); ++c) A_row(c) = -n.dot(D.col(c));
  b = -damper.min_rate(d) - n.dot(v_b);
}

namespace {
bool unit(Eigen::Vector3d v, bool planar, Eigen::Vector3d& n) {
  if (planar) v.z() = 0.0;
  const double len = v.norm();
  if (!(len > 1e-12)) return false;
  n = v / len;
  return true;
}
}  // namespace

bool witness_normal(const ShapeDistance& d, bool planar, const Eigen::Vector3d& fallback, Eigen::Vector3d& n) {
  const Eigen::Vector3d diff = d.point_a - d.point_b;
  if (diff.norm() > 1e-9 && unit((d.distance < 0.0 ? -1.0 : 1.0) * diff, planar, n)) return true;
  if (unit(fallback, planar, n)) return true;
  n.setZero();
  return false;
}

}  // namespace redres
