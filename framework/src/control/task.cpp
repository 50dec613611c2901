#include "redres/control/task.hpp"
#include "common/text.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace redres {

void Task::set_mode(TaskMode mode) { mode_ = mode; }

void Task::set_priority(int priority) {
  REDRES_REQUIRE(priority >= 0, "Task::set_priority", "the priority of '" + name() + "' is >= 0");
  priority_ = priority;
}

void Task::set_weight(double weight) {
  REDRES_REQUIRE(std::isfinite(weight) && weight > 0.0, "Task::set_weight",
                 "the weight of '" + name() + "' is finite and > 0");
  weight_ = weight;
}

int Task::inequality_rows() const {
  int count = 0;
  for (int r = 0; r < rows(); ++r) count += (has_lower(r) ? 1 : 0) + (has_upper(r) ? 1 : 0);
  return count;
}

void Task::write_common(toml::table& out) const {
  Plugin::write_common(out);
  out.insert("mode", std::string(config_io::enum_name(mode_)));
  out.insert("priority", priority_);
  out.insert("weight", weight_);
}

void Task::size_rows(TaskTerms& rows_out, int n) const {
  const int k = rows();
  rows_out.J = Eigen::MatrixXd::Zero(k, n);
  rows_out.d = Eigen::VectorXd::Zero(k);
  rows_out.lo = Eigen::VectorXd::Constant(k, -std::numeric_limits<double>::infinity());
  rows_out.hi = Eigen::VectorXd::Constant(k, std::numeric_limits<double>::infinity());
  rows_out.error = Eigen::VectorXd::Zero(k);
}

std::unique_ptr<PluginData> Task::make_data() const {
  auto data = std::make_unique<TaskData>();
  size_rows(data->rows, dof_);
  return data;
}

namespace {
[[gnu::cold]] [[noreturn]] void bad_rows(const Task& task, const char* what, Eigen::Index r, Eigen::Index c, double v) {
  std::ostringstream s;
  s << "task '" << task.name() << "'";
  if (!task.source().empty()) s << " (" << task.source() << ")";
  s << " produced a non-finite " << what << " in row " << r << " ('" << task.row_name(static_cast<int>(r)) << "')";
  if (c >= 0) s << ", column " << c;
  s << ": " << v;
  throw std::invalid_argument(s.str());
}
}  // namespace

REDRES_HOT void Task::evaluate(const Context& ctx, TaskData& data) const {
  evaluate_unchecked(ctx, data);
  const TaskTerms& t = data.rows;
  // One scan; the slow path names the entry.
  double acc = finite_probe(t.J.data(), t.J.size()) + finite_probe(t.error.data(), t.error.size());
  if (mode_ == TaskMode::kInequality) {
    for (Eigen::Index r = 0; r < t.lo.size(); ++r) {
      if (std::isnan(t.lo(r)) || std::isnan(t.hi(r))) bad_rows(*this, "velocity bound", r, -1, t.lo(r) + t.hi(r));
      if (has_lower(static_cast<int>(r))) acc += t.lo(r) * 0.0;
      if (has_upper(static_cast<int>(r))) acc += t.hi(r) * 0.0;
    }
  } else {
    acc += finite_probe(t.d.data(), t.d.size());
  }
  acc += t.damping * 0.0;
  if (acc == 0.0) return;
  for (Eigen::Index c = 0; c < t.J.cols(); ++c) {
    for (Eigen::Index r = 0; r < t.J.rows(); ++r) {
      if (!std::isfinite(t.J(r, c))) bad_rows(*this, "Jacobian entry", r, c, t.J(r, c));
    }
  }
  for (Eigen::Index r = 0; r < t.d.size(); ++r) {
    if (mode_ != TaskMode::kInequality && !std::isfinite(t.d(r))) bad_rows(*this, "target velocity", r, -1, t.d(r));
    if (mode_ == TaskMode::kInequality && has_lower(static_cast<int>(r)) && !std::isfinite(t.lo(r))) {
      bad_rows(*this, "lower velocity bound", r, -1, t.lo(r));
    }
    if (mode_ == TaskMode::kInequality && has_upper(static_cast<int>(r)) && !std::isfinite(t.hi(r))) {
      bad_rows(*this, "upper velocity bound", r, -1, t.hi(r));
    }
    if (!std::isfinite(t.error(r))) bad_rows(*this, "error", r, -1, t.error(r));
  }
  bad_rows(*this, "damping term", 0, -1, t.damping);
}

