#pragma once
/// @file
/// Objective and constraint plugins, the Context they read, and the QpBuilder they write through.
///
/// A plugin is a `final` class registered by name from its own .cpp. The framework reads the common keys
/// (`type`, `name`, `weight`, `active`), the plugin's constructor reads its own keys from a strict TableReader,
/// and the framework then rejects unknown keys, listing the plugin's keys. Each plugin writes its configuration
/// back with write_config() so that a configuration survives a round trip.
///
/// The public, non-virtual contribute() calls the private virtual add_to() and then validates what the plugin
/// wrote: every entry finite, W symmetric. Bounds are intersected (lo_i = max, hi_i = min) with the plugin as
/// source, so a conflict lo_i > hi_i names the plugins that caused it; the engine reports it as infeasible.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/kinematics.hpp"
#include "redres/qp.hpp"
#include "redres/registry.hpp"

namespace redres {

/// Everything a plugin may read at one control step. New inputs are added here, never to plugin signatures.
struct Context {
  double t = 0.0;    //!< time since the start of the task (s)
  double T = 0.0;    //!< task duration (s)
  double tau = 0.0;  //!< control step (s)
  const RobotModel* robot = nullptr;          //!< the robot
  const KinematicsData* kinematics = nullptr; //!< kinematics at theta (f, J, dJ, w, grad w, ...)
  const Eigen::VectorXd* r_d = nullptr;       //!< desired task coordinates r_d(t) (m_task)
  const Eigen::VectorXd* r_d_dot = nullptr;   //!< desired task velocity r_d_dot(t) (m_task)

  /// Joint positions theta (n).
  [[nodiscard]] const Eigen::VectorXd& theta() const { return kinematics->theta; }
};

/// Writes one plugin's contributions into the QP. The framework positions it on the plugin's rows and weight.
class QpBuilder {
 public:
  /// Builds into `qp`, which must be sized.
  explicit QpBuilder(QpProblem& qp) : qp_(&qp) {}

  /// W += weight * scale * I.
  void add_identity(double scale = 1.0);
  /// W += weight * diag(diagonal).
  void add_diagonal(const Eigen::Ref<const Eigen::VectorXd>& diagonal);
  /// W += weight * H (H symmetric); marks W as non-diagonal when H has off-diagonal entries.
  void add_hessian(const Eigen::Ref<const Eigen::MatrixXd>& H);
  /// zeta += weight * z.
  void add_linear(const Eigen::Ref<const Eigen::VectorXd>& z);
  /// This plugin's equality rows of J (rows x n) and d; the plugin overwrites them.
  [[nodiscard]] Eigen::Block<Eigen::MatrixXd> equality_matrix() { return qp_->J.middleRows(eq_offset_, eq_rows_); }
  [[nodiscard]] Eigen::VectorBlock<Eigen::VectorXd> equality_rhs() { return qp_->d.segment(eq_offset_, eq_rows_); }
  /// This plugin's inequality rows of A (rows x n) and b (A x <= b).
  [[nodiscard]] Eigen::Block<Eigen::MatrixXd> inequality_matrix() { return qp_->A.middleRows(in_offset_, in_rows_); }
  [[nodiscard]] Eigen::VectorBlock<Eigen::VectorXd> inequality_rhs() { return qp_->b.segment(in_offset_, in_rows_); }
  /// lo = max(lo, lower), hi = min(hi, upper), entry-wise, remembering this plugin as the source of each change.
  void intersect_bounds(const Eigen::Ref<const Eigen::VectorXd>& lower, const Eigen::Ref<const Eigen::VectorXd>& upper);
  /// The same for one joint.
  void intersect_bound(int joint, double lower, double upper);
  /// An n-vector of workspace (contents undefined on entry), so that contributions need no allocation.
  [[nodiscard]] Eigen::VectorXd& scratch() noexcept { return qp_->scratch; }
  /// The plugin's weight.
  [[nodiscard]] double weight() const noexcept { return weight_; }
  /// The QP being built (read access).
  [[nodiscard]] const QpProblem& problem() const noexcept { return *qp_; }

