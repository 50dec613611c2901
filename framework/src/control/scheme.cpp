#include "redres/control/scheme.hpp"
#include "redres/common/hot.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string_view>

namespace redres {

namespace {
// The plugins, owned as const from here on.
template <class T>
std::vector<std::unique_ptr<const T>> frozen(std::vector<std::unique_ptr<T>> plugins) {
  std::vector<std::unique_ptr<const T>> out;
  out.reserve(plugins.size());
  for (auto& p : plugins) out.push_back(std::move(p));
  return out;
}
}  // namespace

Scheme::Scheme(const RobotModel& robot, std::vector<std::unique_ptr<Objective>> objectives,
               std::vector<std::unique_ptr<Constraint>> constraints, ControlOrder order)
    : Scheme(robot, std::move(objectives), std::move(constraints), {}, order) {}

Scheme::Scheme(const RobotModel& robot, std::vector<std::unique_ptr<Objective>> objectives,
               std::vector<std::unique_ptr<Constraint>> constraints, std::vector<std::unique_ptr<Task>> tasks,
               ControlOrder order)
    : robot_(&robot),
      objectives_(frozen(std::move(objectives))),
      constraints_(frozen(std::move(constraints))),
      tasks_(frozen(std::move(tasks))),
      order_(order) {
  std::set<std::string> names;
  // Every plugin: present, uniquely named, working at the scheme's order; the scheme reads the deepest kinematics.
  const auto admit = [&](const Plugin* p, const char* kind) {
    REDRES_REQUIRE(p != nullptr, "Scheme", std::string("every ") + kind + " is non-null");
    REDRES_REQUIRE(names.insert(p->name()).second, "Scheme",
                   "plugin names are unique (two are named '" + p->name() + "'; rename one with set_name())");
    kinematics_level_ = std::max(kinematics_level_, p->kinematics_level());
    if (!p->active() || p->supports(order)) return;
    throw std::invalid_argument(std::string(kind) + " '" + p->name() + "' (type " + p->type() +
                                ") does not work at the " +
                                (order == ControlOrder::kAcceleration ? "acceleration" : "velocity") +
                                " level ([scheme] level); docs/motion.md lists the plugins that do");
  };
  for (const auto& o : objectives_) admit(o.get(), "objective");
  for (const auto& c : constraints_) {
    admit(c.get(), "constraint");
    const int e = c->equality_rows(robot);
    const int i = c->inequality_rows(robot);
    REDRES_REQUIRE(e >= 0 && i >= 0, "Scheme", "constraint '" + c->name() + "' declares non-negative row counts");
    eq_offset_.push_back(m_eq_);
    eq_rows_.push_back(e);
    in_offset_.push_back(m_in_);
    in_rows_.push_back(i);
    m_eq_ += e;
    m_in_ += i;
  }
  for (int yielding = 0; yielding < 2; ++yielding) {
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
      if (constraints_[k]->yields_bounds() == (yielding == 1)) constraint_order_.push_back(k);
    }
  }
  m_eq_c_ = m_eq_;
  m_in_c_ = m_in_;
  for (const auto& t : tasks_) {
    admit(t.get(), "task");
    task_active_.push_back(t->active());
  }
  // The levels: the active objectives' and tasks' priorities, highest (0) first.
  std::set<int> priorities;
  for (const auto& o : objectives_) {
    if (o->active()) priorities.insert(o->priority());
  }
  for (const auto& t : tasks_) {
    if (t->active()) priorities.insert(t->priority());
  }
  if (priorities.empty()) priorities.insert(0);
  for (int p : priorities) {
    SchemeLevelSpec spec;
    spec.priority = p;
    for (std::size_t k = 0; k < objectives_.size(); ++k) {
      if (objectives_[k]->active() && objectives_[k]->priority() == p) spec.objectives.push_back(static_cast<int>(k));
    }
    for (std::size_t k = 0; k < tasks_.size(); ++k) {
      if (tasks_[k]->active() && tasks_[k]->priority() == p) spec.tasks.push_back(static_cast<int>(k));
    }
    levels_.push_back(std::move(spec));
  }
  // One level: the tasks' rows follow the constraints' in the one QP.
  for (std::size_t k = 0; k < tasks_.size(); ++k) {
    const Task& t = *tasks_[k];
    const bool in_qp = !cascaded() && task_active_[k];
    const int e = in_qp && t.mode() == TaskMode::kEquality ? t.rows() : 0;
    const int i = in_qp && t.mode() == TaskMode::kInequality ? t.inequality_rows() : 0;
    task_eq_offset_.push_back(m_eq_);
    task_eq_rows_.push_back(e);
    task_in_offset_.push_back(m_in_);
    task_in_rows_.push_back(i);
    m_eq_ += e;
    m_in_ += i;
  }
  // The acceleration level's task reads J_dot theta_dot = sum_i theta_dot_i dJ/dtheta_i theta_dot.
  if (order == ControlOrder::kAcceleration) {
    kinematics_level_ = std::max(kinematics_level_, KinematicsLevel::kManipulability);
  }
}

