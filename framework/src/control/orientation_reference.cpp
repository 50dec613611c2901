#include "redres/control/orientation_reference.hpp"

#include <algorithm>

#include <Eigen/Geometry>

#include "redres/control/path.hpp"

namespace redres {

void OrientationReference::evaluate(const RobotModel& robot, const KinematicsData& kin, double t, double T, int p,
                                    Eigen::VectorXd& r_d, Eigen::VectorXd& r_d_dot) {
  evaluate_rows(robot, kin, t, T, p, r_d, r_d_dot, nullptr);
}

void OrientationReference::evaluate(const RobotModel& robot, const KinematicsData& kin, double t, double T, int p,
                                    Eigen::VectorXd& r_d, Eigen::VectorXd& r_d_dot, Eigen::VectorXd& r_d_ddot) {
  evaluate_rows(robot, kin, t, T, p, r_d, r_d_dot, &r_d_ddot);
}

void OrientationReference::evaluate_rows(const RobotModel& robot, const KinematicsData& kin, double t, double T, int p,
                                         Eigen::VectorXd& r_d, Eigen::VectorXd& r_d_dot, Eigen::VectorXd* r_d_ddot) {
  if (!set_ && !captured_) {
    // Hold the orientation the end effector has at the start.
    orientation_ =
        robot.kind() == ChainKind::kPlanar ? Eigen::Vector3d(0.0, 0.0, kin.f(2)) : Eigen::Vector3d(kin.f.tail<3>());
    captured_ = true;
  }
  const int rest = robot.reference_dim() - p;
  // The turn's progress s(t) in [0, 1], its rate and its second derivative (zero when the orientation is held, and
  // the last also outside [0, T], where the progress stays at 0 or 1).
  double progress = 0.0, rate = 0.0, rate_dot = 0.0;
  if (turn_.squaredNorm() > 0.0 && T > 0.0) {
    double dprogress = 0.0;  // d progress / du, u = t / T
    if (r_d_ddot != nullptr) {
      double d2progress = 0.0;  // d^2 progress / du^2
      timing(TimingLaw::kCycloidal, std::clamp(t / T, 0.0, 1.0), progress, dprogress, d2progress);
      if (t >= 0.0 && t <= T) rate_dot = d2progress / (T * T);
    } else {
      timing(TimingLaw::kCycloidal, std::clamp(t / T, 0.0, 1.0), progress, dprogress);
    }
    rate = dprogress / T;
  }
  if (robot.kind() == ChainKind::kPlanar) {
    r_d(2) = orientation_.z() + progress * turn_.z();
    r_d_dot(2) = rate * turn_.z();
    if (r_d_ddot != nullptr) (*r_d_ddot)(2) = rate_dot * turn_.z();
    return;
  }
  if (progress == 0.0) {
    r_d.tail(rest) = orientation_;
  } else {
    const double angle = turn_.norm();
    const Eigen::AngleAxisd R(Eigen::AngleAxisd(progress * angle, turn_ / angle).toRotationMatrix() *
                              rotation_from_vector(orientation_));
    r_d.tail(rest) = R.angle() * R.axis();
  }
  r_d_dot.tail(rest) = rate * turn_;  // the world angular velocity, as J's angular rows
  // Its derivative: the axis turn / |turn| is fixed in the world, so only the rate changes.
  if (r_d_ddot != nullptr) r_d_ddot->tail(rest) = rate_dot * turn_;
}

}  // namespace redres
