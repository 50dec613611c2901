#pragma once
/// @file
/// The Context: everything a plugin may read at one control step.

#include <Eigen/Core>

#include "redres/model/kinematics.hpp"

namespace redres {

/// Everything a plugin may read at one control step. New inputs are added here, never to plugin signatures.
struct Context {
  double t = 0.0;                              //!< time since the start of the task (s)
  double T = 0.0;                              //!< task duration (s)
  double tau = 0.0;                            //!< control step (s)
  const RobotModel* robot = nullptr;           //!< the robot
  const KinematicsData* kinematics = nullptr;  //!< kinematics at theta (f, J, dJ, w, grad w, ...)
  const Eigen::VectorXd* r_d = nullptr;        //!< desired task coordinates r_d(t) (m_task)
  const Eigen::VectorXd* r_d_dot = nullptr;    //!< desired task velocity r_d_dot(t) (m_task)
  /// The robot's velocity-limit laws at theta (n each), evaluated once per step by the Controller; null where a
  /// caller builds a Context without them (plugins then evaluate the laws themselves).
  const Eigen::VectorXd* velocity_lower = nullptr;
  const Eigen::VectorXd* velocity_upper = nullptr;

  /// Joint positions theta (n).
  [[nodiscard]] const Eigen::VectorXd& theta() const { return kinematics->theta; }
};

}  // namespace redres