Scheme Scheme::from_toml(const TableReader& root, const RobotModel& robot, double duration, double step) {
  std::vector<std::unique_ptr<Objective>> objectives;
  std::vector<std::unique_ptr<Constraint>> constraints;
  std::vector<std::unique_ptr<Task>> tasks;
  std::set<std::string> names;
  const auto unique = [&](const TableReader& t, Plugin& p) {
    if (!names.insert(p.name()).second) {
      t.fail("name", "duplicate plugin name '" + p.name() + "'; give one of them a different `name`");
    }
    p.set_source(t.location().str());
    if (duration > 0.0 && step > 0.0) {
      try {
        p.check_run(duration, step);
      } catch (const FieldError& e) {
        rethrow_at(t, e);
      }
    }
  };
  if (root.has("objectives")) {
    for (const TableReader& t : root.tables("objectives")) {
      objectives.push_back(make_objective(t, robot));
      unique(t, *objectives.back());
    }
  }
  if (root.has("constraints")) {
    for (const TableReader& t : root.tables("constraints")) {
      constraints.push_back(make_constraint(t, robot));
      unique(t, *constraints.back());
    }
  }
  if (root.has("tasks")) {
    for (const TableReader& t : root.tables("tasks")) {
      tasks.push_back(make_task(t, robot));
      unique(t, *tasks.back());
    }
  }
  if (objectives.empty()) root.fail("expected at least one [[objectives]] entry (e.g. type = \"min_velocity_norm\")");
  // The robot file's acceleration and jerk limits hold in every run: a scheme that lists no constraint for them gets
  // one (docs/motion.md).
  const auto listed = [&constraints](std::string_view type) {
    return std::any_of(constraints.begin(), constraints.end(), [type](const auto& c) { return c->type() == type; });
  };
  const auto add_default = [&](const char* type) {
    auto doc = std::make_shared<TomlFile>();
    doc->path = root.file_ptr() ? root.file_ptr()->path : std::filesystem::path();
    doc->root.insert("type", type);
    auto c = make_constraint(TableReader::root(doc, "constraints"), robot);
    c->set_source("the robot file's limits (added: the scenario lists no " + std::string(type) + ")");
    if (names.insert(c->name()).second) constraints.push_back(std::move(c));
  };
  if (robot.has_acceleration_limits() && !listed("joint_acceleration_limits")) add_default("joint_acceleration_limits");
  if (robot.has_jerk_limits() && !listed("joint_jerk_limits")) add_default("joint_jerk_limits");
  ControlOrder order = ControlOrder::kVelocity;
  if (root.has("scheme")) {
    const TableReader t = root.table("scheme");
    const TableReader scheme(t.file_ptr(), t.raw(), "scheme");
    SchemeTable table;
    read_config(scheme, SchemeTable::schema(), table);
    scheme.finish();
    order = table.order;
    const double eps = table.regularization;
    try {
      Scheme out(robot, std::move(objectives), std::move(constraints), std::move(tasks), order);
      out.set_regularization(eps);
      return out;
    } catch (const std::invalid_argument& e) {
      scheme.fail("level", e.what());
    }
  }
  return Scheme(robot, std::move(objectives), std::move(constraints), std::move(tasks), order);
}

