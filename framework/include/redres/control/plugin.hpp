#pragma once
/// @file
/// Objective and constraint plugins.
///
/// A plugin is a class with a typed Config (config.hpp), built from C++ or by name from its registry:
///
///   auto m = std::make_unique<Manipulability>(Manipulability::Config{.p = 2.0}, robot);
///   auto c = constraint_registry().create("joint_angle_margin", JointAngleMargin::Config{.kappa = 4.0}, robot);
///   auto t = objective_registry().create(table_reader, robot);   // from a [[objectives]] table
///
/// Common to every instance, outside its Config: the instance `name` (default: the type; used in diagnoses), and
/// `active` (false builds it but leaves it out of the QP). Objectives also have a `weight` >= 0 that scales W and
/// zeta. Constraints are hard and have no weight: a `weight` key on a constraint is rejected.
///
/// The public, non-virtual contribute() calls the private virtual add_to() and then validates what the plugin
/// wrote: every entry finite, W symmetric. Bounds are intersected (lo_i = max, hi_i = min) with the plugin as
/// source, so a conflict lo_i > hi_i names the plugins that caused it; the engine reports it as infeasible.
///
/// Model and data. A plugin is immutable once built: everything a step writes (distances, broadphase state, scratch
/// matrices) lives in the plugin's PluginData, which the plugin makes (make_data()) for each controller and the
/// controller owns and hands back at every step. One scheme can so serve several controllers, each in its own
/// thread. What a plugin adds to a run's outputs (trajectory columns, summary figures, obstacles) is not part of
/// this interface: see run/plugin_output.hpp.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/common/text_sink.hpp"
#include "redres/config/config.hpp"
#include "redres/config/registry.hpp"
#include "redres/control/context.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/qp/qp_builder.hpp"

namespace redres {

/// One controller's state and scratch of one plugin: derive a plugin's own data from it, and make it in
/// Plugin::make_data(). The controller owns it and passes it to every call that a step makes.
class PluginData {
 public:
  PluginData() = default;
  PluginData(const PluginData&) = delete;
  PluginData& operator=(const PluginData&) = delete;
  virtual ~PluginData() = default;
};

/// Plugin data that is workspace only: `count` vectors of n entries, sized when it is made, their contents undefined
/// at each step. A plugin whose add_to needs temporaries and keeps nothing between steps returns one from make_data()
/// (std::make_unique<Workspace>(n, count)) and reads it as static_cast<Workspace&>(*data)[k]: no allocation per step,
/// and nothing shared with another plugin or another controller.
class Workspace final : public PluginData {
 public:
  Workspace(int n, int count) : vectors_(static_cast<std::size_t>(count), Eigen::VectorXd::Zero(n)) {}
  [[nodiscard]] Eigen::VectorXd& operator[](std::size_t k) { return vectors_[k]; }

 private:
  std::vector<Eigen::VectorXd> vectors_;
};

/// Base of objectives and constraints: type, instance name, active flag and the configuration round trip.
class Plugin {
 public:
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;
  virtual ~Plugin() = default;

  /// Registry type, e.g. "manipulability".
  [[nodiscard]] const std::string& type() const noexcept { return type_; }
  /// Instance name (default: the type).
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// Renames the instance (non-empty).
  void set_name(std::string name);
  /// Where the plugin was configured ("file:line:col" of its table), for diagnoses; empty for a plugin built in
  /// code. Scheme::from_toml sets it.
  [[nodiscard]] const std::string& source() const noexcept { return source_; }
  void set_source(std::string source) { source_ = std::move(source); }
  /// Checks what can be checked once the run's duration T and step tau are known, e.g. a formula of t at every
  /// step time; throws FieldError naming the key. Called at load (Scheme::from_toml with run times). Default: none.
  virtual void check_run(double T, double tau) const {
    (void)T;
    (void)tau;
  }
  /// Inactive plugins are built but contribute nothing.
  [[nodiscard]] bool active() const noexcept { return active_; }
  void set_active(bool active) noexcept { active_ = active; }
  /// Whether this plugin works at a control order (Context::order). Default: the velocity level only; a plugin that
  /// also serves the acceleration level reads Context::order and writes its terms for x = theta_ddot there.
  [[nodiscard]] virtual bool supports(ControlOrder order) const { return order == ControlOrder::kVelocity; }
  /// The kinematics this plugin reads.
  [[nodiscard]] virtual KinematicsLevel kinematics_level() const { return KinematicsLevel::kPosition; }
  /// The full configuration (type, common keys and the plugin's own), readable by the same registry.
  [[nodiscard]] toml::table config() const;
  /// Makes this plugin's data for one controller (at setup; may allocate). Default: none (nullptr), for a plugin
  /// whose steps keep no state and need no scratch.
  [[nodiscard]] virtual std::unique_ptr<PluginData> make_data() const { return nullptr; }
  /// Called when a run starts, before its first step, and again after Controller::reset(): forget what `data` holds
  /// from an earlier run (a filter's state, a previous command of your own). `data` is what make_data() made (may be
  /// null). Allocation-free. Default: nothing.
  virtual void start(PluginData* data) const { (void)data; }
  /// Whether the state at the last contribution (recorded in `data`, what make_data() made) breaks what this plugin
  /// guards (e.g. two bodies overlap). The simulation counts such a step as failed, with describe_violation() in
  /// its diagnosis. Allocation-free.
  [[nodiscard]] virtual bool violated(const PluginData* data) const {
    (void)data;
    return false;
  }
  /// What is violated, e.g. "link 'j3' ... vs obstacle 1 overlap by 0.004 m" (called only when violated()).
  [[nodiscard]] virtual std::string describe_violation(const PluginData* data) const {
    (void)data;
    return {};
  }

