#pragma once
/// @file
/// The orientation rows of a pose task's reference: the path gives the position rows; this gives the rest. It holds
/// an orientation (set, or the end effector's at the first step) or turns it over the run: from R_0 at t = 0 to
/// Rot(turn) R_0 at t = T, about the fixed world axis turn / |turn| through |turn| rad (for |turn| <= pi the
/// spherical linear interpolation; a larger |turn| goes the long way round, as asked), with the cycloidal timing
/// s(t) = t/T - sin(2 pi t/T) / (2 pi), so that the angular velocity turn s'(t), fed forward, starts and ends at
/// zero. Planar: an angle about z (only turn.z() is used). The rows of r_d_ddot are the reference's angular
/// acceleration turn s''(t) (planar: the z angle's second derivative), which is the time derivative of the angular
/// velocity in r_d_dot (the axis is fixed) and zero when the orientation is held or t is outside [0, T].

#include <Eigen/Core>

#include "redres/model/kinematics.hpp"
#include "redres/model/robot.hpp"

namespace redres {

/// The orientation part of r_d, r_d_dot and r_d_ddot. Allocation-free.
class OrientationReference {
 public:
  /// The orientation to hold or to start the turn from (planar: the angle in z; spatial: a rotation vector).
  void set(const Eigen::Vector3d& rotation_vector) {
    orientation_ = rotation_vector;
    set_ = true;
  }
  /// The turn over the run (zero: hold).
  void set_turn(const Eigen::Vector3d& turn) { turn_ = turn; }
  /// Forgets a captured (not an explicitly set) orientation: the next evaluate() captures it again.
  void forget_captured() noexcept { captured_ = false; }
  /// The orientation held or turned from (meaningful once set or captured).
  [[nodiscard]] const Eigen::Vector3d& orientation() const noexcept { return orientation_; }

  /// Writes rows p.. of r_d and r_d_dot (p = the path's dimension) at time t of a run of duration T, capturing the
  /// end effector's orientation from `kin` first when none was set or captured.
  void evaluate(const RobotModel& robot, const KinematicsData& kin, double t, double T, int p, Eigen::VectorXd& r_d,
                Eigen::VectorXd& r_d_dot);
  /// As above, and rows p.. of r_d_ddot (r_d and r_d_dot are bit-identical to the overload above).
  void evaluate(const RobotModel& robot, const KinematicsData& kin, double t, double T, int p, Eigen::VectorXd& r_d,
                Eigen::VectorXd& r_d_dot, Eigen::VectorXd& r_d_ddot);

 private:
  // Both overloads: r_d_ddot's rows are written when it is not null.
  void evaluate_rows(const RobotModel& robot, const KinematicsData& kin, double t, double T, int p,
                     Eigen::VectorXd& r_d, Eigen::VectorXd& r_d_dot, Eigen::VectorXd* r_d_ddot);

  Eigen::Vector3d orientation_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d turn_ = Eigen::Vector3d::Zero();
  bool set_ = false;       // by set()
  bool captured_ = false;  // from the first evaluate()
};

}  // namespace redres