static_assert(SchemeTable{}.regularization == Scheme::kDefaultRegularization, "one default of the regularization");

const Schema<SchemeTable>& SchemeTable::schema() {
  using C = SchemeTable;
  static const Schema<C> s{
      {field(
           "level", &C::order, "",
           "what x is: \"velocity\" (x = theta_dot, the paper's) or \"acceleration\" (x = theta_ddot; docs/motion.md)"),
       field("regularization", &C::regularization, "",
             "the eps |x|^2 / 2 that every priority level adds to its QP (docs/tasks.md)",
             rule<double>("a number in (0, 1]", [](double eps) { return eps > 0.0 && eps <= 1.0; }))}};
  return s;
}

void Scheme::set_regularization(double eps) {
  REDRES_REQUIRE(std::isfinite(eps) && eps > 0.0, "Scheme::set_regularization", "eps > 0 and finite");
  regularization_ = eps;
}

SchemeData Scheme::make_data() const {
  SchemeData data;
  for (const auto& o : objectives_) data.objectives.push_back(o->make_data());
  for (const auto& c : constraints_) data.constraints.push_back(c->make_data());
  for (const auto& t : tasks_) data.tasks.push_back(t->make_data());
  return data;
}

void Scheme::start(SchemeData& data) const {
  REDRES_REQUIRE(data.objectives.size() == objectives_.size() && data.constraints.size() == constraints_.size() &&
                     data.tasks.size() == tasks_.size(),
                 "Scheme::start", "data was made by this scheme's make_data()");
  for (std::size_t k = 0; k < objectives_.size(); ++k) objectives_[k]->start(data.objectives[k].get());
  for (std::size_t k = 0; k < constraints_.size(); ++k) constraints_[k]->start(data.constraints[k].get());
  for (std::size_t k = 0; k < tasks_.size(); ++k) tasks_[k]->start(data.tasks[k].get());
}

void Scheme::name_sources(QpProblem& qp, const SchemeData& data) const {
  REDRES_REQUIRE(data.objectives.size() == objectives_.size() && data.constraints.size() == constraints_.size() &&
                     data.tasks.size() == tasks_.size(),
                 "Scheme::setup", "data was made by this scheme's make_data()");
  qp.source_names.clear();
  qp.variable_names.clear();
  for (const auto& j : robot_->joints()) qp.variable_names.push_back(j.name);
  for (const auto& o : objectives_) qp.source_names.push_back(o->name());
  for (const auto& c : constraints_) qp.source_names.push_back(c->name());
  for (const auto& t : tasks_) qp.source_names.push_back("task '" + t->name() + "'");
  const int base = static_cast<int>(objectives_.size());
  // The constraints' data, by the vector's storage: it stays where it is when the SchemeData itself is moved.
  const std::unique_ptr<PluginData>* own = data.constraints.data();
  qp.in_row_description = [this, own](int row, TextSink& out) {
    for (std::size_t k = 0; k < constraints_.size(); ++k) {
      if (row >= in_offset_[k] && row < in_offset_[k] + in_rows_[k]) {
        constraints_[k]->describe_inequality_row_to(own[k].get(), row - in_offset_[k], out);
        return;
      }
    }
    for (std::size_t k = 0; k < tasks_.size(); ++k) {
      if (row >= task_in_offset_[k] && row < task_in_offset_[k] + task_in_rows_[k]) {
        out << "task '" << tasks_[k]->name() << "' bound " << row - task_in_offset_[k] + 1;
        return;
      }
    }
  };
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    for (int r = 0; r < eq_rows_[k]; ++r)
      qp.eq_source[static_cast<std::size_t>(eq_offset_[k] + r)] = base + static_cast<int>(k);
    for (int r = 0; r < in_rows_[k]; ++r)
      qp.in_source[static_cast<std::size_t>(in_offset_[k] + r)] = base + static_cast<int>(k);
  }
}

