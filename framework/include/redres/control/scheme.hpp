#pragma once
/// @file
/// A redundancy-resolution scheme: the objectives and constraints that together build one QP per step.

#include <memory>
#include <vector>

#include "redres/control/plugin.hpp"
#include "redres/control/task.hpp"

namespace redres {

/// One controller's data for a scheme: each plugin's PluginData (nullptr for a plugin that makes none), in the
/// scheme's order. Made by Scheme::make_data(); the caller (a Controller) owns it and passes it to every build.
struct SchemeData {
  std::vector<std::unique_ptr<PluginData>> objectives;   //!< one per objective
  std::vector<std::unique_ptr<PluginData>> constraints;  //!< one per constraint
  std::vector<std::unique_ptr<PluginData>> tasks;        //!< one per task (a TaskData)
};

/// One priority level of a scheme: its active objectives and tasks (indices into the scheme's lists).
struct SchemeLevelSpec {
  int priority = 0;
  std::vector<int> objectives;
  std::vector<int> tasks;
};

/// A scenario file's [scheme] table, read through its schema (and listed by `redres keys scenario`).
struct SchemeTable {
  ControlOrder order = ControlOrder::kVelocity;  //!< key `level`: what x is, theta_dot (the paper's) or theta_ddot
  double regularization = 1e-9;  //!< the eps |x|^2 / 2 of every priority level (Scheme::regularization())
  static const Schema<SchemeTable>& schema();
};

/// Objectives and constraints assembled into one QP. Immutable after construction, so one scheme can serve several
/// controllers at once (each with its own SchemeData, in its own thread); build() allocates nothing.
class Scheme {
 public:
  /// The default of regularization().
  static constexpr double kDefaultRegularization = 1e-9;
  /// Takes ownership of the plugins; sizes follow from the robot and the constraints' row counts.
  /// Throws std::invalid_argument when an active plugin does not work at `order` (Plugin::supports).
  Scheme(const RobotModel& robot, std::vector<std::unique_ptr<Objective>> objectives,
         std::vector<std::unique_ptr<Constraint>> constraints, ControlOrder order = ControlOrder::kVelocity);
  /// The same with tasks (control/task.hpp). Active objectives and tasks are grouped by priority into levels(), which
  /// the Controller solves in turn, one QP each (control/cascade.hpp).
  Scheme(const RobotModel& robot, std::vector<std::unique_ptr<Objective>> objectives,
         std::vector<std::unique_ptr<Constraint>> constraints, std::vector<std::unique_ptr<Task>> tasks,
         ControlOrder order = ControlOrder::kVelocity);

  /// Reads `[[objectives]]`, `[[constraints]]` and `[[tasks]]` arrays of tables from `root`, and the `[scheme]` table's
  /// `level`. When the robot file gives every joint an acceleration (jerk) limit and no constraint of type
  /// `joint_acceleration_limits` (`joint_jerk_limits`) is listed, one is added with its defaults, so that the robot's
  /// limits hold in every run (list one with `active = false` to run without). Each plugin's source() is its
  /// table's file:line:col. With `duration` and `step` (> 0), each plugin's check_run(duration, step) runs too, and
  /// its FieldError is a ConfigError at the key.
  static Scheme from_toml(const TableReader& root, const RobotModel& robot, double duration = 0.0, double step = 0.0);

  /// Makes every plugin's data for one controller (allocates; at setup).
  [[nodiscard]] SchemeData make_data() const;
  /// Tells every plugin that a run starts (Plugin::start), with its data in `data`.
  void start(SchemeData& data) const;
  /// A scheme of one level: its one QP, for a caller that solves it without a Controller (e.g. a benchmark or a test).
  /// The Controller's Cascade writes the same QP from the parts below (objectives, constraints, tasks), with the same
  /// entries. Sizes `qp` for this scheme (n, m_e, m_i) and names its sources; the descriptions of its inequality rows
  /// read the plugins' data in `data` (which may be moved, but must outlive `qp`'s use).
  void setup(QpProblem& qp, const SchemeData& data) const;
  /// Clears `qp` and lets every active plugin contribute. `ctx.kinematics` must be at kinematics_level().
  /// The plugins write without checks; then one scan checks every entry they can have written (W, zeta, the
  /// rows; bounds are checked as they are intersected). When it finds a non-finite entry (or an asymmetric W), the
  /// QP is built again with a check after each plugin, which throws std::invalid_argument naming the plugin and
  /// the entry. The QP it leaves is therefore valid (QpProblem::validate() would pass).
  void build(const Context& ctx, QpProblem& qp, SchemeData& data) const;

