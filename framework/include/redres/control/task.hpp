#pragma once
/// @file
/// Task plugins (`[[tasks]]` in a scenario; docs/tasks.md): rows J x ~ d on any frame or on the joints, each with a
/// mode and a priority.
///
/// A task computes, once per step, its rows J (rows x n) and per row either a target velocity d (modes `equality` and
/// `soft`) or velocity bounds lo <= J x <= hi (mode `inequality`). The scheme maps them onto its QP:
/// - `equality`: the rows J x = d, hard;
/// - `soft`: the weighted least squares (weight / 2) |J x - d|^2 in the objective: W += weight J'J, zeta -= weight J'd;
/// - `inequality`: the rows J x <= hi and -J x <= -lo where those bounds are finite.
/// Tasks and objectives carry a `priority` (0 the highest). With one priority everything goes into one QP; with
/// several, the controller solves one QP per level, each keeping the higher levels' optima (control/cascade.hpp).
///
/// A task's rows live in its TaskData (made by make_data(), owned by the controller), so several levels read them
/// without computing them again, and the run's outputs read its error there.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "redres/control/plugin.hpp"

namespace redres {

/// How a task's rows enter the QP.
enum class TaskMode { kEquality, kSoft, kInequality };
inline const std::vector<std::pair<TaskMode, const char*>>& enum_names(TaskMode) {
  static const std::vector<std::pair<TaskMode, const char*>> names{
      {TaskMode::kEquality, "equality"}, {TaskMode::kSoft, "soft"}, {TaskMode::kInequality, "inequality"}};
  return names;
}

/// One step's rows of a task, sized at setup.
struct TaskTerms {
  Eigen::MatrixXd J;       //!< rows x n
  Eigen::VectorXd d;       //!< target velocity of each row (equality, soft)
  Eigen::VectorXd lo;      //!< lower velocity bound of each row (inequality; -inf where open)
  Eigen::VectorXd hi;      //!< upper velocity bound of each row (inequality; +inf where open)
  Eigen::VectorXd error;   //!< each row's error this step: reference - value (equality, soft), or how far the value
                           //!< is outside its bounds (inequality; 0 inside)
  double damping = 0.0;    //!< lambda^2 this step: the Levenberg-Marquardt term the task adds (soft tasks only)
  double sigma_min = 0.0;  //!< the smallest singular value of J this step (tasks with damping; else 0)
};

/// A task's data for one controller: its rows, and what the task itself keeps (derive from it for more).
class TaskData : public PluginData {
 public:
  TaskTerms rows;
};

/// Base of task plugins.
class Task : public Plugin {
 public:
  [[nodiscard]] TaskMode mode() const noexcept { return mode_; }
  void set_mode(TaskMode mode);
  /// 0 is the highest priority.
  [[nodiscard]] int priority() const noexcept { return priority_; }
  void set_priority(int priority);
  /// The weight of a soft task's least squares; also an equality or inequality task's when a lower level cannot meet
  /// it and solves it in least squares (docs/tasks.md). > 0.
  [[nodiscard]] double weight() const noexcept { return weight_; }
  void set_weight(double weight);

  /// Number of rows (fixed at construction).
  [[nodiscard]] virtual int rows() const = 0;
  /// Row r's name, e.g. "x" or "wz" (for diagnoses and outputs).
  [[nodiscard]] virtual std::string row_name(int r) const = 0;
  /// Inequality mode: whether row r has a lower (upper) bound (fixed at construction).
  [[nodiscard]] virtual bool has_lower(int r) const {
    (void)r;
    return false;
  }
  [[nodiscard]] virtual bool has_upper(int r) const {
    (void)r;
    return false;
  }
  /// The QP inequality rows it writes in inequality mode: one per finite bound.
  [[nodiscard]] int inequality_rows() const;
  /// The rows' units, e.g. "m" (position rows) or "rad".
  [[nodiscard]] virtual std::string row_unit(int r) const = 0;

