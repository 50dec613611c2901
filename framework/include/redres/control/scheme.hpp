#pragma once
/// @file
/// A redundancy-resolution scheme: the objectives and constraints that together build one QP per step.

#include <memory>
#include <vector>

#include "redres/control/plugin.hpp"

namespace redres {

/// One controller's data for a scheme: each plugin's PluginData (nullptr for a plugin that makes none), in the
/// scheme's order. Made by Scheme::make_data(); the caller (a Controller) owns it and passes it to every build.
struct SchemeData {
  std::vector<std::unique_ptr<PluginData>> objectives;   //!< one per objective
  std::vector<std::unique_ptr<PluginData>> constraints;  //!< one per constraint
};

/// Objectives and constraints assembled into one QP. Immutable after construction, so one scheme can serve several
/// controllers at once (each with its own SchemeData, in its own thread); build() allocates nothing.
class Scheme {
 public:
  /// Takes ownership of the plugins; sizes follow from the robot and the constraints' row counts.
  /// Throws std::invalid_argument when an active plugin does not work at `level` (Plugin::supports).
  Scheme(const RobotModel& robot, std::vector<std::unique_ptr<Objective>> objectives,
         std::vector<std::unique_ptr<Constraint>> constraints, SchemeLevel level = SchemeLevel::kVelocity);

  /// Reads `[[objectives]]` and `[[constraints]]` arrays of tables from `root`, and the `[scheme]` table's `level`.
  /// When the robot file gives every joint an acceleration (jerk) limit and no constraint of type
  /// `joint_acceleration_limits` (`joint_jerk_limits`) is listed, one is added with its defaults, so that the robot's
  /// limits hold in every run (list one with `active = false` to run without). Each plugin's source() is its
  /// table's file:line:col. With `duration` and `step` (> 0), each plugin's check_run(duration, step) runs too, and
  /// its FieldError is a ConfigError at the key.
  static Scheme from_toml(const TableReader& root, const RobotModel& robot, double duration = 0.0, double step = 0.0);

  /// Makes every plugin's data for one controller (allocates; at setup).
  [[nodiscard]] SchemeData make_data() const;
  /// Tells every plugin that a run starts (Plugin::start), with its data in `data`.
  void start(SchemeData& data) const;
  /// Sizes `qp` for this scheme (n, m_e, m_i) and names its sources; the descriptions of its inequality rows read
  /// the plugins' data in `data` (which may be moved, but must outlive `qp`'s use).
  void setup(QpProblem& qp, const SchemeData& data) const;
  /// Clears `qp` and lets every active plugin contribute. `ctx.kinematics` must be at kinematics_level().
  /// The plugins write without checks; then one scan checks every entry they can have written (W, zeta, the
  /// rows; bounds are checked as they are intersected). When it finds a non-finite entry (or an asymmetric W), the
  /// QP is built again with a check after each plugin, which throws std::invalid_argument naming the plugin and
  /// the entry. The QP it leaves is therefore valid (QpProblem::validate() would pass).
  void build(const Context& ctx, QpProblem& qp, SchemeData& data) const;

  /// The deepest kinematics any plugin reads.
  [[nodiscard]] KinematicsLevel kinematics_level() const noexcept { return level_; }
  /// What the QP's x is: theta_dot or theta_ddot.
  [[nodiscard]] SchemeLevel level() const noexcept { return scheme_level_; }
  /// Total equality and inequality rows.
  [[nodiscard]] int equality_rows() const noexcept { return m_eq_; }
  [[nodiscard]] int inequality_rows() const noexcept { return m_in_; }
  /// The plugins.
  [[nodiscard]] const std::vector<std::unique_ptr<Objective>>& objectives() const noexcept { return objectives_; }
  [[nodiscard]] const std::vector<std::unique_ptr<Constraint>>& constraints() const noexcept { return constraints_; }
  /// The robot (not owned; must outlive the scheme).
  [[nodiscard]] const RobotModel& robot() const noexcept { return *robot_; }

 private:
  const RobotModel* robot_;
  std::vector<std::unique_ptr<Objective>> objectives_;
  std::vector<std::unique_ptr<Constraint>> constraints_;
  std::vector<int> eq_offset_, eq_rows_, in_offset_, in_rows_;
  int m_eq_ = 0, m_in_ = 0;
  KinematicsLevel level_ = KinematicsLevel::kPosition;
  SchemeLevel scheme_level_ = SchemeLevel::kVelocity;
  // Clears qp and lets every plugin write (checked: through contribute(), which throws naming a culprit); returns
  // whether a plugin wrote off W's diagonal.
  bool contribute_all(const Context& ctx, QpProblem& qp, SchemeData& data, bool checked) const;
};

}  // namespace redres