REDRES_HOT int write_task_terms(const Task& task, const TaskTerms& t, QpBuilder& builder, int slack) {
  const Eigen::Index n = t.J.cols();
  const bool least_squares = slack >= 0;
  switch (task.mode()) {
    case TaskMode::kEquality:
      if (least_squares) {
        builder.add_least_squares(t.J, t.d, task.weight());
      } else {
        // Column by column into the QP's J (column-major, leading dimension m_eq): the end-effector task's rows are
        // written at every step, by a copy as cheap as the rows themselves.
        auto J = builder.equality_matrix();
        const Eigen::Index m = t.J.rows(), ld = J.outerStride();
        const double* from = t.J.data();
        double* to = J.data();
        if (ld == m) {
          std::copy_n(from, m * n, to);
        } else {
          for (Eigen::Index c = 0; c < n; ++c) std::copy_n(from + c * m, m, to + c * ld);
        }
        std::copy_n(t.d.data(), m, builder.equality_rhs().data());
      }
      break;
    case TaskMode::kInequality: {
      auto A = builder.inequality_matrix();
      auto b = builder.inequality_rhs();
      Eigen::Index row = 0;
      for (Eigen::Index r = 0; r < t.J.rows(); ++r) {
        for (int side = 0; side < 2; ++side) {
          const bool upper = side == 0;
          if (upper ? !task.has_upper(static_cast<int>(r)) : !task.has_lower(static_cast<int>(r))) continue;
          if (upper) {
            A.row(row).head(n) = t.J.row(r);
          } else {
            A.row(row).head(n) = -t.J.row(r);
          }
          b(row) = upper ? t.hi(r) : -t.lo(r);
          if (least_squares) {
            A(row, slack) = -1.0;
            builder.set_diagonal(slack, task.weight());
            ++slack;
          }
          ++row;
        }
      }
      break;
    }
    case TaskMode::kSoft:
      builder.add_least_squares(t.J, t.d, task.weight());
      if (t.damping > 0.0) builder.add_identity(task.weight() * t.damping, n);
      break;
  }
  return slack;
}

double smallest_singular_value(const Eigen::Ref<const Eigen::MatrixXd>& J) {
  using M6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  REDRES_REQUIRE(J.rows() <= 6, "smallest_singular_value", "J has at most 6 rows");
  M6 G(J.rows(), J.rows());
  G.noalias() = J.lazyProduct(J.transpose());
  Eigen::SelfAdjointEigenSolver<M6> eig(G, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
}

TaskRegistry& task_registry() {
  static TaskRegistry registry("task");
  return registry;
}

namespace {

struct TaskCommon {
  std::optional<std::string> name;
  bool active = true;
  TaskMode mode = TaskMode::kEquality;
  int priority = 0;
  double weight = 1.0;
  static const Schema<TaskCommon>& schema() {
    static const Schema<TaskCommon> s{
        {field("name", &TaskCommon::name, "",
               "instance name, used in diagnoses and output columns (default: the type)"),
         field("active", &TaskCommon::active, "", "false builds the task but leaves it out of the QP"),
         field("mode", &TaskCommon::mode, "",
               "\"equality\" (hard rows J x = d), \"soft\" (weighted least squares in the objective) or "
               "\"inequality\" (lower <= value <= upper)"),
         field("priority", &TaskCommon::priority, "",
               "its level: 0 is the highest; each level keeps the optima of "
               "the levels above it",
               between<int>(0, 100)),
         field("weight", &TaskCommon::weight, "",
               "the weight of its least squares (soft mode; and where a lower level cannot meet it)",
               between(1e-12, 1e12))}};
    return s;
  }
};

}  // namespace

const std::vector<KeyInfo>& task_common_keys() {
  static const std::vector<KeyInfo> keys = describe_keys(TaskCommon::schema());
  return keys;
}

std::unique_ptr<Task> make_task(const TableReader& config, const RobotModel& robot) {
  TaskCommon common;
  read_config(config, TaskCommon::schema(), common);
  // The mode is read before the type's own keys: a task's reader checks its keys against it.
  auto p = task_registry().create(config, robot);
  config.finish();
  if (common.name) {
    if (common.name->empty()) config.fail("name", "expected a non-empty name");
    if (const std::string why = column_name_problem(*common.name); !why.empty()) config.fail("name", why);
    p->set_name(*common.name);
  }
  p->set_active(common.active);
  p->set_mode(common.mode);
  p->set_priority(common.priority);
  p->set_weight(common.weight);
  try {
    p->check_mode();
  } catch (const FieldError& e) {
    rethrow_at(config, e);
  }
  return p;
}

}  // namespace redres