void Scheme::setup(QpProblem& qp, const SchemeData& data) const {
  qp.resize(robot_->dof(), m_eq_, m_in_);
  name_sources(qp, data);
  for (std::size_t k = 0; k < tasks_.size(); ++k) {
    for (int r = 0; r < task_eq_rows_[k]; ++r)
      qp.eq_source[static_cast<std::size_t>(task_eq_offset_[k] + r)] = task_source(k);
    for (int r = 0; r < task_in_rows_[k]; ++r)
      qp.in_source[static_cast<std::size_t>(task_in_offset_[k] + r)] = task_source(k);
  }
}

void Scheme::setup_constraints(QpProblem& qp, const SchemeData& data) const {
  qp.resize(robot_->dof(), m_eq_c_, m_in_c_);
  name_sources(qp, data);
}

REDRES_HOT void Scheme::build(const Context& ctx, QpProblem& qp, SchemeData& data) const {
  REDRES_REQUIRE(!cascaded(), "Scheme::build",
                 "the scheme has one priority level (with several, the Controller solves one QP per level)");
  REDRES_REQUIRE(qp.n() == robot_->dof() && qp.m_eq() == m_eq_ && qp.m_in() == m_in_, "Scheme::build",
                 "qp was sized by setup()");
  check_inputs(ctx, data);
  const bool full_w = contribute_all(ctx, qp, data, false);
  check_built(ctx, qp, data, full_w, false);
}

void Scheme::build_constraints(const Context& ctx, QpProblem& qp, SchemeData& data) const {
  REDRES_REQUIRE(qp.n() == robot_->dof() && qp.m_eq() == m_eq_c_ && qp.m_in() == m_in_c_, "Scheme::build_constraints",
                 "qp was sized by setup_constraints()");
  check_inputs(ctx, data);
  const bool full_w = contribute_all(ctx, qp, data, false, true);
  check_built(ctx, qp, data, full_w, true);
}

void Scheme::evaluate_tasks(const Context& ctx, SchemeData& data) const {
  check_inputs(ctx, data);
  for (std::size_t k = 0; k < tasks_.size(); ++k) {
    if (task_active_[k]) tasks_[k]->evaluate(ctx, static_cast<TaskData&>(*data.tasks[k]));
  }
}

QpBuilder::WrittenW Scheme::build_objectives(const Context& ctx, int level, QpProblem& qp, SchemeData& data) const {
  REDRES_REQUIRE(level >= 0 && level < static_cast<int>(levels_.size()) && qp.n() == robot_->dof(),
                 "Scheme::build_objectives", "0 <= level < levels().size() and qp has n variables");
  qp.clear();
  QpBuilder builder(qp);
  QpBuilder::WrittenW written = QpBuilder::WrittenW::kNone;
  for (int k : levels_[static_cast<std::size_t>(level)].objectives) {
    const Objective& o = *objectives_[static_cast<std::size_t>(k)];
    builder.begin(k, o.weight(), 0, 0, 0, 0);
    o.contribute(ctx, builder, data.objectives[static_cast<std::size_t>(k)].get());
    written = std::max(written, builder.written_w());
  }
  return written;
}

REDRES_HOT void Scheme::check_inputs(const Context& ctx, const SchemeData& data) const {
  REDRES_REQUIRE(ctx.kinematics != nullptr && ctx.robot == robot_, "Scheme::build",
                 "ctx.robot is the scheme's robot and ctx.kinematics is set");
  REDRES_REQUIRE(ctx.kinematics->level >= kinematics_level_, "Scheme::build",
                 "ctx.kinematics was computed at kinematics_level() or deeper");
  REDRES_REQUIRE(data.objectives.size() == objectives_.size() && data.constraints.size() == constraints_.size() &&
                     data.tasks.size() == tasks_.size(),
                 "Scheme::build", "data was made by this scheme's make_data()");
}