  /// Framework use: positions the builder on one plugin.
  void begin(int source, double weight, int eq_offset, int eq_rows, int in_offset, int in_rows);

 private:
  QpProblem* qp_;
  int source_ = -1;
  double weight_ = 1.0;
  int eq_offset_ = 0, eq_rows_ = 0, in_offset_ = 0, in_rows_ = 0;
};

/// Base of objectives and constraints: the common keys and the configuration round trip.
class Plugin {
 public:
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;
  virtual ~Plugin() = default;

  /// Registry type, e.g. "manipulability".
  [[nodiscard]] const std::string& type() const noexcept { return type_; }
  /// Instance name (default: the type).
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// Weight (objectives scale W and zeta by it; constraints scale their rows, which leaves the solution as is).
  [[nodiscard]] double weight() const noexcept { return weight_; }
  /// Inactive plugins are built but contribute nothing.
  [[nodiscard]] bool active() const noexcept { return active_; }
  /// The kinematics this plugin reads.
  [[nodiscard]] virtual KinematicsLevel kinematics_level() const { return KinematicsLevel::kPosition; }
  /// The full configuration (common keys and the plugin's own), readable by the same factory.
  [[nodiscard]] toml::table config() const;

 protected:
  /// Reads the common keys from `config`.
  explicit Plugin(const TableReader& config);

 private:
  /// Writes the plugin's own keys.
  virtual void write_config(toml::table& out) const = 0;

  std::string type_;
  std::string name_;
  double weight_ = 1.0;
  bool active_ = true;
};

/// An objective adds to W and zeta (weighted).
class Objective : public Plugin {
 public:
  /// Adds this objective's terms and validates them.
  void contribute(const Context& ctx, QpBuilder& builder) const;
  /// A scalar P(theta) whose gradient is the zeta this objective adds per unit weight, where one exists; the
  /// conformance test checks zeta against central differences of it.
  [[nodiscard]] virtual std::optional<double> potential(const Context& ctx) const {
    (void)ctx;
    return std::nullopt;
  }

 protected:
  using Plugin::Plugin;

 private:
  virtual void add_to(const Context& ctx, QpBuilder& builder) const = 0;
};

/// A constraint adds equality rows, inequality rows or bounds.
class Constraint : public Plugin {
 public:
  /// Adds this constraint's rows and bounds and validates them.
  void contribute(const Context& ctx, QpBuilder& builder) const;
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

 protected:
  using Plugin::Plugin;

 private:
  virtual void add_to(const Context& ctx, QpBuilder& builder) const = 0;
};

/// Objective factories receive their table and the robot.
using ObjectiveRegistry = Registry<Objective, const RobotModel&>;
/// Constraint factories receive their table and the robot.
using ConstraintRegistry = Registry<Constraint, const RobotModel&>;
/// The process-wide objective registry.
ObjectiveRegistry& objective_registry();
/// The process-wide constraint registry.
ConstraintRegistry& constraint_registry();

/// Builds an objective from a table (`type` plus keys); unknown types and keys are ConfigErrors.
[[nodiscard]] std::unique_ptr<Objective> make_objective(const TableReader& config, const RobotModel& robot);
/// Builds a constraint from a table.
[[nodiscard]] std::unique_ptr<Constraint> make_constraint(const TableReader& config, const RobotModel& robot);

/// Reads a per-joint parameter given either as one number or as an array of n numbers.
[[nodiscard]] Eigen::VectorXd read_per_joint(const TableReader& config, std::string_view key, double fallback, int n);
/// Writes a per-joint parameter: one number when all entries are equal, an array otherwise.
void write_per_joint(toml::table& out, std::string_view key, const Eigen::VectorXd& values);

}  // namespace redres
