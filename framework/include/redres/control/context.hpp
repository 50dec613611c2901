#pragma once
/// @file
/// The Context: everything a plugin may read at one control step.

#include <array>
#include <string_view>
#include <utility>

#include <Eigen/Core>

#include "redres/model/kinematics.hpp"
#include "redres/qp/solver_status.hpp"

namespace redres {

/// The order of the derivative a scheme's QP solves for (the scenario's `[scheme] level`; docs/motion.md): x =
/// theta_dot (the paper's velocity level) or x = theta_ddot (the acceleration level: theta_dot and theta are integrated
/// from x).
/// ("Level" alone, in the code, is a priority level.)
enum class ControlOrder { kVelocity, kAcceleration };
/// The names a scenario's [scheme] level takes.
inline auto enum_names(ControlOrder) {
  return std::array{std::pair{ControlOrder::kVelocity, std::string_view("velocity")},
                    std::pair{ControlOrder::kAcceleration, std::string_view("acceleration")}};
}

/// Everything a plugin may read at one control step. New inputs are added here, never to plugin signatures.
struct Context {
  double t = 0.0;                              //!< time since the start of the task (s)
  double T = 0.0;                              //!< task duration (s)
  double tau = 0.0;                            //!< control step (s)
  const RobotModel* robot = nullptr;           //!< the robot
  const KinematicsData* kinematics = nullptr;  //!< kinematics at theta (f, J, dJ, w, grad w, ...)
  const Eigen::VectorXd* r_d = nullptr;        //!< desired task coordinates r_d(t) (m_task)
  const Eigen::VectorXd* r_d_dot = nullptr;    //!< desired task velocity r_d_dot(t) (m_task)
  /// Desired task acceleration r_d_ddot(t) (m_task): set at the acceleration level; null at the velocity level.
  const Eigen::VectorXd* r_d_ddot = nullptr;
  /// What x is: theta_dot (velocity level) or theta_ddot (acceleration level).
  ControlOrder order = ControlOrder::kVelocity;
  /// The joint velocity at this step (n) at the acceleration level: the measured one when the caller passed it, else
  /// the previous step's command (theta_dot_prev). Null at the velocity level.
  const Eigen::VectorXd* theta_dot = nullptr;
  /// The robot's velocity-limit laws at theta (n each), evaluated once per step by the Controller; null where a
  /// caller builds a Context without them (plugins then evaluate the laws themselves).
  const Eigen::VectorXd* velocity_lower = nullptr;
  const Eigen::VectorXd* velocity_upper = nullptr;
  /// The robot's acceleration and jerk limits at theta (n each), evaluated once per step by the Controller when the
  /// robot has them; null otherwise, or where a caller builds a Context without them (plugins then evaluate the laws
  /// themselves).
  const Eigen::VectorXd* acceleration_lower = nullptr;
  const Eigen::VectorXd* acceleration_upper = nullptr;
  const Eigen::VectorXd* jerk_lower = nullptr;
  const Eigen::VectorXd* jerk_upper = nullptr;

  // State between steps (docs/motion.md), kept by the Controller; null where a caller builds a Context itself.
  /// The command of the previous step (n): what the arm was last asked for, as applied (Heun's average of its two
  /// stages; zeros after a held step). Zeros at the first step of a run (after construction or reset()).
  const Eigen::VectorXd* theta_dot_prev = nullptr;
  /// The command of the step before that (n): with theta_dot_prev, the previous acceleration.
  const Eigen::VectorXd* theta_dot_prev2 = nullptr;
  /// The joint velocity the caller measured at this step (n), when it passed one; null otherwise.
  const Eigen::VectorXd* theta_dot_measured = nullptr;
  /// The previous step's status (SolverStatus::kNotRun at the first step of a run).
  SolverStatus status_prev = SolverStatus::kNotRun;
  /// The steps this run has made before this one (0 at its first step; the second stage of Heun's method is not a
  /// step of its own).
  long step_index = 0;

  /// Joint positions theta (n).
  [[nodiscard]] const Eigen::VectorXd& theta() const { return kinematics->theta; }
  /// Bounds lo <= v' <= hi on the joint velocity v' after this step, as bounds on x: (lo - theta_dot) / tau at the
  /// acceleration level, lo itself at the velocity level. For plugins that bound velocities at either level.
  [[nodiscard]] double velocity_to_x(double v_next, int j) const {
    return order == ControlOrder::kVelocity ? v_next : (v_next - (*theta_dot)(j)) / tau;
  }
  /// Joint j's velocity-limit law at theta: as the Controller evaluated it once for the step (velocity_lower/upper),
  /// or from the law where a caller's Context carries none.
  [[nodiscard]] VelocityBounds velocity_bounds(int j) const {
    if (velocity_lower != nullptr && velocity_upper != nullptr) return {(*velocity_lower)(j), (*velocity_upper)(j)};
    return robot->joint(j).velocity_limit->bounds(theta()(j));
  }
  /// Whether this step starts a run (no previous command yet).
  [[nodiscard]] bool first_step() const noexcept { return step_index == 0; }
};

}  // namespace redres