REDRES_HOT void Scheme::check_built(const Context& ctx, QpProblem& qp, SchemeData& data, bool full_w,
                                    bool constraints_only) const {
  // One scan of everything the plugins can have written (bounds are checked as they are intersected; W off its
  // diagonal keeps clear()'s zeros unless a plugin wrote there).
  const Eigen::Index n = qp.W.rows();
  double acc = 0.0;
  if (full_w) {
    acc = finite_probe(qp.W.data(), qp.W.size());
  } else {
    const double* W = qp.W.data();
    double odd = 0.0;  // two sums, as in finite_probe
    Eigen::Index i = 0;
    for (; i + 2 <= n; i += 2) {
      acc += W[i * (n + 1)] * 0.0;
      odd += W[(i + 1) * (n + 1)] * 0.0;
    }
    if (i < n) acc += W[i * (n + 1)] * 0.0;
    acc += odd;
  }
  // The probes are independent sums, added at the end.
  acc += (finite_probe(qp.zeta.data(), n) + finite_probe(qp.J.data(), qp.J.size())) +
         (finite_probe(qp.d.data(), qp.d.size()) +
          (finite_probe(qp.A.data(), qp.A.size()) + finite_probe(qp.b.data(), qp.b.size())));
  if (acc == 0.0 && (!full_w || qp.W.isApprox(qp.W.transpose(), 1e-12))) return;
  // Build again with a check after each plugin, which names the plugin and the entry, and throws.
  contribute_all(ctx, qp, data, true, constraints_only);
  qp.validate();  // the checked build found nothing (a plugin that gives different values when called again)
  throw_invalid_argument("Scheme::build",
                         "the QP had a non-finite or asymmetric entry that a second build did not "
                         "reproduce (a plugin whose output changes between two calls at one state)");
}

REDRES_HOT bool Scheme::contribute_all(const Context& ctx, QpProblem& qp, SchemeData& data, bool checked,
                                       bool constraints_only) const {
  qp.clear();
  QpBuilder builder(qp);
  bool full_w = false;  // some plugin wrote off the diagonal of W
  int source = 0;
  for (std::size_t k = 0; k < objectives_.size(); ++k) {
    if (constraints_only) {
      ++source;
      continue;
    }
    const Objective& o = *objectives_[k];
    PluginData* own = data.objectives[k].get();
    builder.begin(source++, o.weight(), 0, 0, 0, 0);
    if (checked) {
      o.contribute(ctx, builder, own);
    } else {
      o.contribute_unchecked(ctx, builder, own);
    }
    full_w = full_w || builder.written_w() == QpBuilder::WrittenW::kFull;
  }
  // Constraints whose bounds yield come last (constraint_order_); sources are numbered in the list's order.
  const int first_constraint = source;
  for (const std::size_t k : constraint_order_) {
    // Inactive constraints leave their rows empty: 0 x = 0 and 0 x <= 0 are always met.
    builder.begin(first_constraint + static_cast<int>(k), 1.0, eq_offset_[k], eq_rows_[k], in_offset_[k], in_rows_[k]);
    PluginData* own = data.constraints[k].get();
    if (checked) {
      constraints_[k]->contribute(ctx, builder, own);
    } else {
      constraints_[k]->contribute_unchecked(ctx, builder, own);
    }
    full_w = full_w || builder.written_w() == QpBuilder::WrittenW::kFull;
  }
  if (constraints_only) return full_w;
  // One level: the tasks (each checks its own rows as it computes them).
  for (std::size_t k = 0; k < tasks_.size(); ++k) {
    if (!task_active_[k]) continue;
    const Task& t = *tasks_[k];
    auto& own = static_cast<TaskData&>(*data.tasks[k]);
    t.evaluate(ctx, own);
    builder.begin(task_source(k), 1.0, task_eq_offset_[k], task_eq_rows_[k], task_in_offset_[k], task_in_rows_[k]);
    write_task_terms(t, own.rows, builder);
    full_w = full_w || builder.written_w() == QpBuilder::WrittenW::kFull;
  }
  return full_w;
}

}  // namespace redres
