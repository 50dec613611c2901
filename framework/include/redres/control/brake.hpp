#pragma once
/// @file
/// The braking law of a step that is not solved (FailurePolicy::kBrake, docs/motion.md), on its own so that it can be
/// called and tested without a controller: the command is theta_dot = s b, b the joint velocity before the step and
/// s >= 0 one scale for every joint (the arm slows along the path it was on). s is the smallest scale that keeps every
/// joint's acceleration limits, its velocity limits and, where all of them can hold with s <= 1, its jerk limits from
/// the previous acceleration. Braking never speeds the arm up: s < 1 wherever a joint moves and its deceleration limit
/// is below zero. An arm that was accelerating faster than its jerk limits can turn round in one step (a_prev >
/// -tau j^- for the joint) cannot keep them and brake; the jerk limits then yield (`jerk_yields`) and s is the
/// acceleration limits' smallest scale.

#include <Eigen/Core>

namespace redres {

/// What the braking law reads, every vector of one entry per joint, each evaluated at the step's joint angles.
struct BrakeInput {
  const Eigen::VectorXd* velocity = nullptr;            //!< b: the joint velocity before the step (rad/s)
  const Eigen::VectorXd* acceleration_lower = nullptr;  //!< the acceleration limits (rad/s^2)
  const Eigen::VectorXd* acceleration_upper = nullptr;
  const Eigen::VectorXd* velocity_lower = nullptr;  //!< the velocity-limit laws (rad/s)
  const Eigen::VectorXd* velocity_upper = nullptr;
  /// The jerk limits (rad/s^3); null when the robot has none.
  const Eigen::VectorXd* jerk_lower = nullptr;
  const Eigen::VectorXd* jerk_upper = nullptr;
  /// The commands applied at the last two steps (the previous acceleration is their difference over tau); read only
  /// with jerk limits.
  const Eigen::VectorXd* previous = nullptr;
  const Eigen::VectorXd* previous2 = nullptr;
  double tau = 0.0;  //!< the step (s, > 0)
};

/// The braking law's answer.
struct BrakeScale {
  double scale = 0.0;        //!< s: the command is s b
  int deciding_joint = -1;   //!< the joint (0-based) whose limit sets s; -1 when none does
  bool jerk_yields = false;  //!< the jerk limits could not hold with the others, and yielded to them
};

/// The scale of the braking command (allocation-free). A joint whose velocity is zero or not finite, or whose limits
/// are not finite there (a law outside its range), sets nothing.
[[nodiscard]] BrakeScale braking_scale(const BrakeInput& in);

}  // namespace redres
