#pragma once
/// @file
/// Inverse kinematics for the start configuration (docs/ik.md): from a seed, iterate redres's own QP until the end
/// effector reaches a target pose, within the joint limits and clear of collisions.
///
/// Each iteration is one Controller step of a scheme built from the registered plugins, for a copy of the robot
/// whose task rows are the target's (position, or the whole pose when an orientation is given):
///   - objective `min_velocity_norm` (W = I): the smallest change of the joints that does the rest;
///   - `task_tracking` with gain 1 per iteration: J dx = e, the full Gauss-Newton step to the target;
///   - `joint_angle_margin` with kappa = 1: theta + dx stays within [theta^- + margin, theta^+ - margin];
///   - `joint_velocity_limits` over step laws |dx_j| <= max_step: a trust region;
///   - the collision constraints it is given (the scenario's `self_collision`, `obstacle_avoidance`, ...), rebuilt
///     for that copy from their configuration, each pair's damper set to halve its distance to d_s per iteration at
///     most, and every pair within max(d_i, d_s + 0.25 m) of each other given a row.
/// When the rows cannot be met inside the bounds (a target far away, a singular arm, a joint at its limit, a pair at
/// its safety distance) the step is the elastic QP's (Controller::set_failure_policy(kRelax)): damped least squares
/// inside every bound and collision row. A step that makes the error grow, or that makes two bodies overlap, is
/// halved. The iteration ends when both errors are below their tolerances (converged), or when the error has not
/// improved for `stall_iterations` iterations; then it starts again from up to `restarts` other seeds (pseudo-random
/// within the limits, fixed sequence; none for a target beyond the arm's reach), and a failure reports the closest
/// configuration of all with a diagnosis.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "redres/control/plugin.hpp"
#include "redres/model/robot.hpp"

namespace redres {

/// Where the end effector should be, in the world (base) frame.
struct IkTarget {
  /// Position (m); planar robots use x and y (z is ignored).
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  /// Orientation. Spatial: R = Rz(yaw) Ry(pitch) Rx(roll) (rpy_matrix); planar: Rz(phi). Empty: position only.
  std::optional<Eigen::Matrix3d> rotation;
  /// The rows to reach, by name ("x", "y", "z", "wx", "wy", "wz"; planar "x", "y", "phi"), in the pose's order. Empty:
  /// every position row, and every orientation row when `rotation` is given. Orientation rows need `rotation`.
  std::vector<std::string> rows;

  /// A spatial target: position and, optionally, roll, pitch, yaw (rad).
  [[nodiscard]] static IkTarget spatial(const Eigen::Vector3d& position,
                                        const std::optional<Eigen::Vector3d>& rpy = std::nullopt);
  /// A planar target: x, y and, optionally, the end-effector angle phi (rad).
  [[nodiscard]] static IkTarget planar(double x, double y, std::optional<double> phi = std::nullopt);
};

/// Settings of the iteration.
struct IkOptions {
  /// Kept from every joint limit (rad or m): one number, or one per joint (size n). Each must be below half the
  /// joint's range.
  Eigen::VectorXd margin = Eigen::VectorXd::Zero(1);
  double max_step = 0.25;                //!< the largest change of a joint per iteration (rad or m), > 0
  double position_tolerance = 1e-12;     //!< converged when the position error is at most this (m)
  double orientation_tolerance = 1e-12;  //!< and the orientation error at most this (rad)
  int max_iterations = 300;              //!< QP iterations per seed, at most
  int stall_iterations = 25;             //!< a seed gives up after this many iterations without progress
  int restarts = 24;                     //!< further seeds tried when the first does not converge
  double relax_weight = 1e4;             //!< rho of the elastic QP: damping 1 / rho
  bool self_collision = true;            //!< add `self_collision` (its defaults) for a robot with collision
                                         //!< shapes when `collision` has none of that type
};

/// Why an IK did not converge.
enum class IkFailure {
  kNone,         //!< it converged
  kUnreachable,  //!< no joint limit or collision holds it: the target is out of reach (or the seeds' basins)
  kJointLimit,   //!< joints at their limits (margin included) hold it back: `limit_joints`
  kCollision,    //!< a pair at its safety distance holds it back: `blocking_pair`
  kSolver,       //!< a QP could not be solved at all (the solver's diagnosis)
};

/// The outcome of solve_ik(). On failure `theta` is the closest configuration found (within the limits and clear of
/// collisions), never an unchecked one.
struct IkResult {
  bool converged = false;                                         //!< both errors within their tolerances
  Eigen::VectorXd theta;                                          //!< the configuration found (n)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();         //!< the end effector's pose there
  double position_error = 0.0;                                    //!< over the target's position rows (m)
  double orientation_error = 0.0;                                 //!< over its orientation rows (rad; 0 without)
  int iterations = 0;                                             //!< QP iterations, every seed counted
  int seeds = 0;                                                  //!< seeds tried (1 + restarts used)
  double seconds = 0.0;                                           //!< wall time
  double min_distance = std::numeric_limits<double>::infinity();  //!< nearest pair of the collision constraints (m);
                                                                  //!< +inf without any (or none within reach)
  std::string nearest_pair;                                       //!< that pair, e.g. "link 'j3' ... vs obstacle 1 ..."
  IkFailure failure = IkFailure::kNone;                           //!< why not converged
  std::vector<int> limit_joints;                                  //!< kJointLimit: the joints (0-based)
  std::string blocking_pair;                                      //!< kCollision: the pair, as its constraint names it
  std::string diagnosis;                                          //!< one sentence with the figures (empty: converged)

  /// One line: "converged in 9 iterations (1 seed, 2.1 ms): position error 1.1e-16 m, orientation error 2e-16 rad,
  /// nearest collision pair 0.0312 m", or "did not converge: <diagnosis>".
  [[nodiscard]] std::string summary() const;
};

/// Solves the IK of `robot` for `target` from `seed` (n values; clamped into the limits). `collision` lists
/// collision constraints (built for `robot`, e.g. a scenario's) whose bodies the answer keeps apart: each is rebuilt
/// from its config() for the IK's copy of the robot. Throws std::invalid_argument for a target that does not suit
/// the robot (a planar target for a spatial robot, orientation rows without a rotation, a non-finite entry) or for
/// options out of range.
[[nodiscard]] IkResult solve_ik(const RobotModel& robot, const IkTarget& target, const Eigen::VectorXd& seed,
                                const std::vector<const Constraint*>& collision = {}, const IkOptions& options = {});

/// The name of a failure kind: "none", "unreachable", "joint_limit", "collision", "solver".
[[nodiscard]] const char* to_string(IkFailure failure) noexcept;

}  // namespace redres