  /// The parts of a priority level's QP, which the Cascade assembles. The constraints' part: writes their rows and
  /// bounds into `qp` (sized n, constraint_equality_rows(), constraint_inequality_rows(); set up by
  /// setup_constraints()), with build()'s checks.
  void build_constraints(const Context& ctx, QpProblem& qp, SchemeData& data) const;
  /// Sizes `qp` for the constraints alone and names every source (objectives, constraints, tasks).
  void setup_constraints(QpProblem& qp, const SchemeData& data) const;
  /// The tasks' part: computes every active task's rows into its TaskData (checked: a non-finite entry throws
  /// std::invalid_argument naming the task).
  void evaluate_tasks(const Context& ctx, SchemeData& data) const;
  /// The objectives' part: clears `qp` (sized n, 0, 0) and adds the objectives of levels()[level], checked; returns
  /// what they wrote to W.
  QpBuilder::WrittenW build_objectives(const Context& ctx, int level, QpProblem& qp, SchemeData& data) const;

  /// The priority levels of the active objectives and tasks, highest first (at least one).
  [[nodiscard]] const std::vector<SchemeLevelSpec>& levels() const noexcept { return levels_; }
  /// Whether there are several levels (StepOutput::levels then reports each).
  [[nodiscard]] bool cascaded() const noexcept { return levels_.size() > 1; }
  /// The tasks (const: a scheme's plugins do not change once it is built).
  [[nodiscard]] const std::vector<std::unique_ptr<const Task>>& tasks() const noexcept { return tasks_; }
  /// The constraints' equality and inequality rows (without the tasks').
  [[nodiscard]] int constraint_equality_rows() const noexcept { return m_eq_c_; }
  [[nodiscard]] int constraint_inequality_rows() const noexcept { return m_in_c_; }
  /// The QP source index of task k (objectives, then constraints, then tasks).
  [[nodiscard]] int task_source(std::size_t k) const noexcept {
    return static_cast<int>(objectives_.size() + constraints_.size() + k);
  }

  /// With several levels: the eps of the eps |x|^2 / 2 that every level adds to make its answer unique (not held;
  /// control/cascade.hpp). `[scheme] regularization`.
  [[nodiscard]] double regularization() const noexcept { return regularization_; }
  /// Sets it (> 0, finite).
  void set_regularization(double eps);

  /// The deepest kinematics any plugin reads.
  [[nodiscard]] KinematicsLevel kinematics_level() const noexcept { return kinematics_level_; }
  /// What the QP's x is: theta_dot or theta_ddot.
  [[nodiscard]] ControlOrder order() const noexcept { return order_; }
  /// Total equality and inequality rows of build()'s QP (the constraints' and, with one level, the tasks').
  [[nodiscard]] int equality_rows() const noexcept { return m_eq_; }
  [[nodiscard]] int inequality_rows() const noexcept { return m_in_; }
  /// The plugins (const: a scheme's plugins do not change once it is built, so that several controllers may share it).
  [[nodiscard]] const std::vector<std::unique_ptr<const Objective>>& objectives() const noexcept { return objectives_; }
  [[nodiscard]] const std::vector<std::unique_ptr<const Constraint>>& constraints() const noexcept {
    return constraints_;
  }
  /// The robot (not owned; must outlive the scheme).
  [[nodiscard]] const RobotModel& robot() const noexcept { return *robot_; }

 private:
  const RobotModel* robot_;
  std::vector<std::unique_ptr<const Objective>> objectives_;
  std::vector<std::unique_ptr<const Constraint>> constraints_;
  std::vector<std::unique_ptr<const Task>> tasks_;
  std::vector<SchemeLevelSpec> levels_;
  std::vector<int> eq_offset_, eq_rows_, in_offset_, in_rows_;
  std::vector<std::size_t> constraint_order_;  // the order of their contributions: those whose bounds yield last
  std::vector<int> task_eq_offset_, task_eq_rows_, task_in_offset_, task_in_rows_;  // one level: the tasks' rows
  std::vector<bool> task_active_;  // active when the scheme was built (only those are in levels_ and the QP)
  int m_eq_ = 0, m_in_ = 0, m_eq_c_ = 0, m_in_c_ = 0;
  double regularization_ = kDefaultRegularization;
  KinematicsLevel kinematics_level_ = KinematicsLevel::kPosition;
  ControlOrder order_ = ControlOrder::kVelocity;
  // Clears qp and lets every plugin write (checked: through contribute(), which throws naming a culprit); returns
  // whether a plugin wrote off W's diagonal.
  bool contribute_all(const Context& ctx, QpProblem& qp, SchemeData& data, bool checked,
                      bool constraints_only = false) const;
  void check_built(const Context& ctx, QpProblem& qp, SchemeData& data, bool full_w, bool constraints_only) const;
  void name_sources(QpProblem& qp, const SchemeData& data) const;
  void check_inputs(const Context& ctx, const SchemeData& data) const;
};

}  // namespace redres