  /// Makes this task's data (a TaskData, rows sized for `n` joints). Overrides return their own TaskData-derived
  /// class, sized with size_rows().
  [[nodiscard]] std::unique_ptr<PluginData> make_data() const override;
  /// Computes this step's rows into `data` (what make_data() made) and checks them: every entry finite, else
  /// std::invalid_argument naming the task, the row and the entry. Allocation-free.
  void evaluate(const Context& ctx, TaskData& data) const;
  /// The same without the check, for a caller that scans the rows where it writes them (a constraint's QP rows,
  /// which Scheme::check_built() scans and, should an entry be non-finite, names by plugin and row).
  void evaluate_unchecked(const Context& ctx, TaskData& data) const {
    data.rows.damping = 0.0;
    compute(ctx, data);
  }

  /// Checks the task's own keys against its mode (e.g. `lower` only with mode = "inequality"); throws FieldError
  /// naming the key. make_task() calls it once the common keys are set. Default: nothing.
  virtual void check_mode() const {}

  /// Sizes `rows` for this task on a robot of n joints.
  void size_rows(TaskTerms& rows, int n) const;

 protected:
  using Plugin::Plugin;
  /// Writes `type`, `name`, `active`, `mode`, `priority` and `weight`.
  void write_common(toml::table& out) const override;
  /// The robot's number of joints (a task's constructor sets it).
  [[nodiscard]] int dof() const noexcept { return dof_; }
  void set_dof(int n) noexcept { dof_ = n; }

 private:
  /// Writes J, d (equality, soft) or lo, hi (inequality), and error into data.rows.
  virtual void compute(const Context& ctx, TaskData& data) const = 0;

  TaskMode mode_ = TaskMode::kEquality;
  int priority_ = 0;
  double weight_ = 1.0;
  int dof_ = 0;
};

/// Task factories receive their Config and the robot.
using TaskRegistry = Registry<Task, const RobotModel&>;
/// The process-wide task registry.
TaskRegistry& task_registry();
/// The keys every task takes besides its own (`name`, `active`, `mode`, `priority`, `weight`).
[[nodiscard]] const std::vector<KeyInfo>& task_common_keys();
/// Builds a task from a [[tasks]] table; strict.
[[nodiscard]] std::unique_ptr<Task> make_task(const TableReader& config, const RobotModel& robot);

/// The one writer of a task's terms into a QP, at any priority level (Scheme::build's one QP and each level of a
/// Cascade), with `builder` positioned on its rows (equality: rows(); inequality: inequality_rows()). By its mode:
/// equality rows J x = d; inequality rows J_r x <= hi_r and -J_r x <= -lo_r (each finite bound, in row order, upper
/// first); soft: the least squares (weight / 2) |J x - d|^2 plus its damping on the joints' diagonal of W.
/// With `slack` >= 0 (a lower level that cannot meet its tasks, solved in least squares; control/cascade.hpp): an
/// equality task's rows become the least squares (weight / 2) |J x - d|^2 and write no row, and each inequality row
/// gets its own slack variable s, from column `slack` on (J_r x - s <= hi_r, W_ss = weight). Returns the next free
/// slack column (`slack` when it used none). The joints are the QP's first J.cols() variables.
int write_task_terms(const Task& task, const TaskTerms& terms, QpBuilder& builder, int slack = -1);

/// The smallest singular value of a task's k x n rows J (k <= 6), from the eigenvalues of J J' (allocation-free).
[[nodiscard]] double smallest_singular_value(const Eigen::Ref<const Eigen::MatrixXd>& J);

/// The Levenberg-Marquardt term of a task whose rows' smallest singular value is sigma: lambda_max^2 (1 - (sigma /
/// threshold)^2) below the threshold, 0 above it.
[[nodiscard]] inline double damping_term(double sigma, double lambda_max, double threshold) {
  if (!(lambda_max > 0.0) || !(sigma < threshold)) return 0.0;
  const double r = sigma / threshold;
  return lambda_max * lambda_max * (1.0 - r * r);
}

}  // namespace redres