 protected:
  explicit Plugin(std::string type);
  /// Writes `type`, `name`, `active` (objectives add `weight`).
  virtual void write_common(toml::table& out) const;

 private:
  /// Writes the plugin's own keys.
  virtual void write_config(toml::table& out) const = 0;

  std::string type_;
  std::string name_;
  std::string source_;
  bool active_ = true;
};

/// An objective adds to W and zeta (weighted).
class Objective : public Plugin {
 public:
  /// Weight >= 0 (scales W and zeta).
  [[nodiscard]] double weight() const noexcept { return weight_; }
  /// Sets the weight; std::invalid_argument unless finite and >= 0.
  void set_weight(double weight);
  /// Its priority level (0, the default, is the highest; docs/tasks.md): with tasks or objectives at several
  /// priorities the controller solves one QP per level.
  [[nodiscard]] int priority() const noexcept { return priority_; }
  /// Sets the priority; std::invalid_argument unless >= 0.
  void set_priority(int priority);
  /// Adds this objective's terms and validates them. `data` is what make_data() made for the calling controller.
  void contribute(const Context& ctx, QpBuilder& builder, PluginData* data) const;
  /// Framework use (Scheme::build): adds the terms without validating them; the caller checks the whole QP after
  /// every plugin has written, and builds it again through contribute() to name a culprit.
  void contribute_unchecked(const Context& ctx, QpBuilder& builder, PluginData* data) const {
    if (active()) add_to(ctx, builder, data);
  }
  /// A scalar P(theta) whose gradient is the zeta this objective adds per unit weight, where one exists; the
  /// conformance checks compare zeta with central differences of it.
  [[nodiscard]] virtual std::optional<double> potential(const Context& ctx) const {
    (void)ctx;
    return std::nullopt;
  }

 protected:
  using Plugin::Plugin;

 private:
  void write_common(toml::table& out) const override;
  /// Adds W and zeta for this step; `data` is this controller's make_data() (nullptr when it makes none).
  virtual void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const = 0;

  double weight_ = 1.0;
  int priority_ = 0;
};

/// A constraint adds equality rows, inequality rows or bounds.
class Constraint : public Plugin {
 public:
  /// Adds this constraint's rows and bounds and validates them. `data` is what make_data() made for the caller.
  void contribute(const Context& ctx, QpBuilder& builder, PluginData* data) const;
  /// Framework use (Scheme::build): as Objective::contribute_unchecked.
  void contribute_unchecked(const Context& ctx, QpBuilder& builder, PluginData* data) const {
    if (active()) add_to(ctx, builder, data);
  }
  /// Whether its bounds yield to every other constraint's: the scheme adds it after them, and it writes its bounds
  /// with QpBuilder::yield_bounds(), which clips them to the bounds already there (joint_jerk_limits: a smoothness
  /// limit that gives way to position, velocity and acceleration bounds instead of making the step infeasible).
  [[nodiscard]] virtual bool yields_bounds() const { return false; }
  /// Number of equality rows it writes (fixed at setup).
  [[nodiscard]] virtual int equality_rows(const RobotModel& robot) const {
    (void)robot;
    return 0;
  }
  /// Number of inequality rows it writes (fixed at setup).
  [[nodiscard]] virtual int inequality_rows(const RobotModel& robot) const {
    (void)robot;
    return 0;
  }
  /// What its inequality row `row` (0-based, its own numbering) stood for at the last contribution (in `data`),
  /// for the diagnosis of a failed solve (e.g. the collision pair and its distance). Default: nothing.
  [[nodiscard]] virtual std::string describe_inequality_row(const PluginData* data, int row) const {
    (void)data;
    (void)row;
    return {};
  }
  /// The same, written into a failed step's diagnosis: what the diagnosis calls. Default: writes
  /// describe_inequality_row(), whose string allocates; a plugin that writes its text here with `out << ...`
  /// (TextSink: strings and numbers, no allocation) keeps its failed steps allocation-free.
  virtual void describe_inequality_row_to(const PluginData* data, int row, TextSink& out) const {
    out << describe_inequality_row(data, row);
  }

 protected:
  using Plugin::Plugin;

 private:
  /// Adds rows and bounds for this step; `data` is this controller's make_data() (nullptr when it makes none).
  virtual void add_to(const Context& ctx, QpBuilder& builder, PluginData* data) const = 0;
};

/// Objective factories receive their Config and the robot.
using ObjectiveRegistry = Registry<Objective, const RobotModel&>;
/// Constraint factories receive their Config and the robot.
using ConstraintRegistry = Registry<Constraint, const RobotModel&>;
/// The process-wide objective registry.
ObjectiveRegistry& objective_registry();
/// The process-wide constraint registry.
ConstraintRegistry& constraint_registry();

/// The keys every objective takes besides its own (`name`, `weight`, `priority`, `active`).
[[nodiscard]] const std::vector<KeyInfo>& objective_common_keys();
/// The keys every constraint takes besides its own (`name`, `active`).
[[nodiscard]] const std::vector<KeyInfo>& constraint_common_keys();

/// Builds an objective from an [[objectives]] table (`type`, common keys, the type's keys); strict.
[[nodiscard]] std::unique_ptr<Objective> make_objective(const TableReader& config, const RobotModel& robot);
/// Builds a constraint from a [[constraints]] table.
[[nodiscard]] std::unique_ptr<Constraint> make_constraint(const TableReader& config, const RobotModel& robot);

}  // namespace redres
